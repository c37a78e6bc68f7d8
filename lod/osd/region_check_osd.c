/* SPDX-License-Identifier: MIT */
/* The OpenSubdiv cross-check of uniform bicubic regions (sw_lod_osd_check.h). */
#include "sw_lod_osd_check.h"
#include "sw_hooks.h"

#include "sw_lod_osd.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Knots t[k-2] .. t[k+3] equally spaced: span k of a cubic B-spline is then a uniform bicubic
 * B-spline segment of control points k-3 .. k, exactly what OpenSubdiv's regular patches are. */
static int uniform_span(const double *knots, int32_t k)
{
    double h = knots[k + 1] - knots[k];
    if (!(h > 0.0))
        return 0;
    for (int32_t i = k - 2; i <= k + 2; i++) {
        if (fabs((knots[i + 1] - knots[i]) - h) > 1e-12 * h)
            return 0;
    }
    return 1;
}

static int is_nonrational(const sw_sg_surface *s)
{
    size_t n = (size_t)s->n_u * (size_t)s->n_v;
    double w0 = s->cpw[3];
    for (size_t i = 1; i < n; i++) {
        if (fabs(s->cpw[i * 4 + 3] - w0) > 1e-14 * w0)
            return 0;
    }
    return 1;
}

static uint64_t next_random(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return *state >> 11;
}

static double unit_random(uint64_t *state)
{
    return (double)next_random(state) * (1.0 / 9007199254740992.0);
}

/* One uniform region (ku, kv): its 4x4 net in Euclidean form and the net's diagonal. */
static double region_net(const double *verts, int32_t n_u, int32_t ku, int32_t kv, double net[48])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t j = 0; j < 4; j++) {
        for (int32_t i = 0; i < 4; i++) {
            const double *p =
                verts + ((size_t)(kv - 3 + j) * (size_t)n_u + (size_t)(ku - 3 + i)) * 3;
            for (int c = 0; c < 3; c++) {
                net[(j * 4 + i) * 3 + c] = p[c];
                lo[c] = fmin(lo[c], p[c]);
                hi[c] = fmax(hi[c], p[c]);
            }
        }
    }
    double d = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return d > 0.0 ? d : 1.0;
}

static double distance3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Local (s, t) of sample k of a region: the four corners first, then random points. */
static void sample_point(int k, uint64_t *rng, double *s, double *t)
{
    if (k < 4) {
        *s = (double)(k & 1);
        *t = (double)(k >> 1);
    } else {
        *s = unit_random(rng);
        *t = unit_random(rng);
    }
}

typedef struct region_list {
    int32_t *ku, *kv;
    size_t count;
} region_list;

static sw_result list_regions(const sw_sg_surface *s, region_list *out, sw_status *status)
{
    size_t cap = (size_t)(s->n_u - 3) * (size_t)(s->n_v - 3);
    out->ku = sw__malloc(cap * sizeof *out->ku);
    out->kv = sw__malloc(cap * sizeof *out->kv);
    out->count = 0;
    if (!out->ku || !out->kv)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory listing regions");
    for (int32_t kv = 3; kv < s->n_v; kv++) {
        if (!uniform_span(s->knots_v, kv))
            continue;
        for (int32_t ku = 3; ku < s->n_u; ku++) {
            if (!uniform_span(s->knots_u, ku))
                continue;
            out->ku[out->count] = ku;
            out->kv[out->count] = kv;
            out->count++;
        }
    }
    return SW_OK;
}

static void compare_samples(const sw_sg_surface *s, const double *verts, const region_list *rl,
                            int per_region, uint64_t seed, const double *osd_pos,
                            sw_lod_osd_report *report)
{
    uint64_t rng = seed;
    for (size_t r = 0; r < rl->count; r++) {
        double net[48], bez[48];
        double diag = region_net(verts, s->n_u, rl->ku[r], rl->kv[r], net);
        sw_sg_uniform_bicubic_to_bezier(net, bez);
        double bez_h[64];
        for (int i = 0; i < 16; i++) {
            memcpy(bez_h + i * 4, bez + i * 3, 3 * sizeof(double));
            bez_h[i * 4 + 3] = 1.0;
        }
        sw_sg_bezier_patch patch = {3, 3, 0, 0, 0.0, 1.0, 0.0, 1.0, bez_h};
        double u0 = s->knots_u[rl->ku[r]], hu = s->knots_u[rl->ku[r] + 1] - u0;
        double v0 = s->knots_v[rl->kv[r]], hv = s->knots_v[rl->kv[r] + 1] - v0;
        for (int k = 0; k < per_region; k++) {
            double ls, lt, ours[3], bez_p[3];
            sample_point(k, &rng, &ls, &lt);
            sw_sg_surface_eval(s, u0 + ls * hu, v0 + lt * hv, ours);
            sw_sg_bezier_patch_eval(&patch, ls, lt, bez_p);
            const double *ref = osd_pos + (r * (size_t)per_region + (size_t)k) * 3;
            report->max_rel_nurbs = fmax(report->max_rel_nurbs, distance3(ours, ref) / diag);
            report->max_rel_bezier = fmax(report->max_rel_bezier, distance3(bez_p, ref) / diag);
        }
    }
    report->regions += rl->count;
    report->samples += rl->count * (size_t)per_region;
}

static sw_result check_surface(const sw_sg_surface *s, int per_region, uint64_t seed,
                               sw_lod_osd_report *report, sw_status *status)
{
    if (s->deg_u != 3 || s->deg_v != 3 || s->n_u < 4 || s->n_v < 4 || !is_nonrational(s))
        return SW_OK;
    region_list rl = {0};
    sw_result r = list_regions(s, &rl, status);
    size_t n = (size_t)s->n_u * (size_t)s->n_v;
    size_t count = rl.count * (size_t)per_region;
    double *verts = r == SW_OK ? sw__malloc(n * 3 * sizeof *verts) : NULL;
    double *pos = r == SW_OK ? sw__malloc((count ? count : 1) * 3 * sizeof *pos) : NULL;
    sw_lod_osd_sample *samples =
        r == SW_OK ? sw__malloc((count ? count : 1) * sizeof *samples) : NULL;
    if (r == SW_OK && (!verts || !pos || !samples))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory for %zu OSD samples", count);
    if (r == SW_OK && rl.count) {
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                verts[i * 3 + c] = s->cpw[i * 4 + c] / s->cpw[i * 4 + 3];
        uint64_t rng = seed;
        for (size_t q = 0; q < rl.count; q++) {
            for (int k = 0; k < per_region; k++) {
                sw_lod_osd_sample *smp = &samples[q * (size_t)per_region + (size_t)k];
                smp->face_i = rl.ku[q] - 2; /* OSD face (i, i+1) is the centre of net i-1..i+2 */
                smp->face_j = rl.kv[q] - 2;
                sample_point(k, &rng, &smp->s, &smp->t);
            }
        }
        r = sw_lod_osd_eval_grid(verts, s->n_u, s->n_v, samples, count, pos, NULL, NULL, status);
        if (r == SW_OK) {
            compare_samples(s, verts, &rl, per_region, seed, pos, report);
            report->faces_checked++;
        }
    }
    sw__free(verts);
    sw__free(pos);
    sw__free(samples);
    sw__free(rl.ku);
    sw__free(rl.kv);
    return r;
}

sw_result sw_lod_osd_check_face(const sw_sg_scene *scene, uint32_t face, int samples_per_region,
                                uint64_t seed, sw_lod_osd_report *report, sw_status *status)
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, face, &s);
    return check_surface(&s, samples_per_region, seed, report, status);
}

sw_result sw_lod_osd_check_generated(int32_t nx, int32_t ny, int samples_per_region, uint64_t seed,
                                     sw_lod_osd_report *report, sw_status *status)
{
    if (nx < 4 || ny < 4 || nx > 4096 || ny > 4096)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "generated net %dx%d out of 4..4096", nx,
                        ny);
    size_t n = (size_t)nx * (size_t)ny;
    double *cpw = sw__malloc(n * 4 * sizeof *cpw);
    double *ku = sw__malloc((size_t)(nx + 4) * sizeof *ku);
    double *kv = sw__malloc((size_t)(ny + 4) * sizeof *kv);
    sw_result r = SW_OK;
    if (!cpw || !ku || !kv) {
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory for a %dx%d net", nx, ny);
    } else {
        uint64_t rng = seed ^ 0x9e3779b97f4a7c15ull;
        for (int32_t j = 0; j < ny; j++) {
            for (int32_t i = 0; i < nx; i++) {
                double *p = cpw + ((size_t)j * (size_t)nx + (size_t)i) * 4;
                p[0] = i + 0.3 * (unit_random(&rng) - 0.5);
                p[1] = j + 0.3 * (unit_random(&rng) - 0.5);
                p[2] = 2.0 * unit_random(&rng);
                p[3] = 1.0;
            }
        }
        /* uniform, unclamped, and deliberately not starting at 0 */
        for (int32_t i = 0; i < nx + 4; i++)
            ku[i] = 0.5 * i - 1.25;
        for (int32_t j = 0; j < ny + 4; j++)
            kv[j] = 2.0 * j + 3.0;
        sw_sg_surface s = {3, 3, nx, ny, ku, kv, cpw};
        r = check_surface(&s, samples_per_region, seed, report, status);
    }
    sw__free(cpw);
    sw__free(ku);
    sw__free(kv);
    return r;
}

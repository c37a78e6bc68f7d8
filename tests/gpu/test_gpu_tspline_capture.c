/* SPDX-License-Identifier: MIT */
/* T-spline GPU agreement: samples/tsplines/t_junctions.tsm is imported as one bicubic
 * rational Bézier face per Krishnamurthy–Yasui region (face (u, v) = T-spline (u, v)), rendered
 * through the vertex-shader path (Guthe et al. 2005 §4.2) with the shader's debug capture on, and
 * every evaluated vertex (its float (s, t) and eye-relative float position) is compared with the
 * CPU T-spline evaluation (sw_sg_tspline_eval, region point lists) at the same (u, v) =
 * (u0 + s (u1 - u0), v0 + t (v1 - v0)), placed by the occurrence transform, relative to the eye.
 *
 * Bound: the shader rounds the eye-relative control points to float (1/2 ulp), computes the
 * cubic Bernstein weights (<= 4 roundings) and two 4-term sums (<= 3 each) per direction, then
 * divides by w: with non-negative basis weights every partial sum is bounded by R, the largest
 * eye-relative control point of the patch (homogeneous, over w), so the error is below about
 * (1/2 + 2 (4 + 3) + 1) u R + 7 u |P| with u = FLT_EPSILON / 2, i.e. < 8 FLT_EPSILON (R + |P|).
 * The test requires max over vertices of err / (8 FLT_EPSILON (R + |P - eye|)) <= 1 and prints
 * the absolute max and median errors.
 *
 * Usage: test_gpu_tspline_capture OUTDIR FILE.tsm
 */
#include "sw_gpu_internal.h"
#include "sw_sg_tspline.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct piece {
    double u0, u1, v0, v1;
    double world[12];
    double radius; /* largest |control point - eye| (Euclidean, eye-relative) */
} piece;

typedef struct pieces {
    piece *p;
    size_t n, cap;
    int oom, cpu;
} pieces;

static void on_patch(void *user, const sw__gpu_drawn_patch *d)
{
    pieces *ps = user;
    if (!d->gpu) {
        ps->cpu++;
        return;
    }
    if (ps->n == ps->cap) {
        size_t c = ps->cap ? 2 * ps->cap : 64;
        piece *q = realloc(ps->p, c * sizeof *q);
        if (!q) {
            ps->oom = 1;
            return;
        }
        ps->p = q;
        ps->cap = c;
    }
    piece *p = &ps->p[ps->n++];
    p->u0 = d->u0;
    p->u1 = d->u1;
    p->v0 = d->v0;
    p->v1 = d->v1;
    memcpy(p->world, d->world, sizeof p->world);
    p->radius = 0.0;
    size_t m = (size_t)(d->deg_u + 1) * (size_t)(d->deg_v + 1);
    for (size_t i = 0; i < m; ++i) {
        const double *h = d->cpw + 4 * i;
        p->radius = fmax(p->radius, sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]) / h[3]);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Camera on the diagonal of the box, looking at its centre. */
static sw_gpu_camera iso_camera(const double b[6])
{
    sw_gpu_camera c;
    memset(&c, 0, sizeof c);
    double diag = sqrt(pow(b[3] - b[0], 2) + pow(b[4] - b[1], 2) + pow(b[5] - b[2], 2));
    for (int k = 0; k < 3; ++k) {
        c.target[k] = 0.5 * (b[k] + b[3 + k]);
        c.eye[k] = c.target[k] + (k == 2 ? 0.8 : -0.6) * 1.5 * diag;
    }
    c.up[2] = 1.0;
    c.fovy_deg = 40.0;
    return c;
}

static int check(const sw_sg_tspline *ts, const pieces *ps, const sw__gpu_capture_vertex *cv,
                 size_t n, const double eye[3])
{
    double *err = malloc((n ? n : 1) * sizeof *err), worst_ratio = 0.0;
    if (!err)
        return 0;
    size_t bad = 0;
    for (size_t i = 0; i < n; ++i) {
        if (cv[i].piece >= ps->n) {
            bad++;
            continue;
        }
        const piece *p = &ps->p[cv[i].piece];
        double u = p->u0 + (double)cv[i].s * (p->u1 - p->u0);
        double v = p->v0 + (double)cv[i].t * (p->v1 - p->v0);
        double q[3], rel[3], e2 = 0.0, r2 = 0.0;
        sw_sg_tspline_eval(ts, u, v, q);
        for (int k = 0; k < 3; ++k) {
            const double *m = p->world + 4 * k;
            rel[k] = m[0] * q[0] + m[1] * q[1] + m[2] * q[2] + m[3] - eye[k];
            e2 += pow((double)cv[i].pos[k] - rel[k], 2);
            r2 += rel[k] * rel[k];
        }
        err[i] = sqrt(e2);
        double bound = 8.0 * FLT_EPSILON * (p->radius + sqrt(r2));
        worst_ratio = fmax(worst_ratio, err[i] / bound);
    }
    qsort(err, n, sizeof *err, cmp_double);
    printf("%zu captured vertices over %zu pieces (%zu with no piece): error max %.3g median "
           "%.3g; max error / bound %.3f (bound 8 FLT_EPSILON (R + |P - eye|))\n",
           n, ps->n, bad, n ? err[n - 1] : 0.0, n ? err[n / 2] : 0.0, worst_ratio);
    free(err);
    return bad == 0 && n > 0 && worst_ratio <= 1.0;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s OUTDIR FILE.tsm\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    sw_sg_scene *scene = NULL;
    sw_sg_tspline *ts = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK ||
        sw_sg_tspline_import_file(argv[2], &scene, &st) != SW_OK ||
        sw_sg_tspline_load(argv[2], &ts, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    sw_sg_scene_stats ss;
    sw_sg_scene_compute_stats(scene, &ss);
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = 640;
    desc.height = 480;
    desc.camera = iso_camera(ss.bbox);
    pieces ps = {NULL, 0, 0, 0, 0};
    enum { MAX_CAPTURE = 1u << 22 };
    sw__gpu_set_patch_hook(ctx, on_patch, &ps);
    sw__gpu_set_capture(ctx, MAX_CAPTURE);
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    int ok = sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st) == SW_OK;
    sw__gpu_capture_vertex *cv = NULL;
    size_t n = 0, total = 0;
    ok = ok && sw__gpu_capture_read(ctx, &cv, &n, &total, &st) == SW_OK;
    if (!ok)
        fprintf(stderr, "render: %s\n", st.message);
    sw__gpu_set_capture(ctx, 0);
    sw__gpu_set_patch_hook(ctx, NULL, NULL);
    if (ok) {
        printf("%llu patches drawn, %llu in the vertex shader, %d as CPU grids; %zu of %zu "
               "captured\n",
               (unsigned long long)(fs.patches_trimmed + fs.patches_untrimmed),
               (unsigned long long)fs.patches_gpu_evaluated, ps.cpu, n, total);
        ok = !ps.oom && ps.cpu == 0 && total == n && fs.patches_gpu_evaluated > 0 &&
             check(ts, &ps, cv, n, desc.camera.eye);
        char path[1024];
        snprintf(path, sizeof path, "%s/t_junctions_capture.png", argv[1]);
        ok &= sw_gpu_image_write(&img, path, &st) == SW_OK;
    }
    free(cv);
    free(ps.p);
    sw_gpu_image_free(&img);
    sw_sg_tspline_free(ts);
    sw_sg_scene_free(scene);
    sw_gpu_context_free(ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

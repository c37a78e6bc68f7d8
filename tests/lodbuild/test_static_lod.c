/* SPDX-License-Identifier: MIT */
/* Static LODs (Kumar et al. 1997 §4.1-§4.3; lod/static/sw_lod_static.h): every face of every model
 * given on the command line becomes one super-surface (all its patches), is tessellated within δ
 * and simplified into levels, each declared with a certified ε_k; then an independent measurement
 * against the exact surface — random surface points and random points of the triangles, each
 * projected by Newton's iteration — must find every level within its declared ε_k both ways:
 * surface -> mesh and mesh -> surface. Zero violations, or exit 1. (A certification that missed
 * a piece of a level, or level 0's δ, fails here: ε_k would fall below the measured distance.)
 *
 * Usage: test_static_lod [--levels N] [--stride K] [--max-faces N] [--verbose] [--split] model
 * files...
 * --levels -1 checks level 0 only; --stride K takes every K-th face; --verbose prints each face;
 * --split takes the lower half of each face's patch grid (a super-surface ending inside a face).
 * Prints per model: patches, triangles of level 0 and each level, reduction against level 0,
 * whether the coarsest level has fewer than 2n triangles for n patches, the worst measured / ε
 * ratio, and the build time split into tessellation, decimation and certification.
 */
#include "sw_lod_static.h"
#include "sw_sg_geom.h"
#include "model_import.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVELS 9

typedef struct totals {
    long faces, skipped, failed, violations, checks;
    long patches;
    double tri[MAX_LEVELS];
    double eps_rel[MAX_LEVELS]; /* sum of eps / delta */
    int32_t n_levels;
    long coarse_below_2n;
    double worst_ratio;
    double seconds[3];
    size_t memory;
} totals;

/* The patches of one face: its whole Bézier grid over the uv_box (as lod/hierarchy/hierarchy.c
 * builds). */
static uint32_t face_patches(const sw_sg_scene *scene, uint32_t face, sw_lod_static_patch **out)
{
    const sw_sg_face_rec *fr = &sw_sg_scene_view_ptr(scene)->faces[face];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, face, &s);
    sw_sg_bezier_set set;
    *out = NULL;
    if (sw_sg_surface_extract_bezier_in(&s, fr->uv_box[0], fr->uv_box[1], fr->uv_box[2],
                                        fr->uv_box[3], &set, NULL) != SW_OK)
        return 0;
    const uint32_t n = (uint32_t)(set.n_u * set.n_v);
    *out = malloc((n ? n : 1) * sizeof **out);
    for (int32_t j = 0; *out && j < set.n_v; ++j)
        for (int32_t i = 0; i < set.n_u; ++i)
            (*out)[j * set.n_u + i] = (sw_lod_static_patch){face, (uint16_t)i, (uint16_t)j};
    sw_sg_bezier_set_free(&set);
    return *out ? n : 0;
}

static int check_level(const sw_sg_scene *scene, const sw_lod_static_patch *p, uint32_t n,
                       const sw_lod_static_chain *c, int32_t k, uint32_t face, totals *t)
{
    /* independent of the declaring measurement: random points, another seed, other counts */
    const sw_lod_static_level *l = &c->levels[k];
    const sw_lod_static_measure_desc md = {977u + (uint32_t)k, 13, 7, 1};
    sw_lod_static_distance dist;
    sw_status st = {0};
    if (sw_lod_static_measure(scene, p, n, l, &c->levels[0], c->delta, l->eps, &md, &dist, &st) !=
        SW_OK) {
        fprintf(stderr, "face %u level %d: measure failed: %s\n", face, (int)k, st.message);
        return 1;
    }
    t->checks++;
    const double worst = fmax(dist.surface_to_mesh, dist.mesh_to_surface);
    if (worst / l->eps > t->worst_ratio)
        t->worst_ratio = worst / l->eps;
    if (!(worst <= l->eps) || dist.n_surface == 0 || dist.n_mesh == 0) {
        t->violations++;
        fprintf(stderr,
                "VIOLATION face %u level %d: surface->mesh %.6g, mesh->surface %.6g > eps %.6g "
                "(%llu, %llu samples)\n",
                face, (int)k, dist.surface_to_mesh, dist.mesh_to_surface, l->eps,
                (unsigned long long)dist.n_surface, (unsigned long long)dist.n_mesh);
    }
    return 0;
}

static int verbose, split;

/* Bad input is an sw_result, never a crash: no patches, a face or (iu, iv) out of range, bad desc.
 */
static int check_bad_input(const sw_sg_scene *scene)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    sw_lod_static_chain *c = NULL;
    sw_status st = {0};
    const sw_lod_static_patch bad_face = {v->n_faces, 0, 0}, bad_iu = {0, 60000, 0}, ok = {0, 0, 0};
    const sw_lod_static_desc bad_desc = {.delta = -1.0};
    int fail = 0;
    fail |= sw_lod_static_build(scene, &ok, 0, NULL, &c, &st) != SW_ERR_INVALID_ARGUMENT;
    fail |= sw_lod_static_build(scene, &bad_face, 1, NULL, &c, &st) != SW_ERR_INVALID_ARGUMENT;
    fail |= sw_lod_static_build(scene, &bad_iu, 1, NULL, &c, &st) != SW_ERR_INVALID_ARGUMENT;
    fail |= sw_lod_static_build(scene, &ok, 1, &bad_desc, &c, &st) != SW_ERR_INVALID_ARGUMENT;
    fail |= c != NULL;
    printf("bad input: %s\n", fail ? "FAILED" : "every case rejected with SW_ERR_INVALID_ARGUMENT");
    return fail;
}

static int run_model(const char *path, int32_t levels, uint32_t stride, uint32_t max_faces)
{
    sw_sg_scene *scene = NULL;
    const int imported = sw_test_import_model(path, &scene);
    if (imported <= 0)
        return imported < 0;
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    totals t = {0};
    static int bad_input_checked;
    int fail = bad_input_checked++ ? 0 : check_bad_input(scene);
    for (uint32_t f = 0; f < v->n_faces && t.faces < (long)max_faces; f += stride) {
        sw_lod_static_patch *p = NULL;
        uint32_t n = face_patches(scene, f, &p);
        if (split && n >= 2) { /* a partial super-surface: the lower half of the face's grid */
            uint32_t nu = 0, nv = 0, m = 0;
            for (uint32_t k = 0; k < n; ++k)
                nu = p[k].iu + 1u > nu ? p[k].iu + 1u : nu,
                nv = p[k].iv + 1u > nv ? p[k].iv + 1u : nv;
            for (uint32_t k = 0; k < n; ++k)
                if (nu >= 2 ? p[k].iu < nu / 2 : p[k].iv < nv / 2)
                    p[m++] = p[k];
            n = m;
        }
        if (n == 0) {
            free(p);
            t.skipped++;
            continue;
        }
        const sw_lod_static_desc desc = {.n_levels = levels};
        sw_lod_static_chain *c = NULL;
        sw_status st = {0};
        const sw_result r = sw_lod_static_build(scene, p, n, &desc, &c, &st);
        if (r != SW_OK) {
            fprintf(stderr, "%s face %u (%u patches): %s: %s\n", path, f, n, sw_result_id_str(r),
                    st.message);
            if (r == SW_ERR_LIMIT)
                t.skipped++;
            else
                t.failed++;
            free(p);
            continue;
        }
        t.faces++;
        t.patches += n;
        if (verbose) {
            printf("  face %u: %u patches, delta %.3g:", f, n, c->delta);
            for (int32_t k = 0; k < c->n_levels; ++k)
                printf(" L%d %u (eps %.3g, bound %.3g %.3g)", (int)k, c->levels[k].n_triangles,
                       c->levels[k].eps, c->levels[k].bound[0], c->levels[k].bound[1]);
            printf(" [%.2f %.2f %.2f s]\n", c->seconds[0], c->seconds[1], c->seconds[2]);
        }
        t.n_levels = c->n_levels;
        for (int32_t k = 0; k < c->n_levels; ++k) {
            t.tri[k] += c->levels[k].n_triangles;
            t.eps_rel[k] += c->levels[k].eps / c->delta;
            fail |= check_level(scene, p, n, c, k, f, &t);
        }
        t.coarse_below_2n += c->levels[c->n_levels - 1].n_triangles < 2 * n;
        for (int q = 0; q < 3; ++q)
            t.seconds[q] += c->seconds[q];
        t.memory += sw_lod_static_memory(c);
        sw_lod_static_free(c);
        free(p);
    }
    const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    printf("%s: %ld faces (%ld skipped, %ld failed), %ld patches; triangles", name, t.faces,
           t.skipped, t.failed, t.patches);
    for (int32_t k = 0; k < t.n_levels; ++k)
        printf(" L%d %.0f", (int)k, t.tri[k]);
    printf("\n  reduction vs L0:");
    for (int32_t k = 1; k < t.n_levels; ++k)
        printf(" L%d %.1f%% (eps %.1f delta)", (int)k,
               t.tri[0] > 0 ? 100.0 * (1.0 - t.tri[k] / t.tri[0]) : 0.0,
               t.faces ? t.eps_rel[k] / t.faces : 0.0);
    printf("\n  coarsest < 2n triangles: %ld of %ld super-surfaces (coarsest %.0f for 2n = %ld)\n",
           t.coarse_below_2n, t.faces, t.n_levels ? t.tri[t.n_levels - 1] : 0.0, 2 * t.patches);
    printf("  checks %ld, violations %ld, worst measured/eps %.3f; build s: tessellation %.2f, "
           "decimation %.2f, certification %.2f; memory %.1f MB\n",
           t.checks, t.violations, t.worst_ratio, t.seconds[0], t.seconds[1], t.seconds[2],
           t.memory / 1e6);
    sw_sg_scene_free(scene);
    return fail || t.violations || t.failed;
}

int main(int argc, char **argv)
{
    int32_t levels = 0;
    uint32_t stride = 1, max_faces = UINT32_MAX;
    int fail = 0, files = 0;
    for (int a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--levels") && a + 1 < argc)
            levels = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--stride") && a + 1 < argc)
            stride = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--verbose"))
            verbose = 1;
        else if (!strcmp(argv[a], "--split"))
            split = 1;
        else if (!strcmp(argv[a], "--max-faces") && a + 1 < argc)
            max_faces = (uint32_t)atoi(argv[++a]);
        else {
            fail |= run_model(argv[a], levels, stride ? stride : 1, max_faces);
            files++;
        }
    }
    if (!files) {
        fprintf(stderr, "usage: test_static_lod [--levels N] [--stride K] models...\n");
        return 2;
    }
    printf("%s\n", fail ? "FAILED" : "all levels within their declared eps");
    return fail;
}

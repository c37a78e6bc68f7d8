/* SPDX-License-Identifier: MIT */
/* Patch grids kept on the GPU between frames (gpu/resident_grids.c) against the same frames with
 * every grid evaluated in the frame (the context's kept grids off), on MODEL and OTHER_MODEL,
 * through the hierarchy and through the faces' own Bézier patches:
 *  - The same image: at most 0.1 % of the covered pixels differ at all (kept grids are evaluated
 *    around a centre and placed in float, the frame's eye-relative: they round differently),
 *    with no fewer triangles (catches: a grid drawn without its centre's offset or under another
 *    record's placement, a key without the record's part of the domain (pieces sharing a grid),
 *    a class coarser than the view asks for).
 *  - Kept: the same view again evaluates nothing (every record a hit) and draws the same pixels;
 *    a face seen at another place under the same relative view (another translation of the
 *    occurrences and of the eye) finds every grid it needs (keys are the patch's own inputs, not
 *    its placement); coming closer evaluates the finer classes it needs and moving back reuses
 *    them (hysteresis toward finer only: catches a lookup of the exact class only).
 *  - Placed as any affine map places the surface: occurrences under a mirror with a non-uniform
 *    scale and a rotation shade as the frame's own evaluation shades them (catches: normals
 *    turned by the 3 x 3 instead of its cofactors, planted: most pixels differ).
 *  - Another scene in the same context draws as a fresh context does (keys are content: a face
 *    index reused by other geometry finds nothing of the old one).
 *  - Its budget holds: with a budget of 0 a frame keeps what the frame before it drew and no
 *    more, and draws the same image (catches: a cache that never evicts); its vertex buffer does
 *    not fill with freed slots of classes no longer asked for.
 * Usage: test_gpu_resident_grids MODEL OTHER_MODEL */
#include "frame_stages.h"
#include "gpu_test_compare.h"
#include "sw_lod_cache.h"
#include "sw_sg_bvh.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

enum { W = 320, H = 240 };
static sw_th_pool *g_pool;

typedef struct model {
    sw_sg_scene *scene;
    sw_sg_bvh *bvh;
    sw_lod_cache *cache;
} model;

/* The iso view, its eye at `scale` times the fitted distance; converged; the hierarchy path
 * unless `direct`. */
static sw_gpu_frame_desc view_at(const model *m, double scale, int direct)
{
    sw_gpu_frame_desc d = {0};
    d.width = W;
    d.height = H;
    d.camera = sw_test_view_camera_at(m->bvh->box, 1, scale);
    d.hierarchies = direct ? NULL : m->cache;
    d.bvh = m->bvh;
    d.pool = g_pool;
    return d;
}

static int render(sw_gpu_context *ctx, const model *m, const sw_gpu_frame_desc *d, int kept,
                  sw_gpu_image *img, sw_gpu_frame_stats *fs, const char *what)
{
    sw_status st = {0};
    memset(img, 0, sizeof *img);
    memset(fs, 0, sizeof *fs);
    sw__gpu_set_grids_resident(ctx, kept);
    const sw_result r = sw_gpu_render_scene(ctx, m->scene, d, img, fs, &st);
    sw__gpu_set_grids_resident(ctx, 1);
    CHECK(r == SW_OK, "%s: %s", what, st.message);
    return r == SW_OK;
}

/* The frame drawn with kept grids against the frame evaluating every grid. With `fresh` the kept
 * grids are dropped first, so that each is evaluated at the class the view asks for (but where a
 * patch of the same inputs drawn before in the frame made a finer one): at most 1 % of the
 * covered pixels may differ by coverage or by more than 2 levels (normals turned by the cofactors
 * of a non-uniform scale round differently: half the pixels of such a view differ by 1). Else
 * grids kept from earlier frames may be finer (within twice as fine): at most 3 % of the pixels
 * differ by coverage or by more than 48 levels (silhouettes and depth edges move by a fraction
 * of a pixel). Either way no grid is drawn coarser than asked. Returns the kept frame's stats. */
static sw_gpu_frame_stats compare_as(sw_gpu_context *ctx, const model *m,
                                     const sw_gpu_frame_desc *d, int fresh, const char *what)
{
    sw_gpu_image on, off;
    sw_gpu_frame_stats s_on, s_off;
    if (fresh)
        sw__gpu_grid_cache_free(ctx);
    const int ok = render(ctx, m, d, 1, &on, &s_on, what);
    const int64_t extra = ctx->grid_extra_triangles;
    if (ok && render(ctx, m, d, 0, &off, &s_off, what)) {
        const sw_test_image_diff diff = sw_test_compare_images(&on, &off, fresh ? 2 : 48);
        const long per_mille = fresh ? 10 : 30;
        printf("%s: %llu grids kept, %llu evaluated; %llu triangles (%llu resident), %llu "
               "without; %ld of %ld pixels differ; upload %llu bytes, %llu without\n",
               what, (unsigned long long)s_on.grid_hits, (unsigned long long)s_on.grid_misses,
               (unsigned long long)s_on.triangles, (unsigned long long)s_on.resident_triangles,
               (unsigned long long)s_off.triangles, diff.any, diff.covered,
               (unsigned long long)s_on.upload_bytes, (unsigned long long)s_off.upload_bytes);
        CHECK(diff.covered > 0 && diff.differ * 1000 <= per_mille * diff.covered,
              "%s: %ld of %ld pixels differ from the frame evaluating its grids (%ld by coverage)",
              what, diff.differ, diff.covered, diff.cover_differ);
        CHECK(s_on.grid_hits + s_on.grid_misses > 0 && s_on.resident_triangles > 0 &&
                  s_off.grid_hits + s_off.grid_misses == 0 && extra >= 0,
              "%s: %llu + %llu grids kept (%llu without), %lld triangles more than asked for", what,
              (unsigned long long)s_on.grid_hits, (unsigned long long)s_on.grid_misses,
              (unsigned long long)(s_off.grid_hits + s_off.grid_misses), (long long)extra);
    }
    sw_gpu_image_free(&on);
    sw_gpu_image_free(&off);
    return s_on;
}

static sw_gpu_frame_stats compare(sw_gpu_context *ctx, const model *m, const sw_gpu_frame_desc *d,
                                  const char *what)
{
    return compare_as(ctx, m, d, 0, what);
}

/* One view twice: the second evaluates nothing and draws the same pixels. */
static void view_again(sw_gpu_context *ctx, const model *m, const sw_gpu_frame_desc *d,
                       const char *what)
{
    const sw_gpu_frame_stats first = compare_as(ctx, m, d, 1, what);
    sw_gpu_image a, b;
    sw_gpu_frame_stats s1, s2;
    if (render(ctx, m, d, 1, &a, &s1, what) && render(ctx, m, d, 1, &b, &s2, what)) {
        const sw_test_image_diff same = sw_test_compare_images(&a, &b, 0);
        CHECK(s2.grid_misses == 0 && s2.grid_hits == first.grid_hits + first.grid_misses &&
                  same.any == 0 && s2.upload_bytes < first.upload_bytes,
              "%s again: %llu kept, %llu evaluated (first: %llu + %llu), %ld pixels differ, "
              "upload %llu (first %llu)",
              what, (unsigned long long)s2.grid_hits, (unsigned long long)s2.grid_misses,
              (unsigned long long)first.grid_hits, (unsigned long long)first.grid_misses, same.any,
              (unsigned long long)s2.upload_bytes, (unsigned long long)first.upload_bytes);
    }
    sw_gpu_image_free(&a);
    sw_gpu_image_free(&b);
}

/* Closer in steps, then back: no fewer triangles than the frame's own evaluation at any step,
 * the finer classes evaluated on the way in and found on the way back. */
static void approach(sw_gpu_context *ctx, const model *m, int direct)
{
    static const double k_steps[] = {3.0, 2.2, 1.6, 1.2, 0.9, 1.0, 1.3};
    uint64_t misses_in = 0, misses_back = 0, hits_back = 0;
    for (size_t k = 0; k < sizeof k_steps / sizeof *k_steps; ++k) {
        char what[80];
        snprintf(what, sizeof what, "%s, approach at %.1fx", direct ? "direct" : "hierarchy",
                 k_steps[k]);
        const sw_gpu_frame_desc d = view_at(m, k_steps[k], direct);
        const sw_gpu_frame_stats s = compare(ctx, m, &d, what);
        if (k > 0 && k_steps[k] < k_steps[k - 1])
            misses_in += s.grid_misses;
        else if (k > 0) {
            misses_back += s.grid_misses;
            hits_back += s.grid_hits;
        }
    }
    CHECK(misses_in > 0 && hits_back > 4 * misses_back,
          "%s approach: %llu grids evaluated coming closer; moving back %llu kept, %llu "
          "evaluated",
          direct ? "direct" : "hierarchy", (unsigned long long)misses_in,
          (unsigned long long)hits_back, (unsigned long long)misses_back);
    /* from a near view alone to one 1.4 times as far: every class it asks for is at most twice
     * as coarse as one kept (densities follow the distance), so nearly nothing is evaluated */
    const sw_gpu_frame_desc near = view_at(m, 0.9, direct), back = view_at(m, 1.26, direct);
    compare_as(ctx, m, &near, 1, direct ? "direct, near alone" : "hierarchy, near alone");
    const sw_gpu_frame_stats s =
        compare(ctx, m, &back, direct ? "direct, back" : "hierarchy, back");
    CHECK(s.grid_misses * 20 <= s.grid_hits,
          "%s, 1.4 times as far as the only view before: %llu grids evaluated, %llu kept",
          direct ? "direct" : "hierarchy", (unsigned long long)s.grid_misses,
          (unsigned long long)s.grid_hits);
}

/* Occurrences of every face of the model under `world`; n faces. */
static sw_gpu_occurrence *occurrences_under(const model *m, const double world[12], size_t *n)
{
    const sw_sg_scene_view *sv = sw_sg_scene_view_ptr(m->scene);
    sw_gpu_occurrence *o = calloc(sv->n_faces ? sv->n_faces : 1, sizeof *o);
    for (uint32_t f = 0; o && f < sv->n_faces; ++f) {
        o[f].face = f;
        memcpy(o[f].world, world, sizeof o[f].world);
        o[f].color[3] = -1.0f; /* the default grey */
    }
    *n = o ? sv->n_faces : 0;
    return o;
}

/* The model under a mirror with a non-uniform scale and a rotation; and the model and the eye
 * moved together (the same relative view: every grid found). */
static void placements(sw_gpu_context *ctx, const model *m)
{
    /* rows: x' = -1.3 y, y' = 0.7 x, z' = 1.1 z (det < 0), then translated */
    static const double k_mirror[12] = {0.0, -1.3, 0.0, 5.0, 0.7, 0.0,
                                        0.0, -2.0, 0.0, 0.0, 1.1, 3.0};
    size_t n = 0;
    sw_gpu_occurrence *occ = occurrences_under(m, k_mirror, &n);
    sw_gpu_frame_desc d = view_at(m, 1.5, 0);
    const double *b = m->bvh->box;
    double box[6]; /* the model's box under the map (its corners' images bound it) */
    for (int k = 0; k < 3; ++k) {
        box[k] = 1e300;
        box[3 + k] = -1e300;
    }
    for (int c = 0; c < 8; ++c) {
        const double p[3] = {b[c & 1 ? 3 : 0], b[c & 2 ? 4 : 1], b[c & 4 ? 5 : 2]};
        for (int r = 0; r < 3; ++r) {
            const double x = k_mirror[4 * r] * p[0] + k_mirror[4 * r + 1] * p[1] +
                             k_mirror[4 * r + 2] * p[2] + k_mirror[4 * r + 3];
            box[r] = x < box[r] ? x : box[r];
            box[3 + r] = x > box[3 + r] ? x : box[3 + r];
        }
    }
    d.camera = sw_test_view_camera_at(box, 1, 1.5);
    d.occurrences = occ;
    d.n_occurrences = n;
    d.bvh = NULL;
    compare_as(ctx, m, &d, 1, "mirrored, scaled, rotated");
    free(occ);

    /* the same relative view elsewhere: the model and the eye translated together */
    static const double k_moved[12] = {1, 0, 0, 40.0, 0, 1, 0, -25.0, 0, 0, 1, 12.5};
    const sw_gpu_frame_desc here = view_at(m, 1.4, 0);
    compare(ctx, m, &here, "before the move");
    occ = occurrences_under(m, k_moved, &n);
    sw_gpu_frame_desc there = here;
    for (int k = 0; k < 3; ++k) {
        there.camera.eye[k] += k_moved[4 * k + 3];
        there.camera.target[k] += k_moved[4 * k + 3];
    }
    there.occurrences = occ;
    there.n_occurrences = n;
    there.bvh = NULL;
    const sw_gpu_frame_stats s = compare(ctx, m, &there, "moved with the eye");
    CHECK(s.grid_misses == 0 && s.grid_hits > 0,
          "moved with the eye: %llu grids evaluated, %llu kept (the same relative view)",
          (unsigned long long)s.grid_misses, (unsigned long long)s.grid_hits);
    free(occ);
}

/* A budget of 0: a frame keeps the grids the frame before it drew and no others, and draws the
 * same image from them. */
static void budget(sw_gpu_context *ctx, const model *m)
{
    const sw_gpu_frame_desc near = view_at(m, 0.9, 0), far = view_at(m, 3.0, 0);
    sw_gpu_image img;
    sw_gpu_frame_stats s_near, s_far, s_again;
    int ok = render(ctx, m, &near, 1, &img, &s_near, "default budget, near");
    sw_gpu_image_free(&img);
    ok = ok && render(ctx, m, &far, 1, &img, &s_far, "default budget, far");
    sw_gpu_image_free(&img);
    const size_t full = sw__gpu_grid_cache_bytes(ctx);
    sw__gpu_grid_cache_set_budget(ctx, 0);
    ok = ok && render(ctx, m, &far, 1, &img, &s_again, "budget 0, far again");
    sw_gpu_image_free(&img);
    const size_t kept = sw__gpu_grid_cache_bytes(ctx);
    printf("budget 0: %zu bytes kept after a near and a far view, %zu after the far one again\n",
           full, kept);
    if (ok)
        CHECK(kept > 0 && kept < full && s_again.grid_misses == 0,
              "budget 0: %zu bytes kept after a near and a far view, %zu after the far one again "
              "(%llu grids evaluated)",
              full, kept, (unsigned long long)s_again.grid_misses);
    compare(ctx, m, &far, "budget 0, far");
    /* coming closer in small steps over a budget of 0, back out and in again (slightly off the
     * first steps' distances): every frame asks for other classes, whose slots the freed ones are
     * not; the buffer up to its high-water mark stays within twice the most the kept grids held
     * (a frame begins with at most twice what it keeps, or the cache is dropped; its misses add
     * no more than it keeps). Catches freed slots piling up: planted, 2.2 times. */
    size_t most = 0, held = 0;
    for (int k = 0; k < 90 && ok; ++k) { /* in, out, in */
        const int step = k / 30 % 2 ? 29 - k % 30 : k % 30;
        const sw_gpu_frame_desc d = view_at(m, 3.0 * pow(0.92, step) * (k >= 30 ? 1.03 : 1.0), 0);
        ok = render(ctx, m, &d, 1, &img, &s_again, "budget 0, closer");
        sw_gpu_image_free(&img);
        most = sw__gpu_grid_cache_bytes(ctx) > most ? sw__gpu_grid_cache_bytes(ctx) : most;
        held = sw__gpu_grid_cache_held(ctx);
        CHECK(held <= 2 * most,
              "budget 0, step %d closer: %zu bytes in the buffer, %zu kept at most", k, held, most);
    }
    printf("budget 0, 30 steps closer, back, closer again: %zu bytes in the buffer, at most %zu "
           "kept\n",
           held, most);
}

static int model_make(const char *path, model *m)
{
    sw_status st = {0};
    sw_sg_import_desc id = {path, NULL, NULL, NULL, NULL, 0};
    memset(m, 0, sizeof *m);
    if (sw_sg_import_file(&id, &m->scene, NULL, &st) != SW_OK ||
        sw_sg_bvh_build(m->scene, &m->bvh, &st) != SW_OK ||
        sw_lod_cache_create(m->scene, g_pool, NULL, &m->cache, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s: import, BVH or hierarchy cache: %s\n", path, st.message);
        return 0;
    }
    return 1;
}

static void model_free(model *m)
{
    sw_lod_cache_destroy(m->cache);
    sw_sg_bvh_free(m->bvh);
    sw_sg_scene_free(m->scene);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s MODEL OTHER_MODEL\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    sw_th_pool_desc pd = {0};
    model a, b;
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK ||
        sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: pool or context: %s\n", st.message);
        return 1;
    }
    if (!model_make(argv[1], &a) || !model_make(argv[2], &b))
        return 1;
    const sw_gpu_frame_desc iso = view_at(&a, 1.5, 0), iso_direct = view_at(&a, 1.5, 1);
    view_again(ctx, &a, &iso, "hierarchy, iso");
    view_again(ctx, &a, &iso_direct, "direct, iso");
    const sw_gpu_frame_desc close = view_at(&a, 0.3, 1);
    compare_as(ctx, &a, &close, 1, "direct, close (tiles: pieces of one patch)");
    approach(ctx, &a, 0);
    approach(ctx, &a, 1);
    placements(ctx, &a);
    const sw_gpu_frame_desc other = view_at(&b, 1.5, 0);
    compare(ctx, &b, &other, "other model");
    compare(ctx, &a, &iso, "first model again");
    compare_as(ctx, &b, &other, 1, "other model, fresh");
    budget(ctx, &a);
    model_free(&a);
    model_free(&b);
    sw_gpu_context_free(ctx);
    sw_th_pool_destroy(g_pool);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}

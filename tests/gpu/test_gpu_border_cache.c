/* SPDX-License-Identifier: MIT */
/* The border cache (gpu/border_cache.c): fat borders' flattened loops and surface samples kept
 * between frames and shared by a face's occurrences must draw exactly what they replace.
 *  - Every frame of a context with the cache equals, byte for byte and in its triangle and
 *    border-triangle counts, the same frame of a context whose cache is off, over views at four
 *    distances (the keys' tolerance and sampling step change with them), a grid of instances of
 *    the first model (one entry serves many occurrences), a second model (other faces under the
 *    same face indices) and the first again (catches: an entry keyed without its tolerance, a
 *    set found for another step; both planted, both failed here). A stale entry kept across a
 *    scene change shows where a face keeps its key but not its loops: an edited node scene's
 *    next compiled version (planted: api_nodes_live fails).
 *  - It is used: the first frame leaves bytes in it, and the same view again adds none and
 *    places every loop from kept samples (catches: a cache that never keeps or never finds an
 *    entry, counters that miscount).
 *  - Its budget holds: over the budget, the next frame keeps only what the last frame used
 *    (fewer bytes than before), and the cache does not grow while over it (views alternating
 *    between two distances over a budget of one byte), the images still the same (catches: a cache
 * that grows past its budget, or drops what a frame still draws from). Usage: test_gpu_border_cache
 * MODEL OTHER_MODEL */
#include "frame_stages.h"
#include "gpu_test_compare.h"
#include "sw_lod_cache.h"
#include "sw_sg_bvh.h"
#include "sw_sg_generate.h"
#include "sw_sg_import.h"

#include <stdio.h>
#include <string.h>

#include "test_check.h"

enum { W = 320, H = 240, N_DISTANCES = 4 };
static sw_th_pool *g_pool;

typedef struct scene_set {
    sw_sg_scene *scene;
    sw_sg_bvh *bvh;
    sw_lod_cache *cache;
} scene_set;

static int scene_set_make(sw_sg_scene *scene, scene_set *s)
{
    sw_status st = {0};
    memset(s, 0, sizeof *s);
    s->scene = scene;
    if (sw_sg_bvh_build(scene, &s->bvh, &st) != SW_OK ||
        sw_lod_cache_create(scene, g_pool, NULL, &s->cache, &st) != SW_OK || s->bvh->n_nodes == 0) {
        CHECK(0, "BVH or hierarchy cache: %s", st.message);
        return 0;
    }
    return 1;
}

static void scene_set_free(scene_set *s)
{
    sw_lod_cache_destroy(s->cache);
    sw_sg_bvh_free(s->bvh);
    sw_sg_scene_free(s->scene);
}

/* The iso view fitted to the scene, its eye moved to `scale` times the fitted distance. */
static sw_gpu_frame_desc view_at(const scene_set *s, double scale)
{
    sw_gpu_frame_desc d = {0};
    d.width = W;
    d.height = H;
    d.camera = sw_test_view_camera_at(s->bvh->box, 1, scale);
    d.hierarchies = s->cache;
    d.bvh = s->bvh;
    d.pool = g_pool; /* chunks look entries up and add them at once */
    return d;
}

/* One frame on both contexts, compared; the cached frame's stats. */
static sw_gpu_frame_stats frame_pair(sw_gpu_context *cached, sw_gpu_context *plain,
                                     const scene_set *s, const sw_gpu_frame_desc *d,
                                     const char *what)
{
    sw_status st = {0};
    sw_gpu_image a = {0}, b = {0};
    sw_gpu_frame_stats sa = {0}, sb = {0};
    sw_result r = sw_gpu_render_scene(cached, s->scene, d, &a, &sa, &st);
    if (r == SW_OK)
        r = sw_gpu_render_scene(plain, s->scene, d, &b, &sb, &st);
    CHECK(r == SW_OK, "%s: %s", what, st.message);
    if (r == SW_OK) {
        const sw_test_image_diff diff = sw_test_compare_images(&a, &b, 0);
        CHECK(diff.any == 0 && diff.covered > 0,
              "%s: with the cache %ld pixels differ (%ld covered)", what, diff.any, diff.covered);
        CHECK(sa.triangles == sb.triangles && sa.border_triangles == sb.border_triangles &&
                  sa.border_triangles > 0,
              "%s: triangles %llu (borders %llu) with the cache, %llu (%llu) without", what,
              (unsigned long long)sa.triangles, (unsigned long long)sa.border_triangles,
              (unsigned long long)sb.triangles, (unsigned long long)sb.border_triangles);
    }
    sw_gpu_image_free(&a);
    sw_gpu_image_free(&b);
    return sa;
}

static void views(sw_gpu_context *cached, sw_gpu_context *plain, const scene_set *s,
                  const char *name)
{
    static const double scales[N_DISTANCES] = {1.0, 0.6, 2.5, 6.0};
    char what[256];
    for (int i = 0; i < N_DISTANCES; ++i) {
        const sw_gpu_frame_desc d = view_at(s, scales[i]);
        snprintf(what, sizeof what, "%s at %.1fx", name, scales[i]);
        frame_pair(cached, plain, s, &d, what);
    }
    /* the first view again: every entry and sample set is there already */
    const sw_gpu_frame_desc d = view_at(s, scales[0]);
    const size_t before = sw__fr_border_cache_bytes(cached->borders);
    const sw_gpu_frame_stats again = frame_pair(cached, plain, s, &d, name);
    const size_t after = sw__fr_border_cache_bytes(cached->borders);
    CHECK(before > 0 && after == before,
          "%s: the cache held %zu bytes, and %zu after the same view again", name, before, after);
    CHECK(again.border_loops_kept > 0 && again.border_loops_made == 0,
          "%s: the same view again placed %llu loops from kept samples and made %llu", name,
          (unsigned long long)again.border_loops_kept, (unsigned long long)again.border_loops_made);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s MODEL OTHER_MODEL\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *cached = NULL, *plain = NULL;
    sw_th_pool_desc pd = {0};
    sw_sg_import_desc id = {argv[1], NULL, NULL, NULL, NULL, 0};
    sw_sg_import_desc id2 = {argv[2], NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *model = NULL, *grid = NULL, *other = NULL;
    sw_sg_grid_desc gd = {.count = 6, .dims = 2};
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK ||
        sw_gpu_context_create_headless(&cached, &st) != SW_OK ||
        sw_gpu_context_create_headless(&plain, &st) != SW_OK ||
        sw_sg_import_file(&id, &model, NULL, &st) != SW_OK ||
        sw_sg_import_file(&id2, &other, NULL, &st) != SW_OK ||
        sw_sg_generate_grid(model, &gd, &grid, NULL, &st) != SW_OK) {
        fprintf(stderr, "FAIL: pool, contexts, import or grid: %s\n", st.message);
        return 1;
    }
    sw__fr_border_cache_set_budget(plain->borders, 0); /* off */
    scene_set a = {0}, b = {0}, c = {0};
    if (scene_set_make(model, &a) && scene_set_make(grid, &b) && scene_set_make(other, &c)) {
        views(cached, plain, &a, "model");
        views(cached, plain, &b, "grid of 6");
        views(cached, plain, &c, "other model");
        views(cached, plain, &a, "model again");
        /* over the budget: emptied before the next frame, which then draws the same */
        const size_t full = sw__fr_border_cache_bytes(cached->borders);
        sw__fr_border_cache_set_budget(cached->borders, full / 4);
        const sw_gpu_frame_desc d = view_at(&a, 2.5);
        frame_pair(cached, plain, &a, &d, "over the budget");
        const size_t after = sw__fr_border_cache_bytes(cached->borders);
        CHECK(after < full, "over the budget: %zu bytes before the frame, %zu after", full, after);
        /* a budget the entries kept already exceed, and views alternating between distances
         * whose entries are not all kept: each frame could add some, if the cache still added */
        sw__fr_border_cache_set_budget(cached->borders, 1);
        size_t last = after;
        for (int k = 0; k < 4; ++k) {
            const sw_gpu_frame_desc dk = view_at(&a, k % 2 ? 0.6 : 6.0);
            frame_pair(cached, plain, &a, &dk, "over the budget, alternating views");
            const size_t now = sw__fr_border_cache_bytes(cached->borders);
            CHECK(now <= last, "over a budget of 1 byte: %zu bytes after a frame, then %zu", last,
                  now);
            last = now;
        }
        printf("cache: %zu bytes after the views, %zu after the frame over a budget of %zu\n", full,
               after, full / 4);
    }
    scene_set_free(&a);
    scene_set_free(&b);
    scene_set_free(&c);
    sw_gpu_context_free(cached);
    sw_gpu_context_free(plain);
    sw_th_pool_destroy(g_pool);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}

/* SPDX-License-Identifier: MIT */
/* Walkthrough mode (ARCHITECTURE.md "two modes of the same pipeline"; the walkthrough
 * behaviour at the frame level): frames drawn through the hierarchy cache with desc.walkthrough
 * never wait for the worker pool, whatever is missing.
 *  1. A fast orbit (FRAMES_MOVING frames, 11° apart, distance swinging between 0.35 and 1.1 of
 *     the fitted distance) starting with an empty cache: every frame must report 0 pool waits and
 *     0 ms blocked (sw_gpu_frame_stats.pool_waits / ms_pool_wait / ms_hierarchy, counted wherever
 *     the frame's threads block on the pool: group waits that find tasks pending, bracketed waits
 *     on tasks' results; the old hlod_waits was counted on the converged branch only,
 *     so this test passed by construction). It catches a walkthrough frame that waits for a
 *     build: planted as a converged-style wait for one face's hierarchy in the walkthrough
 *     requests (stage_hierarchy.c request_walkthrough), it fails with "waits 1". And the
 *     first frames must really have drawn fallbacks (faces without a hierarchy yet, drawn by their
 *     Bézier patches; leaves too coarse, drawn as they are and queued for refinement) — else the
 *     test would not test anything.
 *  2. The camera stops: within FRAMES_SETTLE frames the fallbacks must fall to 0 (the pool
 *     finished what the view needs while frames went on), and that frame must match a converged
 *     frame of the same view drawn with a fresh cache: at most 0.1 % of the covered pixels differ
 *     (coverage, or a channel by more than 8 levels). That converged frame must itself count its
 *     waits for the fresh cache's builds (pool_waits > 0, ms_hierarchy > 0): the counter is alive.
 *
 * Usage: test_gpu_walkthrough OUTDIR MODEL [FRAMES_MOVING [WxH]]
 * (default 40 frames at 480x270; .ci/run's ThreadSanitizer build runs 2,000 at 320x240, its
 * "pipeline under ThreadSanitizer").
 */
#include "gpu_test_compare.h"
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { FRAMES_SETTLE = 30 };
static int frame_w = 480, frame_h = 270, frames_moving = 40;

static sw_gpu_camera orbit_camera(const double box[6], int i)
{
    sw_gpu_camera c = sw_test_view_camera(box, 1);
    double d[3], a = (11.0 * i) * M_PI / 180.0, s = 0.725 + 0.375 * cos(0.37 * i);
    for (int k = 0; k < 3; ++k)
        d[k] = c.eye[k] - c.target[k];
    double x = d[0] * cos(a) - d[1] * sin(a), y = d[0] * sin(a) + d[1] * cos(a);
    c.eye[0] = c.target[0] + s * x;
    c.eye[1] = c.target[1] + s * y;
    c.eye[2] = c.target[2] + s * d[2];
    return c;
}

static uint64_t fallbacks(const sw_gpu_frame_stats *fs)
{
    return fs->hlod_fallback_faces + fs->hlod_refine_requests;
}

static int frame(sw_gpu_context *ctx, const sw_sg_scene *scene, sw_lod_cache *cache,
                 sw_gpu_camera cam, int walkthrough, sw_gpu_image *img, sw_gpu_frame_stats *fs)
{
    sw_gpu_frame_desc d;
    memset(&d, 0, sizeof d);
    d.width = frame_w;
    d.height = frame_h;
    d.camera = cam;
    d.hierarchies = cache;
    d.walkthrough = walkthrough;
    sw_status st = {0};
    if (sw_gpu_render_scene(ctx, scene, &d, img, fs, &st) != SW_OK) {
        fprintf(stderr, "render: %s\n", st.message);
        return 0;
    }
    return 1;
}

static int moving(sw_gpu_context *ctx, const sw_sg_scene *scene, sw_lod_cache *cache,
                  const double box[6])
{
    uint64_t waits = 0, first_fallbacks = 0, total_fallbacks = 0;
    double blocked_ms = 0.0;
    for (int i = 0; i < frames_moving; ++i) {
        sw_gpu_image img;
        sw_gpu_frame_stats fs;
        if (!frame(ctx, scene, cache, orbit_camera(box, i), 1, &img, &fs))
            return 0;
        sw_gpu_image_free(&img);
        waits += fs.pool_waits;
        blocked_ms += fs.ms_pool_wait + fs.ms_hierarchy;
        total_fallbacks += fallbacks(&fs);
        if (i == 0)
            first_fallbacks = fallbacks(&fs);
    }
    int ok = waits == 0 && blocked_ms == 0.0 && first_fallbacks > 0;
    printf("moving: %d frames, waits %llu (%.1f ms blocked), fallbacks in the first frame %llu, "
           "in all %llu%s\n",
           frames_moving, (unsigned long long)waits, blocked_ms,
           (unsigned long long)first_fallbacks, (unsigned long long)total_fallbacks,
           ok ? "" : "  <-- FAIL");
    return ok;
}

static int settling(sw_gpu_context *ctx, const sw_sg_scene *scene, sw_lod_cache *cache,
                    const double box[6], sw_th_pool *pool, const char *outdir)
{
    sw_gpu_camera cam = orbit_camera(box, frames_moving);
    sw_gpu_image walk = {0}, conv = {0};
    sw_gpu_frame_stats fs;
    int settled = -1;
    for (int i = 0; i < FRAMES_SETTLE && settled < 0; ++i) {
        sw_gpu_image_free(&walk);
        if (!frame(ctx, scene, cache, cam, 1, &walk, &fs))
            return 0;
        if (fs.pool_waits != 0 || fs.ms_pool_wait != 0.0) {
            printf("settling frame %d waited %llu times  <-- FAIL\n", i,
                   (unsigned long long)fs.pool_waits);
            return 0;
        }
        if (fallbacks(&fs) == 0)
            settled = i;
    }
    sw_lod_cache *fresh = NULL;
    sw_status st = {0};
    int ok = settled >= 0 && sw_lod_cache_create(scene, pool, NULL, &fresh, &st) == SW_OK &&
             frame(ctx, scene, fresh, cam, 0, &conv, &fs);
    sw_test_image_diff df = {0, 0, 0, 0};
    if (ok)
        df = sw_test_compare_images(&walk, &conv, 8);
    double frac = (double)df.differ / (double)(df.covered ? df.covered : 1);
    const int counted = ok && fs.pool_waits > 0 && fs.ms_hierarchy > 0.0;
    printf("converged frame with a fresh cache: %llu pool waits, %.1f ms in hierarchy waits%s\n",
           (unsigned long long)fs.pool_waits, fs.ms_hierarchy, counted ? "" : "  <-- FAIL");
    ok = ok && counted && df.covered > 1000 && frac <= 1e-3;
    printf("stopped: fallbacks 0 after %d frames (limit %d); vs converged: %ld of %ld covered "
           "pixels differ (%.4f %%, limit 0.1 %%)%s\n",
           settled + 1, FRAMES_SETTLE, df.differ, df.covered, 100.0 * frac, ok ? "" : "  <-- FAIL");
    char path[1100];
    snprintf(path, sizeof path, "%s/walkthrough_settled.png", outdir);
    if (walk.rgba)
        sw_gpu_image_write(&walk, path, &st);
    sw_gpu_image_free(&walk);
    sw_gpu_image_free(&conv);
    sw_lod_cache_destroy(fresh);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc > 5 || (argc > 3 && sscanf(argv[3], "%d", &frames_moving) != 1) ||
        (argc > 4 && sscanf(argv[4], "%dx%d", &frame_w, &frame_h) != 2) || frames_moving < 1 ||
        frame_w < 16 || frame_h < 16) {
        fprintf(stderr, "usage: %s OUTDIR MODEL [FRAMES_MOVING [WxH]]\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_sg_import_desc id = {argv[2], NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL;
    if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
        fprintf(stderr, "FAIL: import %s: %s\n", argv[2], st.message);
        return 1;
    }
    sw_sg_scene_stats ss;
    sw_sg_scene_compute_stats(scene, &ss);
    sw_gpu_context *ctx = NULL;
    sw_th_pool *pool = NULL;
    sw_lod_cache *cache = NULL;
    sw_th_pool_desc pd = {0};
    int ok = sw_gpu_context_create_headless(&ctx, &st) == SW_OK &&
             sw_th_pool_create(&pd, &pool) == SW_OK &&
             sw_lod_cache_create(scene, pool, NULL, &cache, &st) == SW_OK;
    if (!ok)
        fprintf(stderr, "set-up: %s\n", st.message);
    ok = ok && moving(ctx, scene, cache, ss.bbox);
    ok = ok && settling(ctx, scene, cache, ss.bbox, pool, argv[1]);
    sw_lod_cache_destroy(cache);
    sw_th_pool_destroy(pool);
    sw_gpu_context_free(ctx);
    sw_sg_scene_free(scene);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

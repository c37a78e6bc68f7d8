/* SPDX-License-Identifier: MIT */
/* bench/prepare: what the visibility thread spends on a frame, sw_gpu_frame_prepare (cull, select,
 * tessellate with the fat borders of Guthe et al. 2005 §7.1, trim plan), in thread CPU time, so
 * that other processes on the machine move the figure little. Views: an orbit of N cameras
 * around the scene box (elevation 30°). Each scene runs in two modes:
 *   direct     every face by its own Bézier patches (what walkthrough frames draw while the
 *              hierarchies are still being built)
 *   hierarchy  the bicubic hierarchies (Guthe §6–7), converged: a first unmeasured pass builds
 *              and refines them, so the measured passes only traverse
 * and, in alternating passes, A/B of the fat borders of affine faces (planes): by their loop's
 * vertices (on, the default) or sampled at the grid's cells as curved faces are (off). One
 * submitted frame per variant gives the triangles and the pixels the two variants differ in.
 * Usage: bench_prepare [--views N] [--passes P] [--size WxH] FILE...   (.brep/.step/.igs, .sws)
 */
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"
#include "sw_th_pool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { MAX_VIEWS = 256, MAX_PASSES = 16 };

static double thread_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static sw_gpu_camera orbit_camera(const double box[6], int i, int n)
{
    const double a = 2.0 * M_PI * i / n, up[3] = {0, 0, 1};
    const double from[3] = {cos(a), sin(a), tan(M_PI / 6.0)};
    sw_gpu_camera c;
    sw_gpu_camera_fit_box(box, from, up, &c);
    return c;
}

typedef struct bench {
    sw_gpu_context *ctx;
    const sw_sg_scene *scene;
    sw_gpu_frame_desc desc;
    double box[6];
    int views;
} bench;

/* One pass over the orbit; adds each prepare's thread CPU time to ms (NULL: unmeasured). */
static int pass(bench *b, double *ms)
{
    for (int i = 0; i < b->views; ++i) {
        b->desc.camera = orbit_camera(b->box, i, b->views);
        sw_status st = {0};
        sw_gpu_frame_plan *plan = NULL;
        double t0 = thread_cpu_ms();
        if (sw_gpu_frame_prepare(b->ctx, b->scene, &b->desc, &plan, &st) != SW_OK) {
            fprintf(stderr, "prepare: %s\n", st.message);
            return 0;
        }
        double t1 = thread_cpu_ms();
        sw_gpu_frame_plan_free(plan);
        if (ms)
            ms[i] = t1 - t0;
    }
    return 1;
}

/* View 0 submitted with the affine path on and off: triangles of each, differing pixels. */
static int compare_images(bench *b)
{
    sw_gpu_image img[2];
    sw_gpu_frame_stats fs[2];
    b->desc.camera = orbit_camera(b->box, 0, b->views);
    b->desc.no_readback = 0;
    for (int k = 0; k < 2; ++k) {
        sw_status st = {0};
        sw__gpu_set_border_affine(b->ctx, k == 0);
        if (sw_gpu_render_scene(b->ctx, b->scene, &b->desc, &img[k], &fs[k], &st) != SW_OK) {
            fprintf(stderr, "render: %s\n", st.message);
            if (k)
                sw_gpu_image_free(&img[0]);
            return 0;
        }
    }
    size_t differ = 0, n = (size_t)img[0].width * (size_t)img[0].height;
    for (size_t i = 0; i < n; ++i)
        differ += memcmp(img[0].rgba + 4 * i, img[1].rgba + 4 * i, 4) != 0;
    printf("    view 0: triangles on %llu, off %llu; %zu of %zu pixels differ\n",
           (unsigned long long)fs[0].triangles, (unsigned long long)fs[1].triangles, differ, n);
    sw_gpu_image_free(&img[0]);
    sw_gpu_image_free(&img[1]);
    sw__gpu_set_border_affine(b->ctx, 1);
    b->desc.no_readback = 1;
    return 1;
}

static int run_mode(bench *b, const char *mode, int passes)
{
    static double ms[2][MAX_PASSES * MAX_VIEWS];
    int n[2] = {0, 0};
    if (!pass(b, NULL)) /* warm-up: hierarchies built and refined, buffers grown */
        return 0;
    for (int p = 0; p < passes; ++p)
        for (int k = 0; k < 2; ++k) { /* on, off: alternating, side by side */
            sw__gpu_set_border_affine(b->ctx, k == 0);
            if (!pass(b, ms[k] + n[k]))
                return 0;
            n[k] += b->views;
        }
    sw__gpu_set_border_affine(b->ctx, 1);
    double on = median(ms[0], n[0]), off = median(ms[1], n[1]);
    printf("  %-9s prepare, thread CPU ms, median of %d: affine borders on %.2f, off %.2f "
           "(on/off %.3f)\n",
           mode, n[0], on, off, off > 0.0 ? on / off : 0.0);
    return compare_images(b);
}

static int bench_scene(sw_gpu_context *ctx, sw_th_pool *pool, const char *path, int w, int h,
                       int views, int passes)
{
    sw_status st = {0};
    sw_sg_import_desc id = {path, NULL, NULL, NULL};
    sw_sg_scene *scene = NULL;
    size_t len = strlen(path);
    sw_result r = len > 4 && strcmp(path + len - 4, ".sws") == 0
                      ? sw_sg_scene_open(path, &scene, &st)
                      : sw_sg_import_file(&id, &scene, NULL, &st);
    if (r == SW_OK)
        r = sw_sg_scene_require(scene, SW_SG_SEC_ALL, &st);
    if (r != SW_OK) {
        fprintf(stderr, "%s: %s\n", path, st.message);
        sw_sg_scene_free(scene);
        return 0;
    }
    sw_sg_scene_stats ss;
    sw_sg_scene_compute_stats(scene, &ss);
    bench b = {ctx, scene, {0}, {0}, views};
    memcpy(b.box, ss.bbox, sizeof b.box);
    b.desc.width = w;
    b.desc.height = h;
    b.desc.no_readback = 1;
    printf("%s (%u faces):\n", path, ss.faces);
    int ok = run_mode(&b, "direct", passes);
    sw_lod_cache *cache = NULL;
    if (ok && sw_lod_cache_create(scene, pool, NULL, &cache, &st) != SW_OK) {
        fprintf(stderr, "%s: %s\n", path, st.message);
        ok = 0;
    }
    if (ok) {
        b.desc.hierarchies = cache;
        ok = run_mode(&b, "hierarchy", passes);
    }
    sw_lod_cache_destroy(cache);
    sw_sg_scene_free(scene);
    return ok;
}

int main(int argc, char **argv)
{
    int views = 24, passes = 2, w = 1280, h = 720, first = 1;
    for (; first < argc && strncmp(argv[first], "--", 2) == 0; first += 2) {
        if (first + 1 >= argc)
            break;
        if (strcmp(argv[first], "--views") == 0)
            views = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--passes") == 0)
            passes = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--size") == 0 &&
                 sscanf(argv[first + 1], "%dx%d", &w, &h) == 2)
            continue;
        else
            break;
    }
    if (first >= argc || views < 1 || views > MAX_VIEWS || passes < 1 || passes > MAX_PASSES ||
        w < 1 || h < 1) {
        fprintf(stderr, "usage: %s [--views N<=%d] [--passes P<=%d] [--size WxH] FILE...\n",
                argv[0], MAX_VIEWS, MAX_PASSES);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    sw_th_pool_desc pd = {0};
    pd.worker_count = 1;
    sw_th_pool *pool = NULL;
    if (sw_th_pool_create(&pd, &pool) != SW_OK) {
        fprintf(stderr, "pool: cannot start\n");
        sw_gpu_context_free(ctx);
        return 1;
    }
    printf("%s, %dx%d, ε_img default, %d views, %d passes per variant\n",
           sw_gpu_context_description_ptr(ctx), w, h, views, passes);
    int ok = 1;
    for (int a = first; a < argc && ok; ++a)
        ok = bench_scene(ctx, pool, argv[a], w, h, views, passes);
    sw_th_pool_destroy(pool);
    sw_gpu_context_free(ctx);
    return ok ? 0 : 1;
}

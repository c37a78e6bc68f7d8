/* SPDX-License-Identifier: MIT */
/* bench/prepare: what the visibility thread spends on a frame, sw_gpu_frame_prepare (cull, select,
 * tessellate with the fat borders of Guthe et al. 2005 §7.1, trim plan), in thread CPU time, so
 * that other processes on the machine move the figure little. Views: an orbit of N cameras
 * around the scene box (elevation 30°). Each scene runs in two modes:
 *   direct     every face by its own Bézier patches (what walkthrough frames draw while the
 *              hierarchies are still being built)
 *   hierarchy  the bicubic hierarchies (Guthe §6–7), converged: a first unmeasured pass builds
 *              and refines them, so the measured passes only traverse
 * and, in alternating passes, two A/B pairs:
 *   affine     fat borders of affine faces (planes) by their loop's vertices (on, the default)
 *              or sampled at the grid's cells as curved faces are (off), on one thread; one
 *              submitted frame per variant gives the triangles and the pixels they differ in;
 *   chunks     three variants: the faces tessellated by the preparing thread alone, or in
 *              chunks shared with a pool (desc.pool) of 1 worker, or of 2 (the parallel
 *              visibility stage on one and two more threads), with the join's wait (ms_join);
 *   density    planes' patches given the coarsest grid by the affine test (fast, the default) or
 *              by the full screen-space bound (lod/bezier/sampling.c sw_lod_screen_affine_fast), on
 * one thread, with the triangles and differing pixels of view 0 as for affine; borders    the
 * border cache (gpu/border_cache.c: loops and samples kept between frames) on, the default, or off,
 * on one thread; each variant's passes one after another, so that the cache keeps what its own
 * passes made (its first pass starts empty). Each variant prints the median of the prepare's wall
 * time, of the preparing thread's CPU time, of the process's CPU time (every thread: the pool's
 * share of the work included, so the split's extra work shows) and of the wait at the
 * tessellation's join.
 *
 * --callgrind W: only the measured prepares of the direct mode (after its warm-up; the hierarchy
 * mode's cut depends on when its builds end), with the chunks shared with a pool of W workers
 * (0: the preparing thread alone), the only code callgrind instruments, so that the instructions
 * of every thread that worked on them are counted (its collect toggles act on the calling thread
 * only: the workers' chunks were missed, 0.82x with 2 workers):
 *   valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file=cg.W \
 *     build/bin/bench_prepare --callgrind W --views 4 --passes 1 FILE
 * ("summary:" in cg.W is the total). The split's extra work is the ratio of two such totals.
 * Usage: bench_prepare [--views N] [--passes P] [--size WxH] [--callgrind W] FILE...
 *        (.brep/.step/.igs imported, .sws opened)
 */
#include "cli_numbers.h"
#include "sw_lod_sampling.h"
#include "bench_stats.h"
#include "frame_stages.h"
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"
#include "sw_th_pool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <valgrind/callgrind.h>

enum { MAX_VIEWS = 256, MAX_PASSES = 16 };

static double clock_ms(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

enum { WALL, THREAD, PROCESS, N_CLOCKS };
static const clockid_t k_clocks[N_CLOCKS] = {CLOCK_MONOTONIC, CLOCK_THREAD_CPUTIME_ID,
                                             CLOCK_PROCESS_CPUTIME_ID};

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
    sw_th_pool *workers[2]; /* pools of 1 and 2 workers for the chunks */
    const sw_sg_scene *scene;
    sw_gpu_frame_desc desc;
    double box[6];
    int views;
    int callgrind; /* -1: off; else the workers of the counted prepares */
} bench;

/* Times of one variant, per clock, over its passes, and the waits at the join. */
typedef struct series {
    double ms[N_CLOCKS][MAX_PASSES * MAX_VIEWS];
    double join[MAX_PASSES * MAX_VIEWS];
    int n;
} series;

/* One pass over the orbit, each prepare's times added to s (NULL: unmeasured). */
static int pass(bench *b, series *s)
{
    for (int i = 0; i < b->views; ++i) {
        b->desc.camera = orbit_camera(b->box, i, b->views);
        sw_status st = {0};
        sw_gpu_frame_plan *plan = NULL;
        double t0[N_CLOCKS], t1[N_CLOCKS];
        for (int k = 0; k < N_CLOCKS; ++k)
            t0[k] = clock_ms(k_clocks[k]);
        if (sw_gpu_frame_prepare(b->ctx, b->scene, &b->desc, &plan, &st) != SW_OK) {
            fprintf(stderr, "prepare: %s\n", st.message);
            return 0;
        }
        for (int k = 0; k < N_CLOCKS; ++k)
            t1[k] = clock_ms(k_clocks[k]);
        const double join = sw_gpu_frame_plan_stats(plan)->ms_join;
        sw_gpu_frame_plan_recycle(b->ctx, plan); /* as the renderer's visibility thread does */
        if (!s)
            continue;
        for (int k = 0; k < N_CLOCKS; ++k)
            s->ms[k][s->n] = t1[k] - t0[k];
        s->join[s->n] = join;
        s->n++;
    }
    return 1;
}

static void print_series(const char *name, series *s)
{
    printf("    %-24s wall %8.2f  thread CPU %8.2f  process CPU %8.2f  join %7.2f ms\n", name,
           bench_quantile(s->ms[WALL], s->n, 0.5), bench_quantile(s->ms[THREAD], s->n, 0.5),
           bench_quantile(s->ms[PROCESS], s->n, 0.5), bench_quantile(s->join, s->n, 0.5));
}

/* The passes of n (at most 3) variants set by set(b, 0 .. n - 1): alternating (the machine's
 * drift shared), or each variant's in a row (a cache's state carries over within its own passes
 * only); prints them all. */
static int variants(bench *b, int passes, int alternate, void (*set)(bench *, int),
                    const char *const *names, int n)
{
    static series s[3];
    for (int k = 0; k < n; ++k)
        s[k].n = 0;
    for (int i = 0; i < n * passes; ++i) {
        const int k = alternate ? i % n : i / passes;
        set(b, k);
        if (!pass(b, &s[k]))
            return 0;
    }
    set(b, 0);
    for (int k = 0; k < n; ++k)
        print_series(names[k], &s[k]);
    return 1;
}

static int ab(bench *b, int passes, void (*set)(bench *, int), const char *const names[2])
{
    return variants(b, passes, 1, set, names, 2);
}

static void set_affine(bench *b, int k)
{
    sw__gpu_set_border_affine(b->ctx, k == 0);
}

/* 0: the preparing thread alone; 1, 2: chunks shared with a pool of that many workers. */
static void set_chunks(bench *b, int k)
{
    b->desc.pool = k ? b->workers[k - 1] : NULL;
}

static void set_density(bench *b, int k)
{
    (void)b;
    sw_lod_screen_affine_fast(k == 0);
}

static void set_borders(bench *b, int k)
{
    static size_t budget;
    if (k == 1)
        budget = sw__fr_border_cache_set_budget(b->ctx->borders, 0);
    else if (budget)
        sw__fr_border_cache_set_budget(b->ctx->borders, budget);
}

/* View 0 submitted with a pair's two variants: triangles of each, differing pixels. */
static int compare_images(bench *b, void (*set)(bench *, int))
{
    sw_gpu_image img[2];
    sw_gpu_frame_stats fs[2];
    b->desc.camera = orbit_camera(b->box, 0, b->views);
    b->desc.no_readback = 0;
    for (int k = 0; k < 2; ++k) {
        sw_status st = {0};
        set(b, k);
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
    set(b, 0);
    b->desc.no_readback = 1;
    return 1;
}

/* --callgrind: the mode's measured prepares alone instrumented, the chunks shared with
 * b->workers[callgrind - 1] (0: none). */
static int counted_passes(bench *b, const char *mode, int passes)
{
    set_chunks(b, b->callgrind);
    CALLGRIND_START_INSTRUMENTATION; /* every thread's (collection state is per thread) */
    int ok = 1;
    for (int i = 0; i < passes && ok; ++i)
        ok = pass(b, NULL);
    CALLGRIND_STOP_INSTRUMENTATION;
    b->desc.pool = NULL;
    printf("  %s: %d prepares counted, chunks with %d pool workers\n", mode, passes * b->views,
           b->callgrind);
    return ok;
}

static int run_mode(bench *b, const char *mode, int passes)
{
    static const char *const affine[2] = {"affine borders on", "affine borders off"};
    static const char *const chunks[3] = {"one thread", "chunks, 1 worker", "chunks, 2 workers"};
    static const char *const density[2] = {"affine densities fast", "affine densities bounded"};
    static const char *const borders[2] = {"border cache on", "border cache off"};
    if (!pass(b, NULL)) /* warm-up: hierarchies built and refined, buffers grown */
        return 0;
    if (b->callgrind >= 0) /* the direct mode's cut is the same on every run: the hierarchy's
                              depends on when its builds end, which the workers change */
        return b->desc.hierarchies ? 1 : counted_passes(b, mode, passes);
    printf("  %s, medians of %d prepares per variant:\n", mode, passes * b->views);
    if (!ab(b, passes, set_affine, affine) || !compare_images(b, set_affine))
        return 0;
    if (!ab(b, passes, set_density, density) || !compare_images(b, set_density))
        return 0;
    if (!variants(b, passes, 0, set_borders, borders, 2) || !compare_images(b, set_borders))
        return 0;
    return variants(b, passes, 1, set_chunks, chunks, 3);
}

/* One file through both modes; tmpl gives the context, the pools and the options. */
static int bench_scene(const bench *tmpl, const char *path, int w, int h, int passes)
{
    /* the hierarchies' builds use a pool of their own, so that the chunks' pool is idle */
    sw_status st = {0};
    sw_sg_import_desc id = {.path = path};
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
    bench b = *tmpl;
    b.scene = scene;
    memcpy(b.box, ss.bbox, sizeof b.box);
    b.desc.width = w;
    b.desc.height = h;
    b.desc.no_readback = 1;
    printf("%s (%u faces):\n", path, ss.faces);
    int ok = run_mode(&b, "direct", passes);
    sw_lod_cache *cache = NULL;
    sw_th_pool *builds = NULL;
    sw_th_pool_desc pd = {0};
    pd.worker_count = 1;
    if (ok && sw_th_pool_create(&pd, &builds) != SW_OK) {
        fprintf(stderr, "pool: cannot start\n");
        ok = 0;
    }
    if (ok && sw_lod_cache_create(scene, builds, NULL, &cache, &st) != SW_OK) {
        fprintf(stderr, "%s: %s\n", path, st.message);
        ok = 0;
    }
    if (ok) {
        b.desc.hierarchies = cache;
        ok = run_mode(&b, "hierarchy", passes);
    }
    sw_lod_cache_destroy(cache);
    sw_th_pool_destroy(builds);
    sw_sg_scene_free(scene);
    return ok;
}

static sw_th_pool *make_pool(int workers)
{
    sw_th_pool_desc pd = {0};
    pd.worker_count = (uint32_t)workers;
    sw_th_pool *pool = NULL;
    return sw_th_pool_create(&pd, &pool) == SW_OK ? pool : NULL;
}

int main(int argc, char **argv)
{
    int views = 24, passes = 2, w = 1280, h = 720, callgrind = -1, first = 1;
    for (; first < argc && strncmp(argv[first], "--", 2) == 0; first += 2) {
        if (first + 1 >= argc)
            break;
        if (strcmp(argv[first], "--views") == 0)
            views = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--callgrind") == 0)
            callgrind = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--passes") == 0)
            passes = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--size") == 0 && !sw_cli_parse_size(argv[first + 1], &w, &h))
            continue;
        else
            break;
    }
    if (first >= argc || views < 1 || views > MAX_VIEWS || passes < 1 || passes > MAX_PASSES ||
        w < 1 || h < 1 || callgrind < -1 || callgrind > 2) {
        fprintf(stderr,
                "usage: %s [--views N<=%d] [--passes P<=%d] [--size WxH] [--callgrind 0|1|2] "
                "FILE...\n",
                argv[0], MAX_VIEWS, MAX_PASSES);
        return 2;
    }
    sw_status st = {0};
    bench b = {.views = views, .callgrind = callgrind};
    if (sw_gpu_context_create_headless(&b.ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    b.workers[0] = make_pool(1);
    b.workers[1] = make_pool(2);
    int ok = b.workers[0] && b.workers[1];
    if (!ok)
        fprintf(stderr, "pool: cannot start\n");
    else
        printf("%s, %dx%d, ε_img default, %d views, %d passes per variant\n",
               sw_gpu_context_description_ptr(b.ctx), w, h, views, passes);
    for (int a = first; a < argc && ok; ++a)
        ok = bench_scene(&b, argv[a], w, h, passes);
    sw_th_pool_destroy(b.workers[0]);
    sw_th_pool_destroy(b.workers[1]);
    sw_gpu_context_free(b.ctx);
    return ok ? 0 : 1;
}

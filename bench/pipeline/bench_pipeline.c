/* SPDX-License-Identifier: MIT */
/* bench/pipeline (Kumar et al. 1997 Fig. 9): frame times along one camera path with the
 * renderer's visibility thread preparing frame i+1 while the submitting thread draws frame i
 * (sw_renderer_prepare / sw_renderer_submit, "threaded"), against each frame in one call
 * (sw_renderer_draw, "sequential": prepared on the visibility thread while the caller waits, so
 * nothing overlaps), in walkthrough mode. The two modes run in
 * alternating passes over the same path in one process, each on its own renderer warmed up by one
 * pass first (hierarchies built, trim atlas filled), so that load changes hit both alike; it
 * prints each mode's median and p99 frame time and their ratio.
 *
 * Instruction counts of the submitting thread: the frame loop is bracketed by callgrind's collect
 * toggle, so
 *   valgrind --tool=callgrind --separate-threads=yes --collect-atstart=no \
 *     --callgrind-out-file=cg.out build/bin/bench_pipeline --mode threaded --frames 20 --passes 1
 * writes the main (submitting) thread's count in cg.out-01 ("summary:" line); divide by the
 * frames. Without valgrind the toggles do nothing.
 *
 * usage: bench_pipeline [SCENE] [--frames N] [--passes P] [--size WxH] [--mode
 * both|threaded|sequential] SCENE defaults to the built-in default scene (occt-misc data).
 */
#include <splinewalk/splinewalk.h>

#include "cli.h"
#include "bench_stats.h"
#include "bench_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <valgrind/callgrind.h>

typedef struct bench {
    sw_scene scene;
    sw_rt_camera_path path;
    int frames, passes, w, h;
    int threaded, sequential;
} bench;

static sw_frame_desc frame_at(const bench *b, int i)
{
    sw_frame_desc f = {0};
    f.scene = b->scene;
    f.width = b->w;
    f.height = b->h;
    f.walkthrough = 1;
    sw_rt_path_eval(&b->path, sw_rt_path_frame_time(&b->path, (uint32_t)i, (uint32_t)b->frames),
                    &f.camera);
    return f;
}

/* One pass along the path; ms[i] = the submitting thread's time for frame i. */
static int pass(const bench *b, sw_renderer r, int threaded, double *ms, double *vis,
                uint64_t *fallbacks)
{
    sw_status st = {0};
    sw_frame_desc f = frame_at(b, 0);
    if (threaded && sw_renderer_prepare(r, &f, &st) != SW_OK)
        goto fail;
    for (int i = 0; i < b->frames; ++i) {
        sw_frame_stats fs = {0};
        double t0 = bench_now_ms();
        if (threaded) {
            if (i + 1 < b->frames) {
                f = frame_at(b, i + 1);
                if (sw_renderer_prepare(r, &f, &st) != SW_OK)
                    goto fail;
            }
            if (sw_renderer_submit(r, &fs, &st) != SW_OK)
                goto fail;
        } else {
            f = frame_at(b, i);
            if (sw_renderer_draw(r, &f, &fs, &st) != SW_OK)
                goto fail;
        }
        ms[i] = bench_now_ms() - t0;
        vis[i] = fs.ms_visibility;
        *fallbacks += fs.fallback_draws;
    }
    return 0;
fail:
    fprintf(stderr, "bench_pipeline: %s\n", st.message);
    return -1;
}

typedef struct mode_result {
    double *ms, *vis;
    int n;
    uint64_t fallbacks;
} mode_result;

static int run(bench *b)
{
    const int modes[2] = {b->threaded, b->sequential};
    const char *names[2] = {"threaded", "sequential"};
    sw_renderer r[2] = {{0}, {0}};
    mode_result res[2] = {{0}};
    sw_status st = {0};
    size_t cap = (size_t)b->frames * (size_t)b->passes;
    for (int m = 0; m < 2; ++m) {
        if (!modes[m])
            continue;
        sw_renderer_desc rd = {0};
        res[m].ms = calloc(cap, sizeof(double));
        res[m].vis = calloc(cap, sizeof(double));
        if (!res[m].ms || !res[m].vis || sw_renderer_create(&rd, &r[m], &st) != SW_OK) {
            fprintf(stderr, "bench_pipeline: %s\n", st.message[0] ? st.message : "out of memory");
            return 1;
        }
        uint64_t warm = 0;
        if (pass(b, r[m], m == 0, res[m].ms, res[m].vis, &warm) != 0) /* warm-up */
            return 1;
    }
    CALLGRIND_TOGGLE_COLLECT;
    for (int p = 0; p < b->passes; ++p) {
        for (int m = 0; m < 2; ++m) {
            if (modes[m] && pass(b, r[m], m == 0, res[m].ms + res[m].n, res[m].vis + res[m].n,
                                 &res[m].fallbacks) != 0)
                return 1;
            res[m].n += modes[m] ? b->frames : 0;
        }
    }
    CALLGRIND_TOGGLE_COLLECT;
    double median[2] = {0, 0}, p99[2] = {0, 0};
    for (int m = 0; m < 2; ++m) {
        if (!modes[m])
            continue;
        median[m] = bench_quantile(res[m].ms, res[m].n, 0.5);
        p99[m] = bench_quantile(res[m].ms, res[m].n, 0.99);
        double vmed = bench_quantile(res[m].vis, res[m].n, 0.5);
        printf("%-10s frames %d: median %.2f ms, p99 %.2f ms; visibility + selection + "
               "tessellation median %.2f ms (%s); fallback draws %llu\n",
               names[m], res[m].n, median[m], p99[m], vmed,
               m == 0 ? "on the visibility thread" : "on the frame's thread",
               (unsigned long long)res[m].fallbacks);
        sw_renderer_destroy(r[m]);
        free(res[m].ms);
        free(res[m].vis);
    }
    if (modes[0] && modes[1])
        printf("threaded / sequential: median %.3f, p99 %.3f\n", median[0] / median[1],
               p99[0] / p99[1]);
    return 0;
}

static int parse(int argc, char **argv, bench *b, const char **scene)
{
    *b = (bench){.frames = 120, .passes = 3, .w = 1280, .h = 720, .threaded = 1, .sequential = 1};
    for (int i = 1; i < argc; ++i) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (bench_common_option(argc, argv, &i, &b->frames, &b->passes, &b->w, &b->h))
            continue;
        else if (!strcmp(argv[i], "--mode") && v) {
            const char *m = argv[++i];
            b->threaded = strcmp(m, "sequential") != 0;
            b->sequential = strcmp(m, "threaded") != 0;
        } else if (argv[i][0] != '-' && !*scene)
            *scene = argv[i];
        else
            return -1;
    }
    return b->frames >= 2 && b->passes >= 1 && b->w > 0 && b->h > 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    sw_cli_install_modules(); /* CAD files, .exr, static LOD builds */
    bench b;
    const char *scene_path = NULL;
    if (parse(argc, argv, &b, &scene_path) != 0) {
        fprintf(stderr, "usage: %s [SCENE] [--frames N] [--passes P] [--size WxH] "
                        "[--mode both|threaded|sequential]\n",
                argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_result r = bench_scene_orbit(scene_path, 1.0, b.frames, &b.scene, &b.path, &st);
    if (r != SW_OK) {
        fprintf(stderr, "bench_pipeline: %s\n", st.message);
        return 1;
    }
    const char *lp = getenv("LP_NUM_THREADS");
    printf("bench_pipeline: %s, orbit of %d frames at %dx%d, walkthrough, error 0.5 px, %d "
           "passes per mode alternating, renderer pools of one worker per processor, "
           "LP_NUM_THREADS=%s\n",
           scene_path ? scene_path : "default scene", b.frames, b.w, b.h, b.passes,
           lp ? lp : "(unset)");
    int rc = run(&b);
    sw_rt_path_free(&b.path);
    sw_scene_destroy(b.scene);
    return rc;
}

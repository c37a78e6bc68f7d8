/* SPDX-License-Identifier: MIT */
/* bench/lod (Kumar et al. 1997 §6: "40-50 % better" with static LODs): frame times along
 * one camera path at ε_img = 0.5 px with the static LODs of super-surfaces on and off, threaded
 * walkthrough frames (sw_renderer_prepare / submit), in alternating passes over the same path in
 * one process, each mode on its own renderer. Both are warmed up first: one converged pass with
 * static LODs (every level the path needs is built: static LOD building is preprocessing, as
 * `build-lod` does it) and one walkthrough pass each (hierarchies built, trim atlas filled). Prints
 * per mode the median and p99 frame time, the visibility thread's median time per frame (culling:
 * with static LODs by the BVH of super-surface instances, level choice, tessellation), triangles
 * and static draws per frame, and the ratios.
 *
 * usage: bench_lod [SCENE] [--frames N] [--passes P] [--size WxH] [--distance F]
 * SCENE defaults to the built-in default scene (occt-misc data); the path is an orbit fitted to
 * the scene's box at F (default 1) times the fitted distance.
 */
#include <splinewalk/splinewalk.h>

#include "cli.h"
#include "bench_stats.h"
#include "bench_scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct bench {
    sw_scene scene;
    sw_rt_camera_path path;
    int frames, passes, w, h;
    double distance;
} bench;

typedef struct mode_result {
    double *ms, *vis; /* per frame: the submitting thread's time, the visibility thread's */
    int n;
    uint64_t triangles, static_drawn, static_faces, faces, fallbacks, waits;
} mode_result;

static sw_frame_desc frame_at(const bench *b, int i, int statics, int walkthrough)
{
    sw_frame_desc f = {0};
    f.scene = b->scene;
    f.width = b->w;
    f.height = b->h;
    f.walkthrough = walkthrough;
    f.static_lods = statics;
    sw_rt_path_eval(&b->path, sw_rt_path_frame_time(&b->path, (uint32_t)i, (uint32_t)b->frames),
                    &f.camera);
    return f;
}

static void account(mode_result *res, int frame, const sw_frame_stats *fs)
{
    res->vis[res->n + frame] = fs->ms_visibility;
    res->triangles += fs->triangles;
    res->static_drawn += fs->static_drawn;
    res->static_faces += fs->static_faces;
    res->faces += fs->faces_drawn;
    res->fallbacks += fs->fallback_draws;
    res->waits += fs->pool_waits;
}

/* One threaded walkthrough pass; ms[i] = the submitting thread's time for frame i (NULL: warm-up,
 * not counted). */
static int pass(const bench *b, sw_renderer r, int statics, double *ms, mode_result *res)
{
    sw_status st = {0};
    sw_frame_desc f = frame_at(b, 0, statics, 1);
    if (sw_renderer_prepare(r, &f, &st) != SW_OK)
        goto fail;
    for (int i = 0; i < b->frames; ++i) {
        sw_frame_stats fs = {0};
        const double t0 = bench_now_ms();
        if (i + 1 < b->frames) {
            f = frame_at(b, i + 1, statics, 1);
            if (sw_renderer_prepare(r, &f, &st) != SW_OK)
                goto fail;
        }
        if (sw_renderer_submit(r, &fs, &st) != SW_OK)
            goto fail;
        if (ms) {
            ms[i] = bench_now_ms() - t0;
            account(res, i, &fs);
        }
    }
    return 0;
fail:
    fprintf(stderr, "bench_lod: %s\n", st.message);
    return -1;
}

/* Converged frames along the path with static LODs: every unit the path shows near enough is
 * built (the frames wait for them). */
static int build_static(const bench *b, sw_renderer r)
{
    const double t0 = bench_now_ms();
    for (int i = 0; i < b->frames; ++i) {
        sw_status st = {0};
        sw_frame_desc f = frame_at(b, i, 1, 0);
        if (sw_renderer_draw(r, &f, NULL, &st) != SW_OK) {
            fprintf(stderr, "bench_lod: %s\n", st.message);
            return -1;
        }
        if (i % 10 == 9 || i + 1 == b->frames)
            fprintf(stderr, "\rbench_lod: static LODs along the path: frame %d / %d, %.0f s", i + 1,
                    b->frames, 1e-3 * (bench_now_ms() - t0));
    }
    fprintf(stderr, "\n");
    printf(
        "static LOD preprocessing along the path (converged frames, builds in the pool): %.1f s\n",
        1e-3 * (bench_now_ms() - t0));
    return 0;
}

static void report(const char *name, mode_result *res)
{
    const double n = res->n > 0 ? res->n : 1;
    printf("%-12s frames %d: median %.2f ms, p99 %.2f ms (visibility thread median %.2f ms); per "
           "frame %.0f triangles, %.1f super-surfaces static (%.1f of %.1f faces), fallback draws "
           "%.1f, pool waits %llu\n",
           name, res->n, bench_quantile(res->ms, res->n, 0.5),
           bench_quantile(res->ms, res->n, 0.99), bench_quantile(res->vis, res->n, 0.5),
           res->triangles / n, res->static_drawn / n, res->static_faces / n, res->faces / n,
           res->fallbacks / n, (unsigned long long)res->waits);
}

static int run(bench *b)
{
    const char *names[2] = {"static on", "static off"};
    sw_renderer r[2] = {{0}, {0}};
    mode_result res[2] = {{0}};
    sw_status st = {0};
    const size_t cap = (size_t)b->frames * (size_t)b->passes;
    for (int m = 0; m < 2; ++m) {
        res[m].ms = calloc(cap, sizeof(double));
        res[m].vis = calloc(cap, sizeof(double));
        if (!res[m].ms || !res[m].vis || sw_renderer_create(NULL, &r[m], &st) != SW_OK) {
            fprintf(stderr, "bench_lod: %s\n", st.message[0] ? st.message : "out of memory");
            return 1;
        }
        if ((m == 0 && build_static(b, r[m]) != 0) || pass(b, r[m], m == 0, NULL, NULL) != 0)
            return 1;
    }
    for (int p = 0; p < b->passes; ++p)
        for (int m = 0; m < 2; ++m) {
            if (pass(b, r[m], m == 0, res[m].ms + res[m].n, &res[m]) != 0)
                return 1;
            res[m].n += b->frames;
        }
    double median[2], p99[2];
    for (int m = 0; m < 2; ++m) {
        report(names[m], &res[m]);
        median[m] = bench_quantile(res[m].ms, res[m].n, 0.5);
        p99[m] = bench_quantile(res[m].ms, res[m].n, 0.99);
        sw_renderer_destroy(r[m]);
        free(res[m].ms);
        free(res[m].vis);
    }
    printf("static on / off: median %.3f, p99 %.3f, triangles %.3f\n", median[0] / median[1],
           p99[0] / p99[1],
           (double)res[0].triangles / (double)(res[1].triangles ? res[1].triangles : 1));
    return 0;
}

static int parse(int argc, char **argv, bench *b, const char **scene)
{
    *b = (bench){.frames = 120, .passes = 3, .w = 1280, .h = 720, .distance = 1.0};
    for (int i = 1; i < argc; ++i) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (bench_common_option(argc, argv, &i, &b->frames, &b->passes, &b->w, &b->h))
            continue;
        else if (!strcmp(argv[i], "--distance") && v)
            b->distance = atof(argv[++i]);
        else if (argv[i][0] != '-' && !*scene)
            *scene = argv[i];
        else
            return -1;
    }
    return b->frames >= 2 && b->passes >= 1 && b->w > 0 && b->h > 0 && b->distance > 0.0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    sw_cli_install_modules(); /* CAD files, .exr, static LOD builds */
    bench b;
    const char *scene_path = NULL;
    if (parse(argc, argv, &b, &scene_path) != 0) {
        fprintf(stderr, "usage: %s [SCENE] [--frames N] [--passes P] [--size WxH] [--distance F]\n",
                argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_result r = bench_scene_orbit(scene_path, b.distance, b.frames, &b.scene, &b.path, &st);
    if (r != SW_OK) {
        fprintf(stderr, "bench_lod: %s\n", st.message);
        return 1;
    }
    const char *lp = getenv("LP_NUM_THREADS");
    printf("bench_lod: %s, orbit of %d frames at %dx%d, %.3g x the fitted distance, threaded "
           "walkthrough, error 0.5 px, %d passes per mode alternating, pools of one worker per "
           "processor, LP_NUM_THREADS=%s\n",
           scene_path ? scene_path : "default scene", b.frames, b.w, b.h, b.distance, b.passes,
           lp ? lp : "(unset)");
    int rc = run(&b);
    sw_rt_path_free(&b.path);
    sw_scene_destroy(b.scene);
    return rc;
}

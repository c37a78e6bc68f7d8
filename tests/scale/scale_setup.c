/* SPDX-License-Identifier: MIT */
/* scale_setup: what a renderer builds for a scene before its first frame, stage by stage, with the
 * time and the resident memory each stage adds (large-model readiness). Not a test: it
 * prints figures for the README's memory table and for deciding what must be lazy.
 *
 * The stages are those of runtime/src/api_render.c (renderer_cache) after the public API's load:
 *   open      sw_sg_scene_open: maps the .sws (nothing read yet)
 *   verify    sw_sg_scene_require(SW_SG_SEC_ALL): checksums and validation (touches every page)
 *   stats     sw_sg_scene_compute_stats: what the public API's first acquire of a scene computes
 *             (api_scene.c make_ready) before any frame: Bézier extraction of every face
 *   cache     sw_lod_cache_create: one slot per face, hierarchies built later on first sight
 *   bvh       sw_sg_bvh_build: every face occurrence (instances expanded)
 *   cones     sw_lod_face_cones_build: the back-patch cones of closed-shell faces
 *
 * usage: scale_setup SCENE.sws
 */
#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_sg_bvh.h"
#include "sw_sg_scene.h"
#include "sw_th_pool.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static double clock_ms(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static double now_ms(void)
{
    return clock_ms(CLOCK_MONOTONIC);
}

/* This thread's CPU time: on a machine shared with other work, steadier than the wall clock
 * (every stage but the cache's creation runs on this thread). */
static double cpu_ms(void)
{
    return clock_ms(CLOCK_THREAD_CPUTIME_ID);
}

/* A /proc/self/status field in KiB (VmRSS, VmHWM), or -1. */
static long status_kib(const char *field)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f)
        return -1;
    char line[256];
    long v = -1;
    const size_t n = strlen(field);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, field, n) && line[n] == ':') {
            v = strtol(line + n + 1, NULL, 10);
            break;
        }
    fclose(f);
    return v;
}

typedef struct stage {
    double t0, cpu0;
    long rss0;
} stage;

static stage stage_begin(void)
{
    stage s = {now_ms(), cpu_ms(), status_kib("VmRSS")};
    return s;
}

static void stage_end(const stage *s, const char *name, size_t own_bytes)
{
    const long rss = status_kib("VmRSS");
    printf("  %-8s %9.1f ms wall %9.1f ms cpu   RSS %+8.1f MiB -> %7.1f MiB", name,
           now_ms() - s->t0, cpu_ms() - s->cpu0, (double)(rss - s->rss0) / 1024.0,
           (double)rss / 1024.0);
    if (own_bytes)
        printf("   (own %.1f MiB)", (double)own_bytes / 1048576.0);
    printf("\n");
}

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "scale_setup: %s: %s\n", what, st->message);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: scale_setup SCENE.sws\n");
        return 2;
    }
    struct stat sb;
    if (stat(argv[1], &sb) != 0) {
        perror(argv[1]);
        return 1;
    }
    sw_status st = {0};
    printf("%s: %lld bytes; RSS at start %.1f MiB\n", argv[1], (long long)sb.st_size,
           (double)status_kib("VmRSS") / 1024.0);
    const double t_all = now_ms();

    stage s = stage_begin();
    sw_sg_scene *scene = NULL;
    if (sw_sg_scene_open(argv[1], &scene, &st) != SW_OK)
        return fail("open", &st);
    stage_end(&s, "open", 0);

    s = stage_begin();
    if (sw_sg_scene_require(scene, SW_SG_SEC_ALL, &st) != SW_OK)
        return fail("verify", &st);
    stage_end(&s, "verify", 0);
    s = stage_begin();
    sw_sg_scene_stats stats;
    if (sw_sg_scene_compute_stats(scene, &stats) != SW_OK) {
        fprintf(stderr, "scale_setup: stats: out of memory\n");
        return 1;
    }
    stage_end(&s, "stats", 0);
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    printf("  faces %u, nodes %u\n", v->n_faces, v->n_nodes);

    sw_th_pool_desc pd = {0};
    pd.worker_count = 2;
    sw_th_pool *pool = NULL;
    if (sw_th_pool_create(&pd, &pool) != SW_OK) {
        fprintf(stderr, "scale_setup: worker pool: could not start\n");
        return 1;
    }
    s = stage_begin();
    sw_lod_cache *cache = NULL;
    if (sw_lod_cache_create(scene, pool, NULL, &cache, &st) != SW_OK)
        return fail("cache", &st);
    stage_end(&s, "cache", sw_lod_cache_memory(cache));

    s = stage_begin();
    sw_sg_bvh *bvh = NULL;
    if (sw_sg_bvh_build(scene, &bvh, &st) != SW_OK)
        return fail("bvh", &st);
    stage_end(&s, "bvh", sw_sg_bvh_memory(bvh));
    printf("  bvh: %u items, %u nodes\n", bvh->n_items, bvh->n_nodes);

    s = stage_begin();
    sw_lod_face_cones *cones = NULL;
    if (sw_lod_face_cones_build(scene, &cones, &st) != SW_OK)
        return fail("cones", &st);
    stage_end(&s, "cones", (size_t)cones->n_faces * sizeof *cones->cones);
    printf("  cones: %u faces, %u bounded\n", cones->n_faces, cones->n_bounded);

    printf("setup total %.1f ms; VmRSS %.1f MiB, VmHWM %.1f MiB\n", now_ms() - t_all,
           (double)status_kib("VmRSS") / 1024.0, (double)status_kib("VmHWM") / 1024.0);
    sw_lod_face_cones_free(cones);
    sw_sg_bvh_free(bvh);
    sw_lod_cache_destroy(cache);
    sw_th_pool_destroy(pool);
    sw_sg_scene_free(scene);
    return 0;
}

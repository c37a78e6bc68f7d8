/* SPDX-License-Identifier: MIT */
/* tests/api: the host's allocator and log hooks (sw_setup.h), through the public API of
 * libsplinewalk.so only. Each mode is its own process (sw_setup comes once per process).
 *
 *   test_api_hooks count SCENE.tsm WORKDIR
 *       a counting allocator without realloc (the library emulates it): every block the library
 *       allocates while it loads, describes, picks, saves, renders and destroys a scene is freed
 *       again (blocks and bytes balance exactly against the count before the cycle); what stays
 *       after a warm-up (a scene and a renderer made and destroyed) is the handle tables only; the
 * log hook gets the renderer's info line, the failures' debug lines and (without SW_MISUSE_ASSERT)
 * the misuse's error line. test_api_hooks oom SCENE.tsm WORKDIR an allocator (with realloc) that
 * fails from its N-th allocation on, N swept over every allocation of loading the T-spline scene
 * and of loading its .sws copy: each load fails with SW_ERR_OUT_OF_MEMORY (or succeeds once N is
 * past its last allocation), leaves *out = {0} and frees everything it made (counts back to where
 * they were; ASan in CI). test_api_hooks oom_render SCENE.tsm WORKDIR the same for a renderer's
 * life (create, a converged frame, destroy), allocation N failing for N = 0..15 and then every
 * (allocations / 60)-th: each call fails with SW_ERR_OUT_OF_MEMORY or succeeds, the renderer draws
 * again once memory is back, and its destruction frees everything.
 */
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>
#include <splinewalk/splinewalk.h>

#include "api_test_expect.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef SW_TEST_MISUSE_ASSERTS
#define SW_TEST_MISUSE_ASSERTS 0
#endif

/* ---- a counting allocator with its own size header (the library's calls come from several
 * threads: the renderer's pool, its visibility thread) ------------------------------------------
 */
typedef struct counts {
    atomic_llong allocs, frees, live_blocks, live_bytes, peak_bytes;
    atomic_llong fail_from; /* allocations numbered >= this fail; -1: none */
    atomic_llong failed;
} counts;
static counts g_counts = {.fail_from = -1};

typedef struct block_header {
    _Alignas(16) size_t size;
} block_header;

static void *count_alloc(void *user_data, size_t size)
{
    counts *c = user_data;
    long long n = atomic_fetch_add(&c->allocs, 1);
    long long limit = atomic_load(&c->fail_from);
    if (limit >= 0 && n >= limit) {
        atomic_fetch_sub(&c->allocs, 1); /* allocs counts blocks handed out */
        atomic_fetch_add(&c->failed, 1);
        return NULL;
    }
    block_header *h = malloc(sizeof *h + size);
    if (!h)
        abort();
    h->size = size;
    atomic_fetch_add(&c->live_blocks, 1);
    long long bytes = atomic_fetch_add(&c->live_bytes, (long long)size) + (long long)size;
    long long peak = atomic_load(&c->peak_bytes);
    while (bytes > peak && !atomic_compare_exchange_weak(&c->peak_bytes, &peak, bytes)) {
    }
    return h + 1;
}

static void count_free(void *user_data, void *ptr)
{
    counts *c = user_data;
    if (!ptr) {
        fprintf(stderr, "the library passed NULL to the allocator's free\n");
        abort();
    }
    block_header *h = (block_header *)ptr - 1;
    atomic_fetch_add(&c->frees, 1);
    atomic_fetch_sub(&c->live_blocks, 1);
    atomic_fetch_sub(&c->live_bytes, (long long)h->size);
    free(h);
}

static void *count_realloc(void *user_data, void *ptr, size_t size)
{
    block_header *old = (block_header *)ptr - 1;
    void *fresh = count_alloc(user_data, size);
    if (!fresh)
        return NULL; /* the old block stays, as C's realloc leaves it */
    memcpy(fresh, ptr, old->size < size ? old->size : size);
    count_free(user_data, ptr);
    return fresh;
}

/* ---- a log hook that keeps the lines -----------------------------------------------------------
 */
typedef struct log_lines {
    pthread_mutex_t lock;
    int count[SW_LOG_ERROR + 1];
    char last[SW_LOG_ERROR + 1][512];
    int saw_not_found, saw_misuse_destroy, saw_renderer;
} log_lines;
static log_lines g_log = {.lock = PTHREAD_MUTEX_INITIALIZER};

static void keep_line(void *user_data, sw_log_level level, const char *message)
{
    log_lines *l = user_data;
    pthread_mutex_lock(&l->lock);
    if (level >= SW_LOG_DEBUG && level <= SW_LOG_ERROR) {
        l->count[level]++;
        snprintf(l->last[level], sizeof l->last[level], "%s", message);
    }
    if (level == SW_LOG_DEBUG && strstr(message, "SW_ERR_NOT_FOUND"))
        l->saw_not_found = 1;
    if (level == SW_LOG_ERROR && strstr(message, "sw_scene_destroy"))
        l->saw_misuse_destroy = 1;
    if (level == SW_LOG_INFO && strstr(message, "renderer"))
        l->saw_renderer = 1;
    pthread_mutex_unlock(&l->lock);
}

static void snapshot(long long *blocks, long long *bytes)
{
    *blocks = atomic_load(&g_counts.live_blocks);
    *bytes = atomic_load(&g_counts.live_bytes);
}

static const char *g_scene_path, *g_work;

/* A scene and a renderer made and destroyed: what stays is the handle tables. */
static int warm_up(void)
{
    int failures = g_failures;
    sw_scene scene = {0};
    sw_scene_load_desc load = {.path = g_scene_path};
    EXPECT_RESULT(sw_scene_load(&load, &scene, NULL), SW_OK);
    sw_renderer renderer = {0};
    sw_renderer_desc rdesc = {.worker_threads = 1};
    EXPECT_RESULT(sw_renderer_create(&rdesc, &renderer, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(renderer), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    return g_failures == failures ? 0 : -1;
}

/* Loads, describes, picks, saves, renders (a converged frame of the hierarchy path, one of
 * static LODs, a split walkthrough frame) and destroys; returns 0 when every call succeeded. */
static int full_cycle(int round)
{
    int failures = g_failures;
    sw_scene scene = {0};
    sw_scene_load_desc load = {.path = g_scene_path};
    EXPECT_RESULT(sw_scene_load(&load, &scene, NULL), SW_OK);
    sw_scene_info info;
    EXPECT_RESULT(sw_scene_get_info(scene, &info, NULL), SW_OK);
    double origin[3] = {(info.bbox_min[0] + info.bbox_max[0]) / 2,
                        (info.bbox_min[1] + info.bbox_max[1]) / 2, info.bbox_max[2] + 10.0};
    double down[3] = {0, 0, -1};
    sw_pick_hit hit;
    EXPECT_RESULT(sw_scene_pick(scene, origin, down, &hit, NULL), SW_OK);
    char path[4096];
    snprintf(path, sizeof path, "%s/hooks_%d.sws", g_work, round);
    EXPECT_RESULT(sw_scene_save(scene, path, NULL), SW_OK);

    sw_renderer renderer = {0};
    sw_renderer_desc rdesc = {.worker_threads = 2};
    sw_status status = {0};
    EXPECT_RESULT(sw_renderer_create(&rdesc, &renderer, &status), SW_OK);
    if (status.result != SW_OK)
        fprintf(stderr, "renderer: %s\n", status.message);
    sw_frame_desc frame = {.scene = scene, .width = 160, .height = 120};
    EXPECT_RESULT(sw_renderer_draw(renderer, &frame, NULL, NULL), SW_OK);
    frame.static_lods = 1;
    EXPECT_RESULT(sw_renderer_draw(renderer, &frame, NULL, NULL), SW_OK);
    frame.static_lods = 0;
    frame.walkthrough = 1;
    EXPECT_RESULT(sw_renderer_prepare(renderer, &frame, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_submit(renderer, NULL, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(renderer), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    return g_failures == failures ? 0 : -1;
}

static int run_count(void)
{
    sw_setup_desc setup = {
        .allocator = {count_alloc, NULL, count_free, &g_counts},
        .logger = {keep_line, &g_log, SW_LOG_DEBUG},
    };
    EXPECT_RESULT(sw_setup(&setup, NULL), SW_OK);

    long long blocks0, bytes0, blocks1, bytes1, blocks2, bytes2;
    snapshot(&blocks0, &bytes0);
    EXPECT(blocks0 == 0);
    if (warm_up() != 0)
        return 1;
    snapshot(&blocks1, &bytes1);
    long long allocs1 = atomic_load(&g_counts.allocs);
    /* What the first cycle keeps: the scene and renderer handle tables (items + generations). */
    printf("warm-up (a scene and a renderer made and destroyed): %lld allocations; kept %lld "
           "blocks, %lld bytes (handle tables)\n",
           allocs1, blocks1, bytes1);
    EXPECT(allocs1 > 30);
    EXPECT(blocks1 <= 4 && bytes1 <= 4096);

    if (full_cycle(1) != 0)
        return 1;
    snapshot(&blocks2, &bytes2);
    long long allocs2 = atomic_load(&g_counts.allocs) - allocs1;
    printf("load + info + pick + save + 3 frames + destroy: %lld allocations, peak %lld bytes; "
           "live after it %lld blocks, %lld bytes (before it %lld, %lld)\n",
           allocs2, (long long)atomic_load(&g_counts.peak_bytes), blocks2, bytes2, blocks1, bytes1);
    EXPECT(allocs2 > 1000); /* the allocator sees the library's work, not a handful of calls */
    EXPECT(blocks2 == blocks1 && bytes2 == bytes1);
    EXPECT(atomic_load(&g_counts.allocs) - atomic_load(&g_counts.frees) == blocks2);

    /* The log: a failure as a debug line with its id, the renderer at info. */
    sw_scene missing = {0};
    char path[4096];
    snprintf(path, sizeof path, "%s/no_such_scene.sws", g_work);
    sw_scene_load_desc load = {.path = path};
    EXPECT_RESULT(sw_scene_load(&load, &missing, NULL), SW_ERR_NOT_FOUND);
    EXPECT(g_log.saw_not_found);
    EXPECT(g_log.saw_renderer);
#if !SW_TEST_MISUSE_ASSERTS
    sw_scene stale = {0};
    load.path = g_scene_path;
    EXPECT_RESULT(sw_scene_load(&load, &stale, NULL), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(stale), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(stale), SW_ERR_STALE_HANDLE);
    EXPECT(g_log.saw_misuse_destroy);
#endif
    /* A second sw_setup is refused (it would hand malloc's blocks to another free). Without
     * asserts only: with them it is a misuse that aborts (test_api_misuse covers that). */
#if !SW_TEST_MISUSE_ASSERTS
    sw_status status = {0};
    EXPECT_RESULT(sw_setup(&setup, &status), SW_ERR_INVALID_ARGUMENT);
    EXPECT(strstr(status.message, "once") != NULL);
#endif
    printf("log lines: debug %d, info %d, warning %d, error %d; last info: \"%s\"\n",
           g_log.count[SW_LOG_DEBUG], g_log.count[SW_LOG_INFO], g_log.count[SW_LOG_WARN],
           g_log.count[SW_LOG_ERROR], g_log.last[SW_LOG_INFO]);
    return 0;
}

/* Loads `path` with the N-th allocation (counted from now) failing, for every N until a load
 * succeeds; returns the number of allocations a successful load makes (-1 on a failure). */
static long long sweep_load(const char *path)
{
    sw_scene_load_desc load = {.path = path};
    long long blocks0, bytes0;
    snapshot(&blocks0, &bytes0);
    for (long long n = 0;; n++) {
        long long base = atomic_load(&g_counts.allocs);
        atomic_store(&g_counts.failed, 0);
        atomic_store(&g_counts.fail_from, base + n);
        sw_scene scene = {12345};
        sw_status status = {0};
        sw_result r = sw_scene_load(&load, &scene, &status);
        if (r != SW_OK)
            EXPECT(scene.id == 0);
        sw_scene_info info;
        /* get_info walks the scene once more (its first use): also under the failing budget */
        if (r == SW_OK)
            r = sw_scene_get_info(scene, &info, &status);
        int failed_any = atomic_load(&g_counts.failed) > 0;
        atomic_store(&g_counts.fail_from, -1);
        if (scene.id != 0)
            EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
        long long blocks, bytes;
        snapshot(&blocks, &bytes);
        if (blocks != blocks0 || bytes != bytes0) {
            fprintf(stderr, "%s, allocation %lld failing: %lld blocks, %lld bytes left (%s)\n",
                    path, n, blocks - blocks0, bytes - bytes0, status.message);
            g_failures++;
            return -1;
        }
        if (!failed_any) {
            EXPECT_RESULT(r, SW_OK);
            return n;
        }
        if (r != SW_ERR_OUT_OF_MEMORY) {
            fprintf(stderr, "%s, allocation %lld failing: %s (%s), expected SW_ERR_OUT_OF_MEMORY\n",
                    path, n, sw_result_id_str(r), status.message);
            g_failures++;
            return -1;
        }
    }
}

static int run_oom(void)
{
    sw_setup_desc setup = {.allocator = {count_alloc, count_realloc, count_free, &g_counts}};
    EXPECT_RESULT(sw_setup(&setup, NULL), SW_OK);
    /* The handle table exists before the sweep, so that every load starts from the same state. */
    sw_scene scene = {0};
    sw_scene_load_desc load = {.path = g_scene_path};
    EXPECT_RESULT(sw_scene_load(&load, &scene, NULL), SW_OK);
    char sws[4096];
    snprintf(sws, sizeof sws, "%s/oom.sws", g_work);
    EXPECT_RESULT(sw_scene_save(scene, sws, NULL), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);

    long long n_tsm = sweep_load(g_scene_path);
    long long n_sws = n_tsm >= 0 ? sweep_load(sws) : -1;
    printf("failing allocator: every one of the %lld allocations of loading %s and of the %lld of "
           "loading its .sws copy failed in turn -> SW_ERR_OUT_OF_MEMORY, nothing left behind\n",
           n_tsm, g_scene_path, n_sws);
    EXPECT(n_tsm > 50 && n_sws > 5);
    return 0;
}

/* One renderer's life (create, a converged frame, destroy) with allocation N failing: create and
 * draw fail with SW_ERR_OUT_OF_MEMORY or succeed (a pool task that met the failure may leave its
 * face to a coarser path), a second frame without failures draws, and nothing is left behind.
 * Returns the allocations of a life without failures. */
static long long g_sticky; /* lives whose second frame still met the first one's failure */

static long long renderer_life(sw_scene scene, long long fail_at, int check, int *bad)
{
    long long blocks0, bytes0;
    snapshot(&blocks0, &bytes0);
    long long base = atomic_load(&g_counts.allocs);
    atomic_store(&g_counts.failed, 0);
    atomic_store(&g_counts.fail_from, fail_at >= 0 ? base + fail_at : -1);
    sw_renderer renderer = {0};
    sw_renderer_desc rdesc = {.worker_threads = 2};
    sw_status status = {0};
    sw_result created = sw_renderer_create(&rdesc, &renderer, &status);
    sw_frame_desc frame = {.scene = scene, .width = 96, .height = 72};
    sw_result drawn = created == SW_OK ? sw_renderer_draw(renderer, &frame, NULL, &status) : SW_OK;
    atomic_store(&g_counts.fail_from, -1);
    long long used = atomic_load(&g_counts.allocs) - base;
    sw_result again = created == SW_OK ? sw_renderer_draw(renderer, &frame, NULL, NULL) : SW_OK;
    if (created == SW_OK)
        EXPECT_RESULT(sw_renderer_destroy(renderer), SW_OK);
    long long blocks, bytes;
    snapshot(&blocks, &bytes);
    /* A hierarchy build that met the failure stays failed for this renderer and scene (the
     * cache builds a face once), so the second frame may report it again; a new renderer does
     * not (the next life). Any other result, or memory left, is wrong. */
    if (again == SW_ERR_OUT_OF_MEMORY && drawn == SW_ERR_OUT_OF_MEMORY)
        g_sticky++;
    int ok = (created == SW_OK || created == SW_ERR_OUT_OF_MEMORY) &&
             (drawn == SW_OK || drawn == SW_ERR_OUT_OF_MEMORY) &&
             (again == SW_OK || (again == SW_ERR_OUT_OF_MEMORY && drawn == SW_ERR_OUT_OF_MEMORY)) &&
             (!check || (blocks == blocks0 && bytes == bytes0));
    if (!ok) {
        fprintf(stderr,
                "renderer life, allocation %lld failing: create %s, draw %s (%s), "
                "draw after %s, %lld blocks / %lld bytes left\n",
                fail_at, sw_result_id_str(created), sw_result_id_str(drawn), status.message,
                sw_result_id_str(again), blocks - blocks0, bytes - bytes0);
        g_failures++;
        *bad += 1;
    }
    return used;
}

static int run_oom_render(void)
{
    sw_setup_desc setup = {.allocator = {count_alloc, count_realloc, count_free, &g_counts}};
    EXPECT_RESULT(sw_setup(&setup, NULL), SW_OK);
    sw_scene scene = {0};
    sw_scene_load_desc load = {.path = g_scene_path};
    EXPECT_RESULT(sw_scene_load(&load, &scene, NULL), SW_OK);
    sw_scene_info info;
    EXPECT_RESULT(sw_scene_get_info(scene, &info, NULL), SW_OK);
    int bad = 0;
    renderer_life(scene, -1, 0, &bad); /* the renderer table exists from here on */
    long long total = renderer_life(scene, -1, 1, &bad);
    long long step = total / 60 > 1 ? total / 60 : 1, lives = 0;
    for (long long n = 0; n < total && bad < 5; n += n < 16 ? 1 : step, lives++) {
        renderer_life(scene, n, 1, &bad);
        long long sticky = g_sticky;
        renderer_life(scene, -1, 1, &bad); /* a new renderer draws again */
        EXPECT(g_sticky == sticky);
    }
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    printf("failing allocator: %lld renderer lives (create + converged frame + destroy, %lld "
           "allocations each) with allocation 0..15 and every %lld-th failing: %d wrong; %lld "
           "whose second frame met the first one's hierarchy failure again\n",
           lives, total, step, bad, g_sticky);
    return 0;
}

int main(int argc, char **argv)
{
    (void)sw_import_install(), (void)sw_lod_build_install(); /* CAD files, static LODs */
    if (argc != 4) {
        fprintf(stderr, "usage: %s count|oom|oom_render SCENE.tsm WORKDIR\n", argv[0]);
        return 2;
    }
    g_scene_path = argv[2];
    g_work = argv[3];
    int r = strcmp(argv[1], "count") == 0        ? run_count()
            : strcmp(argv[1], "oom") == 0        ? run_oom()
            : strcmp(argv[1], "oom_render") == 0 ? run_oom_render()
                                                 : 2;
    if (r == 2) {
        fprintf(stderr, "unknown mode %s\n", argv[1]);
        return 2;
    }
    if (g_failures) {
        fprintf(stderr, "%d failure(s)\n", g_failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}

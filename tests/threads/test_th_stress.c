/* SPDX-License-Identifier: MIT */
/* tests/threads: exactly-once execution in the worker pool under random spawning.
 *
 * Every task has an id in [0, N) and an atomic run counter; a task spawns 0–3 children at random
 * (each takes the next id) at a random priority, so the pool pushes, pops and steals at every
 * depth. At the end every counter must be exactly 1 (the reference: a plain array, like GHC's
 * testsuite/tests/rts/testwsdeque.c), and the pool's own executed count must be N.
 *
 * usage: test_th_stress TASKS WORKER_COUNTS MODES     e.g. 1000000 2,5,16 one,half
 */
#include "sw_th_pool.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int64_t g_n;
static _Atomic uint8_t *g_runs;
static _Atomic int64_t g_next;
static sw_th_pool *g_pool;
static sw_th_group g_group;
static _Atomic int g_submit_failed;

static void stress_task(void *ctx);

static uint64_t mix(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdu;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53u;
    return x ^ (x >> 33);
}

static void submit_id(int64_t id, uint64_t h)
{
    sw_th_task t = {.fn = stress_task,
                    .ctx = (void *)(intptr_t)id,
                    .priority = (sw_th_priority)(h & 1),
                    .group = &g_group};
    if (sw_th_pool_submit(g_pool, &t) != SW_OK)
        atomic_store(&g_submit_failed, 1);
}

static void stress_task(void *ctx)
{
    int64_t id = (int64_t)(intptr_t)ctx;
    atomic_fetch_add_explicit(&g_runs[id], 1, memory_order_relaxed);
    uint64_t h = mix((uint64_t)id);
    int children = (int)(h % 4);
    for (int c = 0; c < children; c++) {
        int64_t cid = atomic_fetch_add_explicit(&g_next, 1, memory_order_relaxed);
        if (cid >= g_n)
            return;
        submit_id(cid, h >> (8 + 4 * c));
    }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Returns the number of ids not run exactly once (0 = pass). */
static int64_t run_one(uint32_t workers, sw_th_steal_mode mode)
{
    memset((void *)g_runs, 0, (size_t)g_n * sizeof *g_runs);
    atomic_store(&g_next, 0);
    sw_th_group_init(&g_group);
    sw_th_pool_desc desc = {.worker_count = workers, .steal_mode = mode, .deque_capacity = 16};
    if (sw_th_pool_create(&desc, &g_pool) != SW_OK) {
        fprintf(stderr, "pool creation failed\n");
        return g_n;
    }
    double t0 = now_s();
    int rounds = 0;
    /* A random tree dies out with probability ~0.41: keep planting roots until ids run out. */
    while (atomic_load(&g_next) < g_n) {
        for (int r = 0; r < 16; r++) {
            int64_t id = atomic_fetch_add(&g_next, 1);
            if (id >= g_n)
                break;
            submit_id(id, mix((uint64_t)id + 7));
        }
        sw_th_group_wait(g_pool, &g_group);
        rounds++;
    }
    sw_th_group_wait(g_pool, &g_group);
    double dt = now_s() - t0;
    sw_th_pool_stats st;
    sw_th_pool_stats_get(g_pool, &st);
    sw_th_pool_destroy(g_pool);
    int64_t bad = 0, first_bad = -1;
    for (int64_t i = 0; i < g_n; i++) {
        if (atomic_load_explicit(&g_runs[i], memory_order_relaxed) != 1) {
            if (first_bad < 0)
                first_bad = i;
            bad++;
        }
    }
    printf("workers %2u steal-%s: %" PRId64 " tasks in %.3f s (%.2f M/s), %d root rounds, "
           "steals %" PRIu64 " moving %" PRIu64 ", sleeps %" PRIu64 ", executed %" PRIu64
           ", not exactly once %" PRId64 "\n",
           workers, mode == SW_TH_STEAL_MODE_ONE ? "one " : "half", g_n, dt,
           1e-6 * (double)g_n / dt, rounds, st.steals, st.stolen_tasks, st.sleeps, st.executed,
           bad);
    if (bad)
        fprintf(stderr, "first bad id %" PRId64 " ran %d times\n", first_bad,
                (int)atomic_load(&g_runs[first_bad]));
    if (st.executed != (uint64_t)g_n || st.cancelled != 0 || atomic_load(&g_submit_failed))
        bad++;
    return bad;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: %s TASKS WORKER_COUNTS MODES   e.g. 1000000 2,5,16 one,half\n",
                argv[0]);
        return 2;
    }
    g_n = strtoll(argv[1], NULL, 10);
    if (g_n < 1 || g_n > ((int64_t)1 << 32)) {
        fprintf(stderr, "bad task count\n");
        return 2;
    }
    g_runs = calloc((size_t)g_n, sizeof *g_runs);
    if (!g_runs)
        return 2;
    int failures = 0;
    char *modes = argv[3];
    for (char *wl = strtok(argv[2], ","); wl; wl = strtok(NULL, ",")) {
        uint32_t workers = (uint32_t)strtoul(wl, NULL, 10);
        if (workers < 1 || workers > 256)
            return 2;
        if (strstr(modes, "one"))
            failures += run_one(workers, SW_TH_STEAL_MODE_ONE) != 0;
        if (strstr(modes, "half"))
            failures += run_one(workers, SW_TH_STEAL_MODE_HALF) != 0;
    }
    free((void *)g_runs);
    printf("%s\n", failures ? "FAIL" : "PASS");
    return failures ? 1 : 0;
}

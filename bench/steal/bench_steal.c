/* SPDX-License-Identifier: MIT */
/* bench/steal: throughput of the worker pool (threads/sw_th_pool.h) when idle workers steal one
 * task versus half of the victim's deque (Kumar, Manocha, Zhang, Hoff 1997, §5.1: "partitions
 * Q(busy) into two"), for 1..N workers and two workloads:
 *  - fine:   a recursive binary tree of tasks (each spawns two children) with ~0.1 µs of work each;
 *  - coarse: one task spawning a flat loop of tasks with ~20 µs of work each (all work starts in
 *            one deque, so thieves must spread it).
 * Prints the median tasks/s over the repetitions. With --timing the two columns are instead
 * half-steal pools without and with per-task timing (sw_th_pool_desc.time_tasks: two
 * CLOCK_MONOTONIC reads per task), the cost of the profile's pool_<kind>_ms columns.
 *
 * usage: bench_steal [MAX_WORKERS (default: 2 × cores)] [REPEATS (default 7)] [--timing]
 */
#include "sw_th_pool.h"

#include <stdalign.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

enum { FINE_DEPTH = 20, FINE_WORK = 16, COARSE_TASKS = 4096, COARSE_WORK = 4000 };

/* Completion is counted per worker (single writer, own cache line): one shared counter (a
 * sw_th_group) would be two contended RMWs per task and would measure the counter, not the
 * pool. */
typedef struct slot {
    alignas(64) _Atomic uint64_t done;
    uint64_t sink;
} slot;

static sw_th_pool *g_pool;
static slot g_slots[256];

static void spin_work(uint64_t seed, int iterations)
{
    uint64_t x = seed | 1;
    for (int i = 0; i < iterations; i++)
        x = x * 6364136223846793005u + 1442695040888963407u;
    slot *s = &g_slots[sw_th_pool_current_worker(g_pool)];
    s->sink += x & 1;
    atomic_store_explicit(&s->done, atomic_load_explicit(&s->done, memory_order_relaxed) + 1,
                          memory_order_relaxed);
}

static uint64_t done_count(void)
{
    uint64_t n = 0;
    for (int i = 0; i < 256; i++)
        n += atomic_load_explicit(&g_slots[i].done, memory_order_relaxed);
    return n;
}

static void fine_fn(void *ctx)
{
    uintptr_t depth = (uintptr_t)ctx;
    spin_work(depth, FINE_WORK);
    if (depth == 0)
        return;
    sw_th_task t = {.fn = fine_fn, .ctx = (void *)(depth - 1)};
    sw_th_pool_submit(g_pool, &t);
    sw_th_pool_submit(g_pool, &t);
}

static void coarse_leaf_fn(void *ctx)
{
    spin_work((uintptr_t)ctx, COARSE_WORK);
}

static void coarse_root_fn(void *ctx)
{
    spin_work((uintptr_t)ctx, 1);
    for (uintptr_t i = 0; i < COARSE_TASKS; i++) {
        sw_th_task t = {.fn = coarse_leaf_fn, .ctx = (void *)i};
        sw_th_pool_submit(g_pool, &t);
    }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
           1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

/* One timed run of a workload on `pool`; returns tasks/s and the process CPU ns per task (less
 * sensitive than wall time to other processes on the machine). */
static double run_once(sw_th_pool *pool, int coarse, double *cpu_ns_per_task)
{
    g_pool = pool;
    for (int i = 0; i < 256; i++)
        atomic_store_explicit(&g_slots[i].done, 0, memory_order_relaxed);
    uint64_t tasks = coarse ? COARSE_TASKS + 1 : (2u << FINE_DEPTH) - 1;
    sw_th_task root = {.fn = coarse ? coarse_root_fn : fine_fn,
                       .ctx = (void *)(uintptr_t)FINE_DEPTH};
    double c0 = cpu_s(), t0 = now_s();
    sw_th_pool_submit(pool, &root);
    /* The caller polls: sw_th_group_wait would make it run tasks as an extra worker. */
    while (done_count() < tasks)
        nanosleep(&(struct timespec){0, 50000}, NULL);
    double wall = now_s() - t0;
    *cpu_ns_per_task = 1e9 * (cpu_s() - c0) / (double)tasks;
    return (double)tasks / wall;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    return v[n / 2];
}

/* Median tasks/s of each mode. The two modes' runs alternate (each on its own pool; the idle one
 * sleeps), so that load from other processes falls on both alike. */
static void measure(int coarse, uint32_t workers, int repeats, int timing, double rate[2],
                    double cpu[2], double steals[2])
{
    sw_th_pool *pools[2];
    double runs[2][64], cpus[2][64];
    for (int m = 0; m < 2; m++) {
        sw_th_pool_desc d = {.worker_count = workers,
                             .steal_mode =
                                 m || timing ? SW_TH_STEAL_MODE_HALF : SW_TH_STEAL_MODE_ONE,
                             .time_tasks = timing && m};
        if (sw_th_pool_create(&d, &pools[m]) != SW_OK) {
            fprintf(stderr, "pool creation failed\n");
            exit(1);
        }
    }
    for (int r = 0; r < repeats; r++)
        for (int m = 0; m < 2; m++)
            runs[m][r] = run_once(pools[(m + r) % 2], coarse, &cpus[m][r]);
    /* runs[m][r] ran on pool (m + r) % 2: sort them back per mode. */
    double by_mode[2][64], cpu_by_mode[2][64];
    for (int r = 0; r < repeats; r++) {
        for (int m = 0; m < 2; m++) {
            by_mode[(m + r) % 2][r] = runs[m][r];
            cpu_by_mode[(m + r) % 2][r] = cpus[m][r];
        }
    }
    for (int m = 0; m < 2; m++) {
        sw_th_pool_stats st;
        sw_th_pool_stats_get(pools[m], &st);
        steals[m] = (double)st.steals / repeats;
        sw_th_pool_destroy(pools[m]);
        rate[m] = median(by_mode[m], repeats);
        cpu[m] = median(cpu_by_mode[m], repeats);
    }
}

int main(int argc, char **argv)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int max_workers = argc > 1 ? atoi(argv[1]) : (int)(2 * (cores > 0 ? cores : 1));
    int repeats = argc > 2 ? atoi(argv[2]) : 7;
    const int timing = argc > 3 && strcmp(argv[3], "--timing") == 0;
    if (max_workers < 1 || max_workers > 256 || repeats < 1 || repeats > 64 ||
        (argc > 3 && !timing) || argc > 4) {
        fprintf(stderr, "usage: %s [MAX_WORKERS 1..256] [REPEATS 1..64] [--timing]\n", argv[0]);
        return 2;
    }
    const char *a = timing ? "untimed" : "one", *b = timing ? "timed" : "half";
    printf("bench_steal: %ld cores, median of %d runs; the calling thread only polls\n", cores,
           repeats);
    printf("fine = binary task tree of depth %d (%u tasks, ~%d LCG steps each); "
           "coarse = 1 task spawning %d tasks of %d LCG steps\n",
           FINE_DEPTH, (2u << FINE_DEPTH) - 1, FINE_WORK, COARSE_TASKS, COARSE_WORK);
    printf("%-8s %7s %10s %10s %8s | %10s %10s | %8s %8s\n", "", "", "tasks/s", "[M/s]", "",
           "CPU ns", "per task", "steals", "per run");
    if (timing)
        printf("--timing: both columns steal half; 'timed' times every task (time_tasks = 1)\n");
    printf("%-8s %7s %10s %10s %8s | %10s %10s | %8s %8s\n", "workload", "workers", a, b,
           timing ? "timed/un" : "half/one", a, b, a, b);
    for (int coarse = 0; coarse <= 1; coarse++) {
        for (int w = 1; w <= max_workers; w++) {
            double rate[2], cpu[2], steals[2];
            measure(coarse, (uint32_t)w, repeats, timing, rate, cpu, steals);
            double one = rate[0], half = rate[1], s1 = steals[0], s2 = steals[1];
            printf("%-8s %7d %10.3f %10.3f %8.2f | %10.1f %10.1f | %8.0f %8.0f\n",
                   coarse ? "coarse" : "fine", w, 1e-6 * one, 1e-6 * half, half / one, cpu[0],
                   cpu[1], s1, s2);
            fflush(stdout);
        }
    }
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* tests/threads: worker-pool behaviour (threads/sw_th_pool.h) — cancellation of stale requests,
 * priorities, group waiters that help, fork-join from tasks, shutdown that drains, idle
 * workers that sleep instead of spinning, and the accounting by task kind (counts, own time of
 * nested tasks, time of running tasks, queue lengths, the injection peak). */
#include "sw_th_pool.h"

#include <pthread.h>
#include <sched.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>
#include <cmocka.h>

/* The test's task kinds, registered in main as a layer registers its own. */
static struct {
    sw_th_task_kind compile, hierarchy, wait, refine, build;
} g_kind;

static void register_test_kinds(void)
{
    g_kind.compile = sw_th_task_kind_register("t_compile");
    g_kind.hierarchy = sw_th_task_kind_register("t_hierarchy");
    g_kind.wait = sw_th_task_kind_register("t_wait");
    g_kind.refine = sw_th_task_kind_register("t_refine");
    g_kind.build = sw_th_task_kind_register("t_build");
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* ---- a gate task that occupies a worker until opened ---------------------------------------- */

typedef struct gate {
    _Atomic int running;
    _Atomic int open;
} gate;

static void gate_fn(void *ctx)
{
    gate *g = ctx;
    atomic_store(&g->running, 1);
    while (!atomic_load(&g->open))
        sched_yield();
}

static sw_th_pool *pool_with(uint32_t workers)
{
    sw_th_pool *pool = NULL;
    sw_th_pool_desc d = {.worker_count = workers};
    assert_int_equal(sw_th_pool_create(&d, &pool), SW_OK);
    assert_int_equal(sw_th_pool_worker_count(pool), workers);
    return pool;
}

static void block_worker(sw_th_pool *pool, gate *g)
{
    sw_th_task t = {.fn = gate_fn, .ctx = g};
    assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    while (!atomic_load(&g->running))
        sched_yield();
}

/* ---- cancellation ---------------------------------------------------------------------------- */

enum { MARKS = 4096 };

typedef struct marks {
    _Atomic int ran[MARKS];
    _Atomic int order[MARKS];
    _Atomic int seq;
    _Atomic int done;
} marks;

typedef struct mark_ctx {
    marks *m;
    int id;
} mark_ctx;

static void mark_fn(void *ctx)
{
    mark_ctx *c = ctx;
    atomic_fetch_add(&c->m->ran[c->id], 1);
    atomic_store(&c->m->order[c->id], atomic_fetch_add(&c->m->seq, 1));
    atomic_fetch_add(&c->m->done, 1);
}

/* One worker held by a gate: 1000 tasks of generation g0, cancel, 500 of g1. Only the 500 run;
 * the 1000 are counted as cancelled and still release their group. */
static void test_cancel_external(void **state)
{
    (void)state;
    static marks m;
    static mark_ctx ctx[1500];
    sw_th_pool *pool = pool_with(1);
    gate g = {0};
    block_worker(pool, &g);
    sw_th_token tok;
    sw_th_token_init(&tok);
    sw_th_group grp;
    sw_th_group_init(&grp);
    uint64_t g0 = sw_th_token_current(&tok);
    for (int i = 0; i < 1500; i++) {
        if (i == 1000)
            assert_int_equal(sw_th_token_cancel(&tok), g0 + 1);
        ctx[i] = (mark_ctx){&m, i};
        sw_th_task t = {.fn = mark_fn,
                        .ctx = &ctx[i],
                        .token = &tok,
                        .generation = sw_th_token_current(&tok),
                        .group = &grp,
                        .priority = (sw_th_priority)(i % 2)};
        assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    }
    assert_int_equal(sw_th_group_pending(&grp), 1500);
    atomic_store(&g.open, 1);
    sw_th_group_wait(pool, &grp);
    assert_int_equal(sw_th_group_pending(&grp), 0);
    for (int i = 0; i < 1500; i++)
        assert_int_equal(atomic_load(&m.ran[i]), i < 1000 ? 0 : 1);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(pool, &st);
    assert_int_equal(st.cancelled, 1000);
    sw_th_pool_destroy(pool);
}

typedef struct spawner {
    sw_th_pool *pool;
    sw_th_token tok;
    sw_th_group grp;
    mark_ctx ctx[300];
    marks m;
} spawner;

/* A running task spawns 100 children of the live generation, cancels its request, then spawns
 * 100 of the old generation (all must be skipped) and 100 of the new one (all must run). */
static void spawner_fn(void *arg)
{
    spawner *s = arg;
    uint64_t g0 = sw_th_token_current(&s->tok);
    for (int i = 0; i < 300; i++) {
        if (i == 100)
            sw_th_token_cancel(&s->tok);
        s->ctx[i] = (mark_ctx){&s->m, i};
        sw_th_task t = {.fn = mark_fn,
                        .ctx = &s->ctx[i],
                        .token = &s->tok,
                        .generation = i < 200 ? g0 : g0 + 1,
                        .group = &s->grp};
        assert_int_equal(sw_th_pool_submit(s->pool, &t), SW_OK);
    }
}

static void test_cancel_from_task(void **state)
{
    (void)state;
    static spawner s;
    s.pool = pool_with(4);
    sw_th_token_init(&s.tok);
    sw_th_group_init(&s.grp);
    sw_th_task t = {.fn = spawner_fn, .ctx = &s, .group = &s.grp};
    assert_int_equal(sw_th_pool_submit(s.pool, &t), SW_OK);
    sw_th_group_wait(s.pool, &s.grp);
    int early = 0;
    for (int i = 0; i < 100; i++)
        early += atomic_load(&s.m.ran[i]);
    for (int i = 100; i < 200; i++)
        assert_int_equal(atomic_load(&s.m.ran[i]), 0);
    for (int i = 200; i < 300; i++)
        assert_int_equal(atomic_load(&s.m.ran[i]), 1);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(s.pool, &st);
    /* The first 100 raced with the cancel: each either ran or was counted, never both. */
    assert_int_equal(early + (int)st.cancelled, 200);
    sw_th_pool_destroy(s.pool);
}

/* ---- priorities ------------------------------------------------------------------------------ */

static void check_frame_first(marks *m, int n)
{
    int last_frame = -1, first_background = 1 << 30;
    for (int i = 0; i < 2 * n; i++) {
        int o = atomic_load(&m->order[i]);
        assert_int_equal(atomic_load(&m->ran[i]), 1);
        if (i < n && o < first_background)
            first_background = o; /* ids < n were submitted as BACKGROUND */
        if (i >= n && o > last_frame)
            last_frame = o;
    }
    assert_true(last_frame < first_background);
}

/* One worker held by a gate; 100 BACKGROUND tasks, then 100 FRAME ones: the FRAME ones run
 * first. (The test polls instead of sw_th_group_wait, whose help would add a second runner.) */
static void test_priority_external(void **state)
{
    (void)state;
    static marks m;
    static mark_ctx ctx[200];
    sw_th_pool *pool = pool_with(1);
    gate g = {0};
    block_worker(pool, &g);
    for (int i = 0; i < 200; i++) {
        ctx[i] = (mark_ctx){&m, i};
        sw_th_task t = {.fn = mark_fn,
                        .ctx = &ctx[i],
                        .priority = i < 100 ? SW_TH_PRIORITY_BACKGROUND : SW_TH_PRIORITY_FRAME};
        assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    }
    atomic_store(&g.open, 1);
    while (atomic_load(&m.done) < 200)
        sleep_ms(1);
    check_frame_first(&m, 100);
    sw_th_pool_destroy(pool);
}

typedef struct prio_parent {
    sw_th_pool *pool;
    marks m;
    mark_ctx ctx[100];
} prio_parent;

static void prio_parent_fn(void *arg)
{
    prio_parent *p = arg;
    for (int i = 0; i < 100; i++) {
        p->ctx[i] = (mark_ctx){&p->m, i};
        sw_th_task t = {.fn = mark_fn,
                        .ctx = &p->ctx[i],
                        .priority = i < 50 ? SW_TH_PRIORITY_BACKGROUND : SW_TH_PRIORITY_FRAME};
        assert_int_equal(sw_th_pool_submit(p->pool, &t), SW_OK);
    }
}

/* The same from inside a task: children go to the worker's own deques, FRAME popped first. */
static void test_priority_local(void **state)
{
    (void)state;
    static prio_parent p;
    p.pool = pool_with(1);
    sw_th_task t = {.fn = prio_parent_fn, .ctx = &p};
    assert_int_equal(sw_th_pool_submit(p.pool, &t), SW_OK);
    while (atomic_load(&p.m.done) < 100)
        sleep_ms(1);
    check_frame_first(&p.m, 50);
    sw_th_pool_destroy(p.pool);
}

/* ---- groups ---------------------------------------------------------------------------------- */

typedef struct helper_probe {
    sw_th_pool *pool;
    _Atomic int ran_by_caller;
    _Atomic int ran;
} helper_probe;

static void probe_fn(void *arg)
{
    helper_probe *h = arg;
    if (sw_th_pool_current_worker(h->pool) == -1)
        atomic_fetch_add(&h->ran_by_caller, 1);
    atomic_fetch_add(&h->ran, 1);
}

/* The only worker is held until all 100 tasks ran: sw_th_group_wait must run them itself (a
 * waiter that only blocked would hang here until the test's timeout). */
static void test_group_wait_helps(void **state)
{
    (void)state;
    helper_probe h = {0};
    h.pool = pool_with(1);
    gate g = {0};
    block_worker(h.pool, &g);
    sw_th_group grp;
    sw_th_group_init(&grp);
    for (int i = 0; i < 100; i++) {
        sw_th_task t = {.fn = probe_fn, .ctx = &h, .group = &grp};
        assert_int_equal(sw_th_pool_submit(h.pool, &t), SW_OK);
    }
    sw_th_group_wait(h.pool, &grp);
    assert_int_equal(atomic_load(&h.ran), 100);
    assert_int_equal(atomic_load(&h.ran_by_caller), 100);
    atomic_store(&g.open, 1);
    sw_th_pool_destroy(h.pool);
}

typedef struct fib_ctx {
    sw_th_pool *pool;
    int n;
    long result;
} fib_ctx;

static void fib_fn(void *arg)
{
    fib_ctx *f = arg;
    if (f->n < 2) {
        f->result = f->n;
        return;
    }
    fib_ctx a = {f->pool, f->n - 1, 0}, b = {f->pool, f->n - 2, 0};
    sw_th_group grp;
    sw_th_group_init(&grp);
    sw_th_task ta = {.fn = fib_fn, .ctx = &a, .group = &grp};
    sw_th_task tb = {.fn = fib_fn, .ctx = &b, .group = &grp};
    assert_int_equal(sw_th_pool_submit(f->pool, &ta), SW_OK);
    assert_int_equal(sw_th_pool_submit(f->pool, &tb), SW_OK);
    sw_th_group_wait(f->pool, &grp);
    f->result = a.result + b.result;
}

static long fib_serial(int n)
{
    long a = 0, b = 1;
    for (int i = 0; i < n; i++) {
        long c = a + b;
        a = b;
        b = c;
    }
    return a;
}

/* Fork-join with waits nested in tasks on every worker (each waiter keeps running tasks). */
static void test_fork_join(void **state)
{
    (void)state;
    for (uint32_t workers = 1; workers <= 4; workers += 3) {
        sw_th_pool *pool = pool_with(workers);
        fib_ctx f = {pool, 18, -1};
        sw_th_group grp;
        sw_th_group_init(&grp);
        sw_th_task t = {.fn = fib_fn, .ctx = &f, .group = &grp};
        assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
        sw_th_group_wait(pool, &grp);
        assert_int_equal(f.result, fib_serial(18));
        sw_th_pool_destroy(pool);
    }
}

/* ---- the calling thread's waits (what a frame's "pool waits" are made of) ------------------ */

static void sleep_20_fn(void *ctx)
{
    (void)ctx;
    sleep_ms(20);
}

/* fib_fn after 20 ms: the group is still pending when the submitting thread reaches its wait
 * (fib(14) alone could end before it does on a loaded machine, and then no wait is counted). */
static void sleep_then_fib_fn(void *ctx)
{
    sleep_ms(20);
    fib_fn(ctx);
}

/* A group wait that finds nothing pending is no wait; one that finds a task pending is one, its
 * time at least the task's (whoever runs it); a fork-join wait whose nested tasks wait too (run
 * by this thread while it helps) is still one; bracketed waits nest. */
static void test_thread_waits(void **state)
{
    (void)state;
    sw_th_pool *pool = pool_with(2);
    sw_th_group grp;
    sw_th_group_init(&grp);
    sw_th_wait_count a = sw_th_thread_waits();
    sw_th_group_wait(pool, &grp);
    sw_th_wait_count b = sw_th_thread_waits();
    assert_int_equal(b.waits, a.waits);
    assert_int_equal(b.ns, a.ns);
    sw_th_task t = {.fn = sleep_20_fn, .group = &grp};
    assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    sw_th_group_wait(pool, &grp);
    sw_th_wait_count c = sw_th_thread_waits();
    assert_int_equal(c.waits, b.waits + 1);
    assert_true(c.ns - b.ns >= 15000000u);
    fib_ctx f = {pool, 14, -1};
    sw_th_task ft = {.fn = sleep_then_fib_fn, .ctx = &f, .group = &grp};
    assert_int_equal(sw_th_pool_submit(pool, &ft), SW_OK);
    sw_th_group_wait(pool, &grp);
    assert_int_equal(f.result, fib_serial(14));
    sw_th_wait_count d = sw_th_thread_waits();
    assert_int_equal(d.waits, c.waits + 1);
    sw_th_wait_begin();
    sw_th_wait_begin();
    sw_th_wait_end();
    sw_th_wait_end();
    assert_int_equal(sw_th_thread_waits().waits, d.waits + 1);
    sw_th_pool_destroy(pool);
}

/* ---- shutdown and sleeping ------------------------------------------------------------------- */

typedef struct tree_ctx {
    sw_th_pool *pool;
    _Atomic int64_t count;
} tree_ctx;

static void tree_fn(void *arg);

static void tree_spawn(tree_ctx *c, int depth)
{
    sw_th_task t = {.fn = tree_fn, .ctx = (void *)((uintptr_t)c | (uintptr_t)depth)};
    assert_int_equal(sw_th_pool_submit(c->pool, &t), SW_OK);
}

/* ctx carries the depth in its low bits (tree_ctx is 8-aligned, depth < 8). */
static void tree_fn(void *arg)
{
    tree_ctx *c = (tree_ctx *)((uintptr_t)arg & ~(uintptr_t)7);
    int depth = (int)((uintptr_t)arg & 7);
    atomic_fetch_add(&c->count, 1);
    if (depth > 0) {
        tree_spawn(c, depth - 1);
        tree_spawn(c, depth - 1);
    }
}

/* Destroy right after submitting: every task submitted, and every child spawned by them,
 * still runs (2000 binary trees of depth 5 = 2000 * 63 tasks). */
static void test_shutdown_drains(void **state)
{
    (void)state;
    static tree_ctx c;
    c.pool = pool_with(3);
    for (int i = 0; i < 2000; i++)
        tree_spawn(&c, 5);
    sw_th_pool_destroy(c.pool);
    assert_int_equal(atomic_load(&c.count), 2000 * 63);
}

/* Lost wake-ups: workers that spin only twice before sleeping get a small burst of tasks from
 * outside, then the caller waits WITHOUT helping (polling), so a task left with every worker
 * asleep would never run. 3000 bursts, with pauses that let the pool fall asleep in between. */
static void test_no_lost_wakeup(void **state)
{
    (void)state;
    static tree_ctx c;
    sw_th_pool_desc d = {.worker_count = 3, .spin_rounds = 2};
    assert_int_equal(sw_th_pool_create(&d, &c.pool), SW_OK);
    atomic_store(&c.count, 0);
    int64_t expected = 0;
    for (int i = 0; i < 3000; i++) {
        int depth = i % 3;
        tree_spawn(&c, depth);
        expected += (2 << depth) - 1;
        time_t deadline = time(NULL) + 20;
        while (atomic_load(&c.count) < expected) {
            assert_true(time(NULL) < deadline);
            sched_yield();
        }
        if (i % 7 == 0)
            sleep_ms(1);
    }
    sw_th_pool_stats st;
    sw_th_pool_stats_get(c.pool, &st);
    print_message("3000 bursts: %llu sleeps\n", (unsigned long long)st.sleeps);
    assert_true(st.sleeps > 100);
    sw_th_pool_destroy(c.pool);
}

static double cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
           1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

/* Idle workers block: 4 idle workers for 400 ms burn well under 400 ms of CPU (spinning ones
 * would burn ~4 × 400 ms), and a task submitted afterwards still wakes one and runs. */
static void test_idle_workers_sleep(void **state)
{
    (void)state;
    helper_probe h = {0};
    h.pool = pool_with(4);
    sleep_ms(50);
    double c0 = cpu_seconds();
    sleep_ms(400);
    double burnt = cpu_seconds() - c0;
    print_message("4 idle workers used %.1f ms of CPU in 400 ms\n", 1e3 * burnt);
    assert_true(burnt < 0.1);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(h.pool, &st);
    assert_true(st.sleeps >= 4);
    for (int i = 0; i < 10; i++) {
        sw_th_task t = {.fn = probe_fn, .ctx = &h};
        assert_int_equal(sw_th_pool_submit(h.pool, &t), SW_OK);
        while (atomic_load(&h.ran) < i + 1)
            sched_yield();
        sleep_ms(5); /* let the pool fall asleep again */
    }
    assert_int_equal(atomic_load(&h.ran_by_caller), 0);
    sw_th_pool_destroy(h.pool);
}

/* ---- accounting: kinds, queue lengths, timing ----------------------------------------------- */

typedef struct kind_spawner {
    sw_th_pool *pool;
    sw_th_group *group;
    gate *g;
    _Atomic int children_ran;
} kind_spawner;

static void child_fn(void *ctx)
{
    kind_spawner *sp = ctx;
    atomic_fetch_add(&sp->children_ran, 1);
}

/* Submits 4 HIERARCHY children to its worker's own deque, then holds the worker until opened. */
static void hold_after_spawning_fn(void *ctx)
{
    kind_spawner *sp = ctx;
    for (int i = 0; i < 4; i++) {
        sw_th_task t = {.fn = child_fn, .ctx = sp, .group = sp->group, .kind = g_kind.hierarchy};
        assert_int_equal(sw_th_pool_submit(sp->pool, &t), SW_OK);
    }
    gate_fn(sp->g);
}

/* One worker held by a COMPILE task that queued 4 children in its deque; 5 FRAME tasks and 3
 * BACKGROUND ones injected from here: the queue holds exactly 12 (9 + 3 by priority) while
 * nothing can move, the injection peak is the 5 of the FRAME queue (the children never went
 * through it), and once everything ran each kind counts exactly its own tasks, untimed. */
static void test_kinds_and_queue(void **state)
{
    (void)state;
    sw_th_pool *pool = pool_with(1);
    sw_th_group grp;
    sw_th_group_init(&grp);
    gate g = {0};
    kind_spawner sp = {.pool = pool, .group = &grp, .g = &g};
    sw_th_task hold = {
        .fn = hold_after_spawning_fn, .ctx = &sp, .group = &grp, .kind = g_kind.compile};
    assert_int_equal(sw_th_pool_submit(pool, &hold), SW_OK);
    while (!atomic_load(&g.running))
        sched_yield();
    assert_int_equal(sw_th_pool_inject_peak_take(pool), 1); /* the hold task itself */
    for (int i = 0; i < 8; i++) {
        sw_th_task t = {.fn = child_fn,
                        .ctx = &sp,
                        .group = &grp,
                        .priority = i < 5 ? SW_TH_PRIORITY_FRAME : SW_TH_PRIORITY_BACKGROUND,
                        .kind = i < 5 ? g_kind.refine : g_kind.build};
        assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    }
    int64_t by[SW_TH_PRIORITY_COUNT] = {0};
    assert_int_equal(sw_th_pool_queued(pool, by), 12);
    assert_int_equal(by[SW_TH_PRIORITY_FRAME], 9);
    assert_int_equal(by[SW_TH_PRIORITY_BACKGROUND], 3);
    assert_int_equal(sw_th_pool_inject_peak_take(pool), 5);
    assert_int_equal(sw_th_pool_inject_peak_take(pool), 0);
    atomic_store(&g.open, 1);
    sw_th_group_wait(pool, &grp);
    assert_int_equal(atomic_load(&sp.children_ran), 12);
    assert_int_equal(sw_th_pool_queued(pool, NULL), 0);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(pool, &st);
    uint64_t want[SW_TH_TASK_KIND_MAX] = {0};
    want[g_kind.compile] = 1;
    want[g_kind.hierarchy] = 4;
    want[g_kind.refine] = 5;
    want[g_kind.build] = 3;
    for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++) {
        assert_int_equal(st.executed_by_kind[k], want[k]);
        assert_int_equal(st.ns_by_kind[k], 0); /* timing is off by default */
    }
    assert_int_equal(st.executed, 13);
    sw_th_pool_destroy(pool);
    assert_string_equal(sw_th_task_kind_name(g_kind.build), "t_build");
}

enum { NAP_MS = 30 };

static void nap_fn(void *ctx)
{
    (void)ctx;
    sleep_ms(NAP_MS);
}

typedef struct waiter {
    sw_th_pool *pool;
} waiter;

/* Runs two naps in a group and waits for them: on a one-worker pool it runs them itself,
 * nested in sw_th_group_wait. */
static void wait_for_naps_fn(void *ctx)
{
    waiter *w = ctx;
    sw_th_group naps;
    sw_th_group_init(&naps);
    for (int i = 0; i < 2; i++) {
        sw_th_task t = {.fn = nap_fn, .group = &naps, .kind = g_kind.hierarchy};
        assert_int_equal(sw_th_pool_submit(w->pool, &t), SW_OK);
    }
    sw_th_group_wait(w->pool, &naps);
}

/* Timed: the two nested naps count >= 2 x 30 ms under HIERARCHY, and the waiting task only its
 * own time (not the naps again: well under one nap). Untimed again: a further nap is counted
 * but adds no time. */
static void test_kind_timing_nested(void **state)
{
    (void)state;
    sw_th_pool *pool = NULL;
    sw_th_pool_desc d = {.worker_count = 1, .time_tasks = 1};
    assert_int_equal(sw_th_pool_create(&d, &pool), SW_OK);
    waiter w = {pool};
    sw_th_group grp;
    sw_th_group_init(&grp);
    sw_th_task t = {.fn = wait_for_naps_fn, .ctx = &w, .group = &grp, .kind = g_kind.wait};
    assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    while (sw_th_group_pending(&grp) > 0) /* polls: a helping caller could take a nap itself */
        sleep_ms(1);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(pool, &st);
    print_message("naps %.3f ms, their waiter's own time %.3f ms\n",
                  1e-6 * (double)st.ns_by_kind[g_kind.hierarchy],
                  1e-6 * (double)st.ns_by_kind[g_kind.wait]);
    assert_int_equal(st.executed_by_kind[g_kind.hierarchy], 2);
    assert_int_equal(st.executed_by_kind[g_kind.wait], 1);
    assert_true(st.ns_by_kind[g_kind.hierarchy] >= 2u * NAP_MS * 1000000u);
    assert_true(st.ns_by_kind[g_kind.wait] < NAP_MS * 1000000u);
    sw_th_pool_set_task_timing(pool, 0);
    sw_th_task nap = {.fn = nap_fn, .group = &grp, .kind = g_kind.hierarchy};
    assert_int_equal(sw_th_pool_submit(pool, &nap), SW_OK);
    while (sw_th_group_pending(&grp) > 0)
        sleep_ms(1);
    sw_th_pool_stats st2;
    sw_th_pool_stats_get(pool, &st2);
    assert_int_equal(st2.executed_by_kind[g_kind.hierarchy], 3);
    assert_int_equal(st2.ns_by_kind[g_kind.hierarchy], st.ns_by_kind[g_kind.hierarchy]);
    sw_th_pool_destroy(pool);
}

/* A timed task's time shows while it runs, not only once it ends: half way through a 200 ms
 * STATIC_BUILD task the pool reports >= 90 ms of it and none ended; after it, >= 200 ms. */
static void test_kind_time_while_running(void **state)
{
    (void)state;
    sw_th_pool *pool = NULL;
    sw_th_pool_desc d = {.worker_count = 1, .time_tasks = 1};
    assert_int_equal(sw_th_pool_create(&d, &pool), SW_OK);
    sw_th_group grp;
    sw_th_group_init(&grp);
    gate g = {0};
    sw_th_task hold = {.fn = gate_fn, .ctx = &g, .group = &grp, .kind = g_kind.build};
    assert_int_equal(sw_th_pool_submit(pool, &hold), SW_OK);
    while (!atomic_load(&g.running))
        sched_yield();
    sleep_ms(100);
    sw_th_pool_stats st;
    sw_th_pool_stats_get(pool, &st);
    const double half = 1e-6 * (double)st.ns_by_kind[g_kind.build];
    assert_int_equal(st.executed_by_kind[g_kind.build], 0);
    assert_true(half >= 90.0);
    sleep_ms(100);
    atomic_store(&g.open, 1);
    while (sw_th_group_pending(&grp) > 0)
        sleep_ms(1);
    sw_th_pool_stats_get(pool, &st);
    const double whole = 1e-6 * (double)st.ns_by_kind[g_kind.build];
    print_message("a 200 ms task: %.1f ms half way, %.1f ms at its end\n", half, whole);
    assert_int_equal(st.executed_by_kind[g_kind.build], 1);
    assert_true(whole >= 200.0 && whole >= half);
    sw_th_pool_destroy(pool);
}

/* A binary tree of tasks whose kind is its depth mod the kind count: level d of a tree of depth
 * TREE_DEPTH holds 2^(TREE_DEPTH - d) tasks. Roots come through the injection queue, the rest
 * through the workers' deques. */
enum { TREE_DEPTH = 9, TREE_ROOTS = 40 };

typedef struct kind_level {
    sw_th_pool *pool;
    sw_th_group *group;
    sw_th_task_kind kind;     /* of this level's tasks */
    struct kind_level *below; /* NULL at depth 0 */
} kind_level;

static void kind_tree_fn(void *ctx)
{
    kind_level *l = ctx;
    for (int i = 0; l->below && i < 2; i++) {
        sw_th_task t = {
            .fn = kind_tree_fn, .ctx = l->below, .group = l->group, .kind = l->below->kind};
        assert_int_equal(sw_th_pool_submit(l->pool, &t), SW_OK);
    }
}

/* Three timed workers run 40 trees of mixed kinds while this thread samples the statistics: every
 * sample's per-kind counts and times only grow and the queue is never negative; at the end each
 * kind counts exactly its tasks (single-writer counters lose nothing), and under TSan the
 * samplers' reads race with nothing. */
static void test_kind_counts_concurrent(void **state)
{
    (void)state;
    sw_th_pool *pool = NULL;
    sw_th_pool_desc d = {.worker_count = 3, .time_tasks = 1};
    assert_int_equal(sw_th_pool_create(&d, &pool), SW_OK);
    sw_th_group grp;
    sw_th_group_init(&grp);
    kind_level levels[TREE_DEPTH + 1];
    uint64_t want[SW_TH_TASK_KIND_MAX] = {0};
    for (int depth = 0; depth <= TREE_DEPTH; depth++) {
        levels[depth] = (kind_level){pool, &grp, (sw_th_task_kind)(depth % SW_TH_TASK_KIND_MAX),
                                     depth ? &levels[depth - 1] : NULL};
        want[depth % SW_TH_TASK_KIND_MAX] += (uint64_t)TREE_ROOTS << (TREE_DEPTH - depth);
    }
    for (int r = 0; r < TREE_ROOTS; r++) {
        sw_th_task t = {.fn = kind_tree_fn,
                        .ctx = &levels[TREE_DEPTH],
                        .group = &grp,
                        .kind = levels[TREE_DEPTH].kind};
        assert_int_equal(sw_th_pool_submit(pool, &t), SW_OK);
    }
    sw_th_pool_stats prev = {0};
    int samples = 0;
    while (sw_th_group_pending(&grp) > 0) { /* polls: stats only, no helping */
        sw_th_pool_stats st;
        sw_th_pool_stats_get(pool, &st);
        for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++) {
            assert_true(st.executed_by_kind[k] >= prev.executed_by_kind[k]);
            /* a running task's time so far may run ahead of its end by a store buffer's delay
             * (sw_th_pool_stats.ns_by_kind): 100 us is thousands of times that */
            assert_true(st.ns_by_kind[k] + 100000u >= prev.ns_by_kind[k]);
        }
        assert_true(sw_th_pool_queued(pool, NULL) >= 0);
        assert_true(sw_th_pool_inject_peak_take(pool) <= TREE_ROOTS);
        prev = st;
        samples++;
    }
    sw_th_pool_stats st;
    sw_th_pool_stats_get(pool, &st);
    uint64_t all = 0;
    for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++) {
        assert_int_equal(st.executed_by_kind[k], want[k]);
        all += want[k];
    }
    assert_int_equal(st.executed, all);
    assert_int_equal(sw_th_pool_queued(pool, NULL), 0);
    print_message("%d samples while %llu tasks of %d kinds ran\n", samples, (unsigned long long)all,
                  (int)SW_TH_TASK_KIND_MAX);
    sw_th_pool_destroy(pool);
}

/* Registering: one value per name, distinct names distinct values, "other" at 0, the table's
 * end gives "other" and leaves the names as they were; slots register once, from any thread, with
 * the same value as a direct registration. Would catch a registry that hands out a second value
 * for a name (a profile column split in two), overruns its table, or a slot racing to two values.
 */
static void *slot_thread(void *arg)
{
    return (void *)(uintptr_t)sw_th_task_kind_of(arg);
}

static void test_kind_registry(void **state)
{
    (void)state;
    assert_string_equal(sw_th_task_kind_name(SW_TH_TASK_OTHER), "other");
    assert_int_equal(sw_th_task_kind_register("t_hierarchy"), g_kind.hierarchy);
    assert_true(g_kind.hierarchy != g_kind.compile && g_kind.hierarchy != SW_TH_TASK_OTHER);
    static sw_th_task_kind_slot slot = SW_TH_TASK_KIND_SLOT("t_slot");
    pthread_t th[4];
    for (int i = 0; i < 4; i++)
        assert_int_equal(pthread_create(&th[i], NULL, slot_thread, &slot), 0);
    uintptr_t got[4];
    for (int i = 0; i < 4; i++) {
        void *v;
        pthread_join(th[i], &v);
        got[i] = (uintptr_t)v;
    }
    for (int i = 1; i < 4; i++)
        assert_int_equal(got[i], got[0]);
    assert_int_equal(sw_th_task_kind_register("t_slot"), got[0]);
    assert_string_equal(sw_th_task_kind_name((sw_th_task_kind)got[0]), "t_slot");
    /* fill the table: the rest get values up to the end, then "other" */
    static const char *const extra[SW_TH_TASK_KIND_MAX] = {"x0",  "x1",  "x2",  "x3", "x4",  "x5",
                                                           "x6",  "x7",  "x8",  "x9", "x10", "x11",
                                                           "x12", "x13", "x14", "x15"};
    for (int i = 0; i < SW_TH_TASK_KIND_MAX; i++) {
        const uint32_t before = sw_th_task_kind_count();
        const sw_th_task_kind k = sw_th_task_kind_register(extra[i]);
        if (before < SW_TH_TASK_KIND_MAX) {
            assert_int_equal(k, before);
            assert_string_equal(sw_th_task_kind_name(k), extra[i]);
        } else {
            assert_int_equal(k, SW_TH_TASK_OTHER);
        }
    }
    assert_int_equal(sw_th_task_kind_count(), SW_TH_TASK_KIND_MAX);
    assert_string_equal(sw_th_task_kind_name(g_kind.hierarchy), "t_hierarchy");
    assert_string_equal(sw_th_task_kind_name(SW_TH_TASK_KIND_MAX), "?");
}

int main(void)
{
    register_test_kinds();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cancel_external),
        cmocka_unit_test(test_cancel_from_task),
        cmocka_unit_test(test_priority_external),
        cmocka_unit_test(test_priority_local),
        cmocka_unit_test(test_group_wait_helps),
        cmocka_unit_test(test_fork_join),
        cmocka_unit_test(test_thread_waits),
        cmocka_unit_test(test_shutdown_drains),
        cmocka_unit_test(test_no_lost_wakeup),
        cmocka_unit_test(test_idle_workers_sleep),
        cmocka_unit_test(test_kinds_and_queue),
        cmocka_unit_test(test_kind_timing_nested),
        cmocka_unit_test(test_kind_counts_concurrent),
        cmocka_unit_test(test_kind_time_while_running),
        cmocka_unit_test(test_kind_registry), /* last: it fills the table */
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

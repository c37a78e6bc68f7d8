/* SPDX-License-Identifier: MIT */
/* The work-stealing worker pool (sw_th_pool.h): per-worker Chase-Lev deques per priority,
 * lock-free MPSC injection queues for other threads, random-victim stealing of one task or of
 * half the victim's deque (Kumar et al. 1997, §5.1), and workers that sleep when idle.
 *
 * Sleeping without a lock on the hot path (the scheme of Go's runtime, wakep/nmspinning):
 *  - `searching` counts workers looking for work, `sleepers` workers that announced they sleep.
 *  - After making a task visible, a submitter reads `searching` and `sleepers` (seq_cst loads, no
 *    lock); only if nobody searches and somebody sleeps does it claim a searcher slot for a
 *    sleeper (CAS 0 → 1) and signal it under `lock`.
 *  - A worker about to sleep increments `sleepers`, decrements `searching` (seq_cst RMWs), then
 *    looks at every deque and injection count once more (seq_cst loads) before blocking.
 * The task's publication (seq_cst store of the deque's bottom, seq_cst RMW of an injection
 * count) and those loads form a Dekker pair with the sleeper's RMWs and re-check: in the total
 * order S either the sleeper's re-check sees the task, or the submitter sees the sleeper (or a
 * searcher that will itself re-check). So no task is left with every worker asleep.
 *
 * Threads blocked in sw_th_group_wait take part in the same protocol (they are sleepers too, so
 * new work can wake them to help); the last task of a group broadcasts if anyone waits.
 *
 * The one lock, `lock`, protects `wakes` (wake tokens handed to sleepers) and every
 * test-then-wait on `wake_cond`. It is never held while taking another lock, and push, pop and
 * steal never take it.
 */
#include "sw_clock.h"
#include "sw_th_pool.h"
#include "sw_hooks.h"
#include "sw_th_deque.h"

#include <assert.h>
#include <pthread.h>
#include <sched.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

enum {
    INJECT_BATCH = 32,     /* injected tasks a worker moves into its deque at once */
    STEAL_HALF_MAX = 1024, /* bound on one half-steal, so a thief cannot stall for long */
    STEAL_RETRIES = 4,     /* lost CAS races tolerated per victim per search */
    FRAME_PROBE = 16,      /* every so many background tasks, look for others' FRAME tasks */
    FREE_CHUNK = 256,      /* nodes per chain moved between workers' free lists */
    SPARE_SLOTS = 16,
    MAX_WORKERS = 1024
};

typedef struct node {
    _Atomic(struct node *) next; /* injection-queue link */
    struct node *free_next;      /* free-list link (owner of the list only) */
    sw_th_task task;
} node;

/* Vyukov's intrusive MPSC queue. Producers: any thread (one exchange). The consumer side is
 * serialised by `busy`, a try-flag: a worker that finds it taken goes on searching elsewhere,
 * nobody ever waits on it. */
typedef struct inject_queue {
    alignas(SW_TH_CACHE_LINE) _Atomic(node *) head;
    alignas(SW_TH_CACHE_LINE) node *tail; /* holder of `busy` only */
    _Atomic int busy;
    node stub;
    alignas(SW_TH_CACHE_LINE) _Atomic int64_t count; /* pushed, not yet popped */
} inject_queue;

typedef struct worker {
    sw_th_deque deques[SW_TH_PRIORITY_COUNT];
    struct sw_th_pool *pool;
    uint32_t index;
    uint32_t probe;
    uint64_t rng;
    node *free_list;
    uint32_t free_count;
    bool started;
    pthread_t thread;
    /* Written by the owner only (load + store), read by sw_th_pool_stats_get. */
    alignas(SW_TH_CACHE_LINE) _Atomic uint64_t executed;
    _Atomic uint64_t cancelled, steals, stolen, sleeps;
    _Atomic uint64_t kind_executed[SW_TH_TASK_KIND_MAX];
    /* Timed tasks' own time: kind_ns (ended segments) and the segment running now (seg_kind,
     * SW_TH_TASK_KIND_MAX for none, since seg_start), under the seqlock seg_seq (odd while the
     * owner updates them) so that a reader adds the running segment to a consistent total. */
    _Atomic uint64_t seg_seq;
    _Atomic uint64_t kind_ns[SW_TH_TASK_KIND_MAX];
    _Atomic uint32_t seg_kind;
    _Atomic uint64_t seg_start;
} worker;

struct sw_th_pool {
    worker *workers;
    uint32_t count;
    sw_th_steal_mode mode;
    uint32_t spin_rounds;
    inject_queue inject[SW_TH_PRIORITY_COUNT];
    alignas(SW_TH_CACHE_LINE) _Atomic int searching;
    _Atomic int sleepers;
    _Atomic int stop;
    _Atomic int group_waiters;
    alignas(SW_TH_CACHE_LINE) _Atomic(node *) spare[SPARE_SLOTS];
    alignas(SW_TH_CACHE_LINE) _Atomic uint64_t ext_executed;
    _Atomic uint64_t ext_cancelled, ext_steals;
    _Atomic uint64_t ext_kind_executed[SW_TH_TASK_KIND_MAX], ext_kind_ns[SW_TH_TASK_KIND_MAX];
    _Atomic int time_tasks;      /* read per task (relaxed): a switch, it orders nothing */
    _Atomic int64_t inject_peak; /* longest injection queue a submission made since the last
                                    sw_th_pool_inject_peak_take */
    pthread_mutex_t lock;
    pthread_cond_t wake_cond;
    int wakes; /* under lock */
};

static _Thread_local worker *tls_worker;
static _Thread_local uint64_t tls_rng;
/* The calling thread's running segment of timed task time: the kind of its innermost timed task
 * (SW_TH_TASK_KIND_MAX: none) and since when it runs uninterrupted by a nested task. */
static _Thread_local uint32_t tls_seg_kind = SW_TH_TASK_KIND_MAX;
static _Thread_local uint64_t tls_seg_start;
/* The calling thread's waits (sw_th_thread_waits): outermost waits counted, their time summed. */
static _Thread_local uint32_t tls_wait_depth;
static _Thread_local uint64_t tls_wait_start, tls_waits, tls_wait_ns;

static void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause");
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

static uint64_t xorshift(uint64_t *s)
{
    uint64_t x = *s ? *s : 0x9e3779b97f4a7c15u;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *s = x;
}

/* Single-writer counter: the owner's plain increment, readable by any thread. */
static void bump(_Atomic uint64_t *c, uint64_t n)
{
    atomic_store_explicit(c, atomic_load_explicit(c, memory_order_relaxed) + n,
                          memory_order_relaxed);
}

static worker *own_worker(const sw_th_pool *pool)
{
    worker *w = tls_worker;
    return w && w->pool == pool ? w : NULL;
}

/* ---- task nodes: per-worker free lists, whole chains exchanged through `spare` -------------- */

static node *node_alloc(sw_th_pool *pool, worker *w)
{
    if (w && !w->free_list) {
        for (int i = 0; i < SPARE_SLOTS && !w->free_list; i++) {
            /* acquire: pairs with the release CAS in node_spill (the chain's links). */
            node *chain = atomic_exchange_explicit(&pool->spare[i], NULL, memory_order_acquire);
            if (chain) {
                w->free_list = chain;
                w->free_count = FREE_CHUNK;
            }
        }
    }
    if (w && w->free_list) {
        node *n = w->free_list;
        w->free_list = n->free_next;
        w->free_count--;
        return n;
    }
    return sw__malloc(sizeof(node));
}

/* Moves FREE_CHUNK nodes of a long free list to a spare slot (or back to malloc): a worker
 * that only consumes stolen tasks would otherwise hoard nodes its producer keeps allocating. */
static void node_spill(sw_th_pool *pool, worker *w)
{
    node *chain = w->free_list, *last = chain;
    for (int i = 1; i < FREE_CHUNK; i++)
        last = last->free_next;
    w->free_list = last->free_next;
    w->free_count -= FREE_CHUNK;
    last->free_next = NULL;
    for (int i = 0; i < SPARE_SLOTS; i++) {
        node *expected = NULL;
        if (atomic_compare_exchange_strong_explicit(&pool->spare[i], &expected, chain,
                                                    memory_order_release, memory_order_relaxed))
            return;
    }
    while (chain) {
        node *next = chain->free_next;
        sw__free(chain);
        chain = next;
    }
}

static void node_free(sw_th_pool *pool, worker *w, node *n)
{
    if (!w) {
        sw__free(n);
        return;
    }
    n->free_next = w->free_list;
    w->free_list = n;
    if (++w->free_count >= 2 * FREE_CHUNK)
        node_spill(pool, w);
}

/* ---- injection queues ---------------------------------------------------------------------- */

static void inject_link(inject_queue *q, node *n)
{
    atomic_store_explicit(&n->next, NULL, memory_order_relaxed);
    /* acq_rel: serialises producers; the release half is not what publishes n (see below). */
    node *prev = atomic_exchange_explicit(&q->head, n, memory_order_acq_rel);
    /* release: publishes n's task to the consumer's acquire load of prev->next. */
    atomic_store_explicit(&prev->next, n, memory_order_release);
}

/* Returns the queue's length with n (its count just after the increment). */
static int64_t inject_push(inject_queue *q, node *n)
{
    /* seq_cst, and before linking: a worker about to sleep that sees count > 0 keeps searching
     * (the Dekker pair of the sleep protocol, file comment). */
    const int64_t len = atomic_fetch_add_explicit(&q->count, 1, memory_order_seq_cst) + 1;
    inject_link(q, n);
    return len;
}

/* Raises inject_peak to len. relaxed: a statistic; the load first, so a submitter writes the
 * shared line only while the queue grows past the mark. */
static void record_inject_peak(sw_th_pool *pool, int64_t len)
{
    int64_t peak = atomic_load_explicit(&pool->inject_peak, memory_order_relaxed);
    while (len > peak &&
           !atomic_compare_exchange_weak_explicit(&pool->inject_peak, &peak, len,
                                                  memory_order_relaxed, memory_order_relaxed)) {
        /* the failed CAS reloaded peak */
    }
}

/* Holder of q->busy only. NULL when empty or while a producer is between exchange and link. */
static node *inject_pop(inject_queue *q)
{
    /* acquire loads of next: pair with the release store in inject_link (the node's task). */
    node *tail = q->tail;
    node *next = atomic_load_explicit(&tail->next, memory_order_acquire);
    if (tail == &q->stub) {
        if (!next)
            return NULL;
        q->tail = tail = next;
        next = atomic_load_explicit(&tail->next, memory_order_acquire);
    }
    if (next) {
        q->tail = next;
        return tail;
    }
    /* acquire: pairs with the producers' exchange of head. */
    if (tail != atomic_load_explicit(&q->head, memory_order_acquire))
        return NULL;
    inject_link(q, &q->stub);
    next = atomic_load_explicit(&tail->next, memory_order_acquire);
    if (!next)
        return NULL;
    q->tail = next;
    return tail;
}

/* Pops up to `max` injected tasks into out[], oldest first. */
static int inject_take(inject_queue *q, node **out, int max)
{
    /* relaxed: a hint only; the queue itself decides what is there. */
    if (atomic_load_explicit(&q->count, memory_order_relaxed) <= 0)
        return 0;
    /* acquire/release on the try-flag: hands `tail` from one consumer to the next. */
    if (atomic_exchange_explicit(&q->busy, 1, memory_order_acquire))
        return 0;
    int n = 0;
    while (n < max && (out[n] = inject_pop(q)) != NULL)
        n++;
    atomic_store_explicit(&q->busy, 0, memory_order_release);
    /* relaxed: count only steers searching and sleeping; a stale positive value just makes a
     * worker look once more. */
    if (n)
        atomic_fetch_sub_explicit(&q->count, n, memory_order_relaxed);
    return n;
}

/* ---- waking sleepers ------------------------------------------------------------------------- */

static void notify(sw_th_pool *pool)
{
    /* seq_cst loads: the submitter's half of the Dekker pair (file comment). */
    if (atomic_load_explicit(&pool->searching, memory_order_seq_cst) != 0)
        return;
    if (atomic_load_explicit(&pool->sleepers, memory_order_seq_cst) == 0)
        return;
    int zero = 0;
    /* Claim the searcher slot for the sleeper we wake, so that a burst of pushes wakes one. */
    if (!atomic_compare_exchange_strong_explicit(&pool->searching, &zero, 1, memory_order_seq_cst,
                                                 memory_order_relaxed))
        return;
    /* lock protects wakes; the sleeper tests it under the same lock before waiting. */
    pthread_mutex_lock(&pool->lock);
    pool->wakes++;
    pthread_cond_signal(&pool->wake_cond);
    pthread_mutex_unlock(&pool->lock);
}

static bool work_visible(sw_th_pool *pool)
{
    for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++) {
        if (atomic_load_explicit(&pool->inject[p].count, memory_order_seq_cst) > 0)
            return true;
        for (uint32_t i = 0; i < pool->count; i++)
            if (sw_th_deque_size_estimate(&pool->workers[i].deques[p]) > 0)
                return true;
    }
    return false;
}

/* ---- finding work ---------------------------------------------------------------------------- */

/* Re-homes a task a worker could not push (out of memory growing its deque). */
static void push_or_inject(sw_th_pool *pool, worker *w, int prio, node *n)
{
    if (sw_th_deque_push_owner(&w->deques[prio], n) != SW_OK)
        (void)inject_push(&pool->inject[prio], n);
}

static node *take_injected(sw_th_pool *pool, worker *w, int prio)
{
    node *batch[INJECT_BATCH];
    int n = inject_take(&pool->inject[prio], batch, w ? INJECT_BATCH : 1);
    if (n == 0)
        return NULL;
    /* Newest first, so that the owner pops them in submission order. */
    for (int i = n - 1; i >= 1; i--)
        push_or_inject(pool, w, prio, batch[i]);
    if (n > 1)
        notify(pool);
    return batch[0];
}

/* Steal half (Kumar §5.1) as repeated single steals: one CAS moving top by k would race with
 * an owner that pops several items without a CAS (it CASes only for the last one). */
static void steal_more(sw_th_pool *pool, worker *w, int prio, sw_th_deque *victim)
{
    int64_t extra = sw_th_deque_size_estimate(victim) / 2;
    if (extra > STEAL_HALF_MAX)
        extra = STEAL_HALF_MAX;
    uint64_t moved = 0;
    for (int64_t i = 0; i < extra; i++) {
        void *x;
        sw_th_steal_result r = sw_th_deque_steal(victim, &x);
        if (r == SW_TH_STEAL_EMPTY)
            break;
        if (r == SW_TH_STEAL_OK) {
            push_or_inject(pool, w, prio, x);
            moved++;
        }
    }
    bump(&w->stolen, moved);
}

static node *steal_any(sw_th_pool *pool, worker *w, int prio)
{
    uint32_t count = pool->count;
    uint32_t start = (uint32_t)(xorshift(w ? &w->rng : &tls_rng) % count);
    for (uint32_t k = 0; k < count; k++) {
        uint32_t v = (start + k) % count;
        if (w && v == w->index)
            continue;
        sw_th_deque *victim = &pool->workers[v].deques[prio];
        for (int attempt = 0; attempt < STEAL_RETRIES; attempt++) {
            void *x;
            sw_th_steal_result r = sw_th_deque_steal(victim, &x);
            if (r == SW_TH_STEAL_EMPTY)
                break;
            if (r == SW_TH_STEAL_RETRY)
                continue;
            if (!w) {
                atomic_fetch_add_explicit(&pool->ext_steals, 1, memory_order_relaxed);
                return x;
            }
            bump(&w->steals, 1);
            bump(&w->stolen, 1);
            if (pool->mode == SW_TH_STEAL_MODE_HALF) {
                steal_more(pool, w, prio, victim);
                notify(pool);
            }
            return x;
        }
    }
    return NULL;
}

/* FRAME work before BACKGROUND work: own deque, injected, then other workers'. A worker busy
 * with its own BACKGROUND tasks still looks at the others' FRAME tasks every FRAME_PROBE. */
static node *find_work(sw_th_pool *pool, worker *w)
{
    node *n;
    if (w && (n = sw_th_deque_pop_owner(&w->deques[SW_TH_PRIORITY_FRAME])))
        return n;
    if ((n = take_injected(pool, w, SW_TH_PRIORITY_FRAME)))
        return n;
    if (!w || ++w->probe >= FRAME_PROBE) {
        if (w)
            w->probe = 0;
        if ((n = steal_any(pool, w, SW_TH_PRIORITY_FRAME)))
            return n;
    }
    if (w && (n = sw_th_deque_pop_owner(&w->deques[SW_TH_PRIORITY_BACKGROUND])))
        return n;
    if ((n = take_injected(pool, w, SW_TH_PRIORITY_BACKGROUND)))
        return n;
    if (w && (n = steal_any(pool, w, SW_TH_PRIORITY_FRAME)))
        return n;
    return steal_any(pool, w, SW_TH_PRIORITY_BACKGROUND);
}

static void group_release(sw_th_pool *pool, sw_th_group *g)
{
    /* seq_cst RMW then seq_cst load of group_waiters: Dekker pair with sw_th_group_wait. After
     * the decrement g may already be gone (the waiter returned): only the pool is touched. */
    if (atomic_fetch_sub_explicit(&g->pending, 1, memory_order_seq_cst) != 1)
        return;
    if (atomic_load_explicit(&pool->group_waiters, memory_order_seq_cst) == 0)
        return;
    pthread_mutex_lock(&pool->lock); /* group waiters test pending under it before waiting */
    pthread_cond_broadcast(&pool->wake_cond);
    pthread_mutex_unlock(&pool->lock);
}

/* Ends the calling thread's running segment (its time goes to the segment's kind) and starts one
 * of kind `to` (SW_TH_TASK_KIND_MAX: none). A worker publishes both under its seqlock; a thread
 * outside the pool (waiting on a group) adds the ended segment to the pool's shared totals.
 * Writer side of the seqlock: the odd store, then release stores of the data (a reader that
 * acquires any of them also sees the odd count), then the even store (release). The clock is
 * read after the odd store, so that a reader that saw the old state consistently read its own
 * clock before this segment's end, up to a store buffer's delay. */
static void switch_segment(sw_th_pool *pool, worker *w, uint32_t to)
{
    const uint32_t from = tls_seg_kind;
    if (!w) {
        const uint64_t now = sw__clock_ns();
        if (from < SW_TH_TASK_KIND_MAX)
            atomic_fetch_add_explicit(&pool->ext_kind_ns[from], now - tls_seg_start,
                                      memory_order_relaxed);
        tls_seg_kind = to;
        tls_seg_start = now;
        return;
    }
    const uint64_t seq = atomic_load_explicit(&w->seg_seq, memory_order_relaxed);
    atomic_store_explicit(&w->seg_seq, seq + 1, memory_order_relaxed);
    const uint64_t now = sw__clock_ns();
    if (from < SW_TH_TASK_KIND_MAX)
        atomic_store_explicit(&w->kind_ns[from],
                              atomic_load_explicit(&w->kind_ns[from], memory_order_relaxed) + now -
                                  tls_seg_start,
                              memory_order_release);
    atomic_store_explicit(&w->seg_kind, to, memory_order_release);
    atomic_store_explicit(&w->seg_start, now, memory_order_release);
    atomic_store_explicit(&w->seg_seq, seq + 2, memory_order_release);
    tls_seg_kind = to;
    tls_seg_start = now;
}

/* Runs t timed. Its time is counted in segments: a task that runs others nested (waiting on a
 * group) pauses its own for theirs, so the kinds add up to the thread's busy time instead of
 * counting nested work twice; and a reader sees a running task's time so far, not only once it
 * ends (a static LOD build takes seconds: its time shows in the frames it spans). */
static void timed_run(sw_th_pool *pool, worker *w, const sw_th_task *t)
{
    const uint32_t outer = tls_seg_kind;
    switch_segment(pool, w, (uint32_t)t->kind);
    t->fn(t->ctx);
    switch_segment(pool, w, outer);
}

/* Counts a task that ran: on the worker's single-writer counters, or (a thread outside the pool
 * waiting on a group) on the pool's shared ones. */
static void count_executed(sw_th_pool *pool, worker *w, sw_th_task_kind kind)
{
    if (w) {
        bump(&w->executed, 1);
        bump(&w->kind_executed[kind], 1);
        return;
    }
    atomic_fetch_add_explicit(&pool->ext_executed, 1, memory_order_relaxed);
    atomic_fetch_add_explicit(&pool->ext_kind_executed[kind], 1, memory_order_relaxed);
}

static void run_node(sw_th_pool *pool, worker *w, node *n)
{
    sw_th_task t = n->task;
    node_free(pool, w, n); /* before fn: its children can reuse the node */
    /* acquire: pairs with the release increment in sw_th_token_cancel. */
    bool stale =
        t.token && atomic_load_explicit(&t.token->generation, memory_order_acquire) != t.generation;
    if (stale) {
        if (w)
            bump(&w->cancelled, 1);
        else
            atomic_fetch_add_explicit(&pool->ext_cancelled, 1, memory_order_relaxed);
    } else {
        /* relaxed: a switch; a task that starts just after it flips may go either way */
        if (atomic_load_explicit(&pool->time_tasks, memory_order_relaxed))
            timed_run(pool, w, &t);
        else
            t.fn(t.ctx);
        count_executed(pool, w, t.kind);
    }
    if (t.group)
        group_release(pool, t.group);
}

/* A searcher that found work or leaves: if it was the last one, wake a sleeper for the rest. */
static void stop_searching(sw_th_pool *pool, bool *searching)
{
    if (*searching && atomic_fetch_sub_explicit(&pool->searching, 1, memory_order_seq_cst) == 1)
        notify(pool);
    *searching = false;
}

/* ---- workers --------------------------------------------------------------------------------- */

static void idle_pause(const sw_th_pool *pool, uint32_t fails)
{
    if (fails < pool->spin_rounds / 2)
        cpu_relax();
    else
        sched_yield(); /* oversubscribed pools: let the worker holding the work run */
}

/* Blocks until handed a wake token (returns true: we now hold a searcher slot) or stop. */
static bool sleep_until_woken(sw_th_pool *pool, worker *w)
{
    bool handed = false;
    bump(&w->sleeps, 1);
    pthread_mutex_lock(&pool->lock); /* protects wakes */
    /* relaxed: stop is written before the broadcast under the same lock. */
    while (pool->wakes == 0 && !atomic_load_explicit(&pool->stop, memory_order_relaxed))
        pthread_cond_wait(&pool->wake_cond, &pool->lock);
    if (pool->wakes > 0) {
        pool->wakes--;
        handed = true;
    }
    pthread_mutex_unlock(&pool->lock);
    return handed;
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    sw_th_pool *pool = w->pool;
    tls_worker = w;
    bool searching = false;
    uint32_t fails = 0;
    for (;;) {
        node *n = find_work(pool, w);
        if (n) {
            stop_searching(pool, &searching);
            fails = 0;
            run_node(pool, w, n);
            continue;
        }
        if (!searching) {
            searching = true;
            atomic_fetch_add_explicit(&pool->searching, 1, memory_order_seq_cst);
        }
        if (++fails < pool->spin_rounds) {
            idle_pause(pool, fails);
            continue;
        }
        fails = 0;
        /* The sleeper's half of the Dekker pair: announce, stop searching, look once more. */
        atomic_fetch_add_explicit(&pool->sleepers, 1, memory_order_seq_cst);
        atomic_fetch_sub_explicit(&pool->searching, 1, memory_order_seq_cst);
        searching = false;
        bool stop = atomic_load_explicit(&pool->stop, memory_order_seq_cst);
        if (work_visible(pool)) {
            atomic_fetch_sub_explicit(&pool->sleepers, 1, memory_order_seq_cst);
            continue;
        }
        if (stop) {
            atomic_fetch_sub_explicit(&pool->sleepers, 1, memory_order_seq_cst);
            break;
        }
        searching = sleep_until_woken(pool, w);
        atomic_fetch_sub_explicit(&pool->sleepers, 1, memory_order_seq_cst);
    }
    return NULL;
}

/* ---- public API ------------------------------------------------------------------------------ */

void sw_th_token_init(sw_th_token *token)
{
    atomic_init(&token->generation, 0);
}

uint64_t sw_th_token_current(sw_th_token *token)
{
    return atomic_load_explicit(&token->generation, memory_order_acquire);
}

uint64_t sw_th_token_cancel(sw_th_token *token)
{
    /* release: pairs with the acquire load in run_node. */
    return atomic_fetch_add_explicit(&token->generation, 1, memory_order_acq_rel) + 1;
}

void sw_th_group_init(sw_th_group *group)
{
    atomic_init(&group->pending, 0);
}

int64_t sw_th_group_pending(sw_th_group *group)
{
    return atomic_load_explicit(&group->pending, memory_order_acquire);
}

void sw_th_pool_desc_defaults(sw_th_pool_desc *out, const sw_th_pool_desc *in)
{
    sw_th_pool_desc d = {0};
    if (in)
        d = *in;
    if (d.worker_count == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        d.worker_count = n > 0 && n <= MAX_WORKERS ? (uint32_t)n : 1;
    }
    if (d.steal_mode == SW_TH_STEAL_MODE_DEFAULT)
        d.steal_mode = SW_TH_STEAL_MODE_HALF;
    if (d.spin_rounds == 0)
        d.spin_rounds = 64;
    if (d.deque_capacity == 0)
        d.deque_capacity = 256;
    if (d.seed == 0)
        d.seed = 1;
    *out = d;
}

static size_t round_up(size_t n)
{
    return (n + SW_TH_CACHE_LINE - 1) / SW_TH_CACHE_LINE * SW_TH_CACHE_LINE;
}

static void pool_free(sw_th_pool *pool)
{
    for (uint32_t i = 0; i < pool->count; i++) {
        worker *w = &pool->workers[i];
        for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++)
            sw_th_deque_destroy_owner(&w->deques[p]);
        while (w->free_list) {
            node *next = w->free_list->free_next;
            sw__free(w->free_list);
            w->free_list = next;
        }
    }
    for (int i = 0; i < SPARE_SLOTS; i++) {
        node *chain = atomic_load_explicit(&pool->spare[i], memory_order_acquire);
        while (chain) {
            node *next = chain->free_next;
            sw__free(chain);
            chain = next;
        }
    }
    pthread_mutex_destroy(&pool->lock);
    pthread_cond_destroy(&pool->wake_cond);
    sw__aligned_free(pool->workers);
    sw__aligned_free(pool);
}

static void stop_and_join(sw_th_pool *pool)
{
    atomic_store_explicit(&pool->stop, 1, memory_order_seq_cst);
    pthread_mutex_lock(&pool->lock); /* sleepers test stop under it before waiting */
    pthread_cond_broadcast(&pool->wake_cond);
    pthread_mutex_unlock(&pool->lock);
    for (uint32_t i = 0; i < pool->count; i++)
        if (pool->workers[i].started)
            pthread_join(pool->workers[i].thread, NULL);
}

static sw_result pool_init_workers(sw_th_pool *pool, const sw_th_pool_desc *d)
{
    for (uint32_t i = 0; i < pool->count; i++) {
        worker *w = &pool->workers[i];
        w->pool = pool;
        w->index = i;
        atomic_store_explicit(&w->seg_kind, SW_TH_TASK_KIND_MAX, memory_order_relaxed);
        w->rng = (uint64_t)d->seed * 0x9e3779b97f4a7c15u + i + 1;
        for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++)
            if (sw_th_deque_init_owner(&w->deques[p], d->deque_capacity) != SW_OK)
                return SW_ERR_OUT_OF_MEMORY;
    }
    return SW_OK;
}

sw_result sw_th_pool_create(const sw_th_pool_desc *desc, sw_th_pool **out)
{
    assert(out);
    *out = NULL;
    sw_th_pool_desc d;
    sw_th_pool_desc_defaults(&d, desc);
    if (d.worker_count > MAX_WORKERS || d.steal_mode > SW_TH_STEAL_MODE_HALF)
        return SW_ERR_INVALID_ARGUMENT;
    sw_th_pool *pool = sw__aligned_alloc(SW_TH_CACHE_LINE, round_up(sizeof *pool));
    worker *workers =
        sw__aligned_alloc(SW_TH_CACHE_LINE, round_up(d.worker_count * sizeof *workers));
    if (!pool || !workers) {
        sw__aligned_free(pool);
        sw__aligned_free(workers);
        return SW_ERR_OUT_OF_MEMORY;
    }
    /* Zero bytes are the initial state of every atomic counter and pointer here. */
    memset(pool, 0, sizeof *pool);
    memset(workers, 0, d.worker_count * sizeof *workers);
    pool->workers = workers;
    pool->count = d.worker_count;
    pool->mode = d.steal_mode;
    pool->spin_rounds = d.spin_rounds;
    atomic_store_explicit(&pool->time_tasks, d.time_tasks != 0, memory_order_relaxed);
    for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++) {
        inject_queue *q = &pool->inject[p];
        atomic_init(&q->head, &q->stub);
        q->tail = &q->stub;
    }
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->wake_cond, NULL);
    sw_result r = pool_init_workers(pool, &d);
    for (uint32_t i = 0; r == SW_OK && i < pool->count; i++) {
        if (pthread_create(&workers[i].thread, NULL, worker_main, &workers[i]) != 0)
            r = SW_ERR_INTERNAL;
        else
            workers[i].started = true;
    }
    if (r != SW_OK) {
        stop_and_join(pool);
        pool_free(pool);
        return r;
    }
    *out = pool;
    return SW_OK;
}

void sw_th_pool_destroy(sw_th_pool *pool)
{
    if (!pool)
        return;
    assert(!own_worker(pool) && "a pool cannot be destroyed from one of its tasks");
    stop_and_join(pool);
    for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++)
        assert(atomic_load_explicit(&pool->inject[p].count, memory_order_relaxed) == 0);
    pool_free(pool);
}

sw_result sw_th_pool_submit(sw_th_pool *pool, const sw_th_task *task)
{
    assert(pool && task && task->fn);
    assert((unsigned)task->priority < SW_TH_PRIORITY_COUNT);
    assert((unsigned)task->kind < SW_TH_TASK_KIND_MAX);
    worker *w = own_worker(pool);
    node *n = node_alloc(pool, w);
    if (!n)
        return SW_ERR_OUT_OF_MEMORY;
    n->task = *task;
    /* relaxed: this increment is sequenced before the task can run and release the group, and
     * before the submitting task's own release of it (RMWs of one location are ordered). */
    if (task->group)
        atomic_fetch_add_explicit(&task->group->pending, 1, memory_order_relaxed);
    if (w) {
        if (sw_th_deque_push_owner(&w->deques[task->priority], n) != SW_OK) {
            if (task->group)
                atomic_fetch_sub_explicit(&task->group->pending, 1, memory_order_relaxed);
            node_free(pool, w, n);
            return SW_ERR_OUT_OF_MEMORY;
        }
    } else {
        record_inject_peak(pool, inject_push(&pool->inject[task->priority], n));
    }
    notify(pool);
    return SW_OK;
}

/* The group waiter idles like a worker (same counters, same Dekker pair, same condition
 * variable): it must stay wakeable by new work, or a pool whose workers all wait on groups
 * would deadlock on a task submitted after they blocked. */
void sw_th_wait_begin(void)
{
    if (tls_wait_depth++ == 0) {
        tls_waits++;
        tls_wait_start = sw__clock_ns();
    }
}

void sw_th_wait_end(void)
{
    assert(tls_wait_depth > 0);
    if (--tls_wait_depth == 0)
        tls_wait_ns += sw__clock_ns() - tls_wait_start;
}

sw_th_wait_count sw_th_thread_waits(void)
{
    const sw_th_wait_count c = {tls_waits, tls_wait_ns};
    return c;
}

void sw_th_group_wait(sw_th_pool *pool, sw_th_group *group)
{
    assert(pool && group);
    /* acquire: as the loop's test below */
    if (atomic_load_explicit(&group->pending, memory_order_acquire) <= 0)
        return;
    sw_th_wait_begin();
    worker *w = own_worker(pool);
    bool searching = false;
    uint32_t fails = 0;
    while (atomic_load_explicit(&group->pending, memory_order_acquire) > 0) {
        node *n = find_work(pool, w);
        if (n) {
            stop_searching(pool, &searching);
            fails = 0;
            run_node(pool, w, n);
            continue;
        }
        if (!searching) {
            searching = true;
            atomic_fetch_add_explicit(&pool->searching, 1, memory_order_seq_cst);
        }
        if (++fails < pool->spin_rounds) {
            idle_pause(pool, fails);
            continue;
        }
        fails = 0;
        /* seq_cst RMWs, then seq_cst loads of the queues and of pending: the Dekker pairs with
         * notify (new work) and with group_release (the last task of the group). */
        atomic_fetch_add_explicit(&pool->sleepers, 1, memory_order_seq_cst);
        atomic_fetch_add_explicit(&pool->group_waiters, 1, memory_order_seq_cst);
        atomic_fetch_sub_explicit(&pool->searching, 1, memory_order_seq_cst);
        searching = false;
        if (!work_visible(pool)) {
            pthread_mutex_lock(&pool->lock); /* protects wakes and the test-then-wait */
            while (pool->wakes == 0 &&
                   atomic_load_explicit(&group->pending, memory_order_seq_cst) > 0)
                pthread_cond_wait(&pool->wake_cond, &pool->lock);
            if (pool->wakes > 0) {
                pool->wakes--; /* handed a searcher slot: passed on by stop_searching */
                searching = true;
            }
            pthread_mutex_unlock(&pool->lock);
        }
        atomic_fetch_sub_explicit(&pool->group_waiters, 1, memory_order_seq_cst);
        atomic_fetch_sub_explicit(&pool->sleepers, 1, memory_order_seq_cst);
    }
    stop_searching(pool, &searching);
    sw_th_wait_end();
}

uint32_t sw_th_pool_worker_count(const sw_th_pool *pool)
{
    return pool->count;
}

int sw_th_pool_current_worker(const sw_th_pool *pool)
{
    worker *w = own_worker(pool);
    return w ? (int)w->index : -1;
}

/* Adds worker w's timed task time to ns[]: its ended segments and the one running now. Reader
 * side of the seqlock (switch_segment): an even count, acquire loads of the data, the count
 * again (the acquire loads keep it after them); retried only while the owner is mid-update. */
static void add_task_time(worker *w, uint64_t ns[SW_TH_TASK_KIND_MAX])
{
    uint64_t total[SW_TH_TASK_KIND_MAX], start, seq;
    uint32_t kind;
    for (;;) {
        seq = atomic_load_explicit(&w->seg_seq, memory_order_acquire);
        if (seq & 1) {
            cpu_relax();
            continue;
        }
        for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++)
            total[k] = atomic_load_explicit(&w->kind_ns[k], memory_order_acquire);
        kind = atomic_load_explicit(&w->seg_kind, memory_order_acquire);
        start = atomic_load_explicit(&w->seg_start, memory_order_acquire);
        if (atomic_load_explicit(&w->seg_seq, memory_order_relaxed) == seq)
            break;
    }
    const uint64_t now = sw__clock_ns();
    if (kind < SW_TH_TASK_KIND_MAX && now > start)
        total[kind] += now - start;
    for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++)
        ns[k] += total[k];
}

void sw_th_pool_stats_get(sw_th_pool *pool, sw_th_pool_stats *out)
{
    memset(out, 0, sizeof *out);
    for (uint32_t i = 0; i < pool->count; i++) {
        worker *w = &pool->workers[i];
        out->executed += atomic_load_explicit(&w->executed, memory_order_relaxed);
        out->cancelled += atomic_load_explicit(&w->cancelled, memory_order_relaxed);
        out->steals += atomic_load_explicit(&w->steals, memory_order_relaxed);
        out->stolen_tasks += atomic_load_explicit(&w->stolen, memory_order_relaxed);
        out->sleeps += atomic_load_explicit(&w->sleeps, memory_order_relaxed);
        for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++)
            out->executed_by_kind[k] +=
                atomic_load_explicit(&w->kind_executed[k], memory_order_relaxed);
        add_task_time(w, out->ns_by_kind);
    }
    for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++) {
        out->executed_by_kind[k] +=
            atomic_load_explicit(&pool->ext_kind_executed[k], memory_order_relaxed);
        out->ns_by_kind[k] += atomic_load_explicit(&pool->ext_kind_ns[k], memory_order_relaxed);
    }
    out->executed += atomic_load_explicit(&pool->ext_executed, memory_order_relaxed);
    out->cancelled += atomic_load_explicit(&pool->ext_cancelled, memory_order_relaxed);
    out->steals += atomic_load_explicit(&pool->ext_steals, memory_order_relaxed);
    out->stolen_tasks += atomic_load_explicit(&pool->ext_steals, memory_order_relaxed);
}

void sw_th_pool_set_task_timing(sw_th_pool *pool, int on)
{
    atomic_store_explicit(&pool->time_tasks, on != 0, memory_order_relaxed);
}

int64_t sw_th_pool_queued(sw_th_pool *pool, int64_t by_priority[SW_TH_PRIORITY_COUNT])
{
    int64_t total = 0;
    for (int p = 0; p < SW_TH_PRIORITY_COUNT; p++) {
        /* relaxed: a statistic; the count of an injection queue may run ahead of its links
         * (incremented before linking), which is what "submitted, not yet taken" means */
        int64_t n = atomic_load_explicit(&pool->inject[p].count, memory_order_relaxed);
        n = n > 0 ? n : 0;
        for (uint32_t i = 0; i < pool->count; i++)
            n += sw_th_deque_size_estimate(&pool->workers[i].deques[p]);
        if (by_priority)
            by_priority[p] = n;
        total += n;
    }
    return total;
}

int64_t sw_th_pool_inject_peak_take(sw_th_pool *pool)
{
    /* relaxed: a statistic; a submission racing with the reset counts in one period or the next */
    return atomic_exchange_explicit(&pool->inject_peak, 0, memory_order_relaxed);
}

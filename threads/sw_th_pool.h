/* SPDX-License-Identifier: MIT */
/* splinewalk threads — the work-stealing worker pool (ARCHITECTURE.md: worker pool T).
 *
 * Kumar, Manocha, Zhang, Hoff 1997, §5.1: each processor runs from its own queue; an idle one
 * takes work from a busy one, lock-free. Here each worker owns one Chase-Lev deque per priority
 * (sw_th_deque.h); a task submitted from inside a task goes to the running worker's own deque,
 * one submitted from any other thread goes to a lock-free MPSC injection queue per priority that
 * workers drain into their deques. Idle workers steal from a random victim either one task or
 * half of the victim's tasks (Kumar's "partitions Q(busy) into two"), chosen per pool
 * (bench/steal measures both). Idle workers spin briefly, then sleep on a condition variable;
 * the push/pop/steal path takes no lock (it reads an atomic sleeper count and only then wakes).
 *
 * Priorities: a worker takes FRAME tasks (its own, injected, then a periodic look at the other
 * workers') before BACKGROUND ones. Cancellation: a task names a token and the token generation
 * it belongs to; sw_th_token_cancel bumps the generation, and a task whose generation went stale
 * is skipped (not run), counted, and still completes its group.
 *
 * Accounting (for the profile): every task names a kind (what the renderer submits: hierarchy
 * builds, refinements, static-LOD clustering, builds and retirement, scene compiles). Each worker
 * counts the tasks of each kind it ran and, when timing is on (the desc's time_tasks or
 * sw_th_pool_set_task_timing: two CLOCK_MONOTONIC reads per task, measurable on tasks of ~0.1 us,
 * bench/steal --timing), the time it spent in them; single-writer counters, summed by any thread
 * like the other statistics. sw_th_pool_queued counts the tasks waiting, and
 * sw_th_pool_inject_peak_take the longest the injection queues grew.
 */
#ifndef SPLINEWALK_SW_TH_POOL_H
#define SPLINEWALK_SW_TH_POOL_H

#include <splinewalk/sw_result.h>

#include <stdatomic.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_th_pool sw_th_pool;

typedef enum sw_th_priority {
    SW_TH_PRIORITY_FRAME = 0,      /* needed by the frame being built: runs first (the default) */
    SW_TH_PRIORITY_BACKGROUND = 1, /* prefetch, refinement nobody waits for */
    SW_TH_PRIORITY_COUNT
} sw_th_priority;

typedef enum sw_th_steal_mode {
    SW_TH_STEAL_MODE_DEFAULT = 0, /* → SW_TH_STEAL_MODE_HALF */
    SW_TH_STEAL_MODE_ONE,         /* a thief takes the victim's oldest task */
    SW_TH_STEAL_MODE_HALF         /* a thief takes half of the victim's tasks (Kumar §5.1) */
} sw_th_steal_mode;

/* A request's cancellation token. Zero-initialise (or sw_th_token_init). */
typedef struct sw_th_token {
    _Atomic uint64_t generation;
} sw_th_token;

/* Outstanding-task count of a set of tasks. Zero-initialise (or sw_th_group_init). Must outlive
 * sw_th_group_wait and every task submitted with it. */
typedef struct sw_th_group {
    _Atomic int64_t pending;
} sw_th_group;

typedef void (*sw_th_task_fn)(void *ctx);

/* What a task does, for the pool's per-kind accounting only (scheduling ignores it). The layers
 * that submit tasks register their kinds by name (sw_th_task_kind_register: the hierarchy cache
 * its builds and refinements, the static set its builds, the frame its chunks...); the pool
 * knows none of them. 0, "other", is the default. */
typedef uint32_t sw_th_task_kind;
enum { SW_TH_TASK_OTHER = 0, SW_TH_TASK_KIND_MAX = 16 };

/* Copied at submission. Zero means default for every field but fn. */
typedef struct sw_th_task {
    sw_th_task_fn fn;        /* required */
    void *ctx;               /* passed to fn; may be NULL */
    sw_th_priority priority; /* 0 = FRAME */
    sw_th_token *token;      /* NULL: never stale. Else must outlive the task */
    uint64_t generation;     /* the token generation the task belongs to (sw_th_token_current) */
    sw_th_group *group;      /* NULL: none. Counted at submission, released after fn */
    sw_th_task_kind kind;    /* 0 = OTHER; accounting only */
} sw_th_task;

typedef struct sw_th_pool_desc {
    uint32_t worker_count;       /* 0: the number of online processors */
    sw_th_steal_mode steal_mode; /* 0: SW_TH_STEAL_MODE_HALF */
    uint32_t spin_rounds;        /* failed searches before sleeping; 0: 64 */
    uint32_t deque_capacity;     /* initial slots per deque; 0: 256 */
    uint32_t seed;               /* victim selection; 0: 1 */
    uint32_t time_tasks;         /* 1: time every task (sw_th_pool_stats.ns_by_kind); 0: off */
} sw_th_pool_desc;

typedef struct sw_th_pool_stats {
    uint64_t executed;     /* tasks whose fn ran */
    uint64_t cancelled;    /* tasks skipped because their token went stale */
    uint64_t steals;       /* successful steal operations (one or a batch) */
    uint64_t stolen_tasks; /* tasks moved by them */
    uint64_t sleeps;       /* times a worker blocked for lack of work */
    uint64_t executed_by_kind[SW_TH_TASK_KIND_MAX]; /* of executed, by sw_th_task.kind */
    /* Time in the tasks of each kind while timing was on, ns: a task's own time, without that of
     * the tasks it ran nested (in sw_th_group_wait), so the kinds add up to the busy time. A
     * worker's running task counts up to the call (each sample is, up to a store buffer's delay,
     * at least the one before); a thread outside the pool that runs tasks while waiting on a
     * group adds its time when each of its task segments ends. */
    uint64_t ns_by_kind[SW_TH_TASK_KIND_MAX];
} sw_th_pool_stats;

/* Token. cancel makes every task of the older generations stale; returns the new generation. */
SW_API void sw_th_token_init(sw_th_token *token);
SW_API uint64_t sw_th_token_current(sw_th_token *token);
SW_API uint64_t sw_th_token_cancel(sw_th_token *token);

SW_API void sw_th_group_init(sw_th_group *group);
/* Pending tasks of the group (a snapshot). */
SW_API int64_t sw_th_group_pending(sw_th_group *group);

/* Fills *out from *in (in may be NULL) with every zero field replaced by its default. */
SW_API void sw_th_pool_desc_defaults(sw_th_pool_desc *out, const sw_th_pool_desc *in);
/* desc may be NULL. SW_OK; SW_ERR_INVALID_ARGUMENT (worker_count > 1024 or bad steal_mode);
 * SW_ERR_OUT_OF_MEMORY; SW_ERR_INTERNAL when a thread could not be started. *out is NULL on
 * failure. */
SW_API sw_result sw_th_pool_create(const sw_th_pool_desc *desc, sw_th_pool **out);
/* Runs every task submitted so far (and everything they spawn), then joins the workers and
 * frees the pool. No thread may submit concurrently except the pool's own tasks. NULL is a
 * no-op. */
SW_API void sw_th_pool_destroy(sw_th_pool *pool);

/* Any thread, including the pool's tasks (their children go to the running worker's own deque,
 * lock-free; other threads go through the injection queue, also lock-free). task->fn required.
 * SW_OK or SW_ERR_OUT_OF_MEMORY (the task is then not submitted and its group not counted). */
SW_API sw_result sw_th_pool_submit(sw_th_pool *pool, const sw_th_task *task);

/* Returns when the group has no pending task. The caller runs pool tasks meanwhile (any task,
 * not only the group's) and blocks only when it finds none. Callable from a task (fork-join).
 * A call that finds tasks pending is one wait of the calling thread (sw_th_thread_waits). */
SW_API void sw_th_group_wait(sw_th_pool *pool, sw_th_group *group);

/* The calling thread's waits for pool work (a walkthrough frame must never wait, and its stats
 * must be able to say so when it does). A wait is an outermost sw_th_group_wait that
 * found tasks pending, or an outermost sw_th_wait_begin / sw_th_wait_end bracket; waits nested
 * inside a wait (a task run meanwhile that waits itself) are part of it. ns: the wall time inside
 * them. Counters of the calling thread only, since it started: a frame takes the difference of
 * two readings on each thread it runs on. Lock-free, wait-free. */
typedef struct sw_th_wait_count {
    uint64_t waits;
    uint64_t ns;
} sw_th_wait_count;
SW_API sw_th_wait_count sw_th_thread_waits(void);
/* Brackets a wait of the calling thread for pool work that is not a group wait: a condition
 * variable a task signals, a spin on a result a task publishes. Pairs nest. */
SW_API void sw_th_wait_begin(void);
SW_API void sw_th_wait_end(void);

SW_API uint32_t sw_th_pool_worker_count(const sw_th_pool *pool);
/* Index of the calling thread among the pool's workers, or -1 for any other thread. */
SW_API int sw_th_pool_current_worker(const sw_th_pool *pool);
/* Sums of the workers' counters; approximate while tasks run, exact once the pool is idle. */
SW_API void sw_th_pool_stats_get(sw_th_pool *pool, sw_th_pool_stats *out);
/* Any thread: times the tasks that start from now on (on = 1) or stops timing them (0). */
SW_API void sw_th_pool_set_task_timing(sw_th_pool *pool, int on);
/* Any thread: tasks submitted and not yet taken to run (the injection queues and every worker's
 * deques), in total and per priority into by_priority (may be NULL). A snapshot of counters
 * read one after the other: approximate while tasks move, exact when the pool is quiescent. */
SW_API int64_t sw_th_pool_queued(sw_th_pool *pool, int64_t by_priority[SW_TH_PRIORITY_COUNT]);
/* Any thread: the longest an injection queue (tasks submitted from outside the pool, one queue
 * per priority) grew by a submission since the previous call (or the pool's creation); resets
 * it. A backlog the end-of-frame snapshot of sw_th_pool_queued misses when the workers catch up
 * within the frame. */
SW_API int64_t sw_th_pool_inject_peak_take(sw_th_pool *pool);
/* Registers a task kind under `name` (a string of static lifetime; what the kind's tasks do is
 * said where the name is shown, e.g. the profile's columns); returns its value. A name registered
 * before gets its value again; when all SW_TH_TASK_KIND_MAX values are taken, SW_TH_TASK_OTHER.
 * Any thread; takes a lock: register once (e.g. through a slot below), not per task. */
SW_API sw_th_task_kind sw_th_task_kind_register(const char *name);
/* A kind registered on its first use, for a layer's static table:
 *   static sw_th_task_kind_slot k_build = SW_TH_TASK_KIND_SLOT("static_build");
 *   task.kind = sw_th_task_kind_of(&k_build);
 * The first call registers (a lock, once: two threads racing register the same name and get the
 * same value); later calls are one atomic load. */
typedef struct sw_th_task_kind_slot {
    const char *name;
    _Atomic uint32_t value; /* the kind + 1; 0 until registered */
} sw_th_task_kind_slot;
#define SW_TH_TASK_KIND_SLOT(name)                                                                 \
    {                                                                                              \
        (name), 0                                                                                  \
    }
SW_API sw_th_task_kind sw_th_task_kind_of(sw_th_task_kind_slot *slot);
/* Kinds registered so far (values 0 .. count - 1; "other" is always there). */
SW_API uint32_t sw_th_task_kind_count(void);
/* The registered name of a kind; "?" for a value not registered. */
SW_API const char *sw_th_task_kind_name(sw_th_task_kind kind);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* Frame buffers kept between frames. A frame's plan (visible occurrences, hierarchy choices,
 * geometry: grids, borders, draws, patch records) and its tessellation chunks' geometries are
 * megabytes of arrays grown by doubling. Freed after every frame, they came back from the kernel
 * as fresh pages the next frame and were grown again by realloc copies: on a 50k-face assembly
 * those page faults and copies took ~12 % and ~7 % of the process's CPU samples. A spent plan or
 * chunk geometry is therefore emptied (counts zeroed, arrays kept) and stashed in its context; the
 * next frame starts from it.
 *
 * A few atomic slots per role: putting and taking never block, so a plan may be recycled on any
 * thread (the preparing thread, or the one that submitted it). An item put into a full stash is
 * left to its owner to free. What is kept is bounded by the slots times the largest frame seen
 * (capacity is not trimmed). */
#include "frame_stages.h"
#include "sw_hooks.h"

#include <stdatomic.h>

enum {
    PLAN_SLOTS = 4,   /* the plan being prepared, the one being drawn, the spent one, slack */
    CHUNK_SLOTS = 64, /* CHUNKS_PER_THREAD x 16 threads */
};

struct sw__gpu_stash {
    _Atomic(void *) plan[PLAN_SLOTS];
    _Atomic(void *) chunk[CHUNK_SLOTS];
};

struct sw__gpu_stash *sw__gpu_stash_new(void)
{
    struct sw__gpu_stash *s = sw__malloc(sizeof *s);
    if (!s)
        return NULL;
    for (size_t i = 0; i < PLAN_SLOTS; ++i)
        atomic_init(&s->plan[i], NULL);
    for (size_t i = 0; i < CHUNK_SLOTS; ++i)
        atomic_init(&s->chunk[i], NULL);
    return s;
}

static _Atomic(void *) *role_slots(struct sw__gpu_stash *s, sw__gpu_stash_role role, size_t *n)
{
    *n = role == SW__GPU_STASH_PLAN ? PLAN_SLOTS : CHUNK_SLOTS;
    return role == SW__GPU_STASH_PLAN ? s->plan : s->chunk;
}

void *sw__gpu_stash_take(sw_gpu_context *ctx, sw__gpu_stash_role role)
{
    if (!ctx || !ctx->stash)
        return NULL;
    size_t n;
    _Atomic(void *) *slot = role_slots(ctx->stash, role, &n);
    for (size_t i = 0; i < n; ++i) {
        void *item = atomic_exchange_explicit(&slot[i], NULL, memory_order_acquire);
        if (item)
            return item;
    }
    return NULL;
}

int sw__gpu_stash_put(sw_gpu_context *ctx, sw__gpu_stash_role role, void *item)
{
    if (!ctx || !ctx->stash)
        return 0;
    size_t n;
    _Atomic(void *) *slot = role_slots(ctx->stash, role, &n);
    for (size_t i = 0; i < n; ++i) {
        void *empty = NULL;
        if (atomic_compare_exchange_strong_explicit(&slot[i], &empty, item, memory_order_release,
                                                    memory_order_relaxed))
            return 1;
    }
    return 0;
}

void sw__gpu_stash_free(struct sw__gpu_stash *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < PLAN_SLOTS; ++i)
        sw_gpu_frame_plan_free(atomic_load_explicit(&s->plan[i], memory_order_acquire));
    for (size_t i = 0; i < CHUNK_SLOTS; ++i) {
        sw__fr_geometry *g = atomic_load_explicit(&s->chunk[i], memory_order_acquire);
        if (g) {
            sw__fr_geometry_free(g);
            sw__free(g);
        }
    }
    sw__free(s);
}

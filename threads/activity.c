/* SPDX-License-Identifier: MIT */
/* Activity lists (Kumar et al. 1997 §5.2, §5.3); the contract is in sw_th_activity.h.
 *
 * The ring is Lamport's SPSC queue in C11: the producer writes a slot, then publishes it by
 * storing `tail`; the consumer reads `tail` (acquire) before the slot, and frees the slot by
 * storing `head` after reading it. Each side caches the other's index and reloads it only when
 * the cache says empty (full), so a burst costs one shared load.
 *
 * Sleeping (Kumar's P busy-waits; ours sleeps). A consumer that finds the ring empty takes
 * `lock`, announces itself with a seq_cst exchange on `consumer_sleeps`, re-reads `tail` (seq_cst)
 * and waits on `cond` only if the ring is still empty. A producer stores `tail` (seq_cst) and then
 * reads `consumer_sleeps` (seq_cst): in the single total order of seq_cst operations either the
 * consumer's re-read sees the new tail, or the producer sees the announcement and signals under
 * `lock` — which it can only take once the consumer is inside pthread_cond_wait, so no wake-up is
 * lost. The full-ring case is the mirror image (`producer_sleeps`, `head`). Both sides cannot
 * sleep at once (that needs a ring both empty and full), so they share one condition variable.
 * seq_cst read-modify-writes instead of stand-alone fences: ThreadSanitizer does not model
 * atomic_thread_fence (PLATFORM.md). No lock is taken by a push or pop that does not wait, and a
 * push takes one only when the consumer is asleep.
 */
#include "sw_th_activity.h"
#include "sw_hooks.h"

#include <assert.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

sw_result sw_th_spsc_init(sw_th_spsc *q, uint32_t capacity)
{
    memset(q, 0, sizeof *q);
    uint64_t cap = 1;
    while (cap < (capacity ? capacity : 1024u))
        cap <<= 1;
    q->slots = sw__calloc(cap, sizeof *q->slots);
    if (!q->slots)
        return SW_ERR_OUT_OF_MEMORY;
    q->mask = cap - 1;
    pthread_mutex_init(&q->lock, NULL);
    pthread_cond_init(&q->cond, NULL);
    return SW_OK;
}

void sw_th_spsc_destroy(sw_th_spsc *q)
{
    if (!q->slots)
        return;
    pthread_mutex_destroy(&q->lock);
    pthread_cond_destroy(&q->cond);
    sw__free(q->slots);
    q->slots = NULL;
}

/* The waking half of the Dekker pair: `side` is the other thread's announcement flag. */
static void wake_if_asleep(sw_th_spsc *q, _Atomic int *side)
{
    if (!atomic_load_explicit(side, memory_order_seq_cst))
        return;
    pthread_mutex_lock(&q->lock); /* the sleeper holds it from its re-check until it waits */
    pthread_cond_broadcast(&q->cond);
    pthread_mutex_unlock(&q->lock);
}

static bool ring_full(sw_th_spsc *q, uint64_t t)
{
    return t - atomic_load_explicit(&q->head, memory_order_seq_cst) > q->mask;
}

static void wait_not_full(sw_th_spsc *q, uint64_t t)
{
    pthread_mutex_lock(&q->lock);
    atomic_exchange_explicit(&q->producer_sleeps, 1, memory_order_seq_cst);
    if (ring_full(q, t)) {
        atomic_fetch_add_explicit(&q->producer_waits, 1, memory_order_relaxed);
        do
            pthread_cond_wait(&q->cond, &q->lock);
        while (ring_full(q, t));
    }
    atomic_exchange_explicit(&q->producer_sleeps, 0, memory_order_seq_cst);
    pthread_mutex_unlock(&q->lock);
}

static void push(sw_th_spsc *q, void *item, uint64_t frame)
{
    /* relaxed: only this thread writes tail */
    uint64_t t = atomic_load_explicit(&q->tail, memory_order_relaxed);
    if (t - q->head_seen > q->mask) {
        /* acquire: pairs with the consumer's store of head; the slot it freed is then ours */
        q->head_seen = atomic_load_explicit(&q->head, memory_order_acquire);
        if (t - q->head_seen > q->mask) {
            wait_not_full(q, t);
            q->head_seen = atomic_load_explicit(&q->head, memory_order_acquire);
        }
    }
    q->slots[t & q->mask] = (sw_th__act_slot){.item = item, .frame = frame};
    /* seq_cst: publishes the slot (release) and is the producer's store of the Dekker pair */
    atomic_store_explicit(&q->tail, t + 1, memory_order_seq_cst);
    wake_if_asleep(q, &q->consumer_sleeps);
}

void sw_th_spsc_push_producer(sw_th_spsc *q, void *item)
{
    assert(item);
    push(q, item, 0);
}

void sw_th_spsc_end_frame_producer(sw_th_spsc *q, uint64_t frame)
{
    push(q, NULL, frame);
}

sw_th_act_status sw_th_spsc_try_pop_consumer(sw_th_spsc *q, void **item, uint64_t *frame)
{
    /* relaxed: only this thread writes head */
    uint64_t h = atomic_load_explicit(&q->head, memory_order_relaxed);
    if (h == q->tail_seen) {
        /* acquire: pairs with the producer's store of tail, so the slot's contents are visible */
        q->tail_seen = atomic_load_explicit(&q->tail, memory_order_acquire);
        if (h == q->tail_seen)
            return SW_TH_ACT_NOT_YET;
    }
    sw_th__act_slot s = q->slots[h & q->mask];
    /* seq_cst: hands the slot back (release) and is the consumer's store of the Dekker pair */
    atomic_store_explicit(&q->head, h + 1, memory_order_seq_cst);
    wake_if_asleep(q, &q->producer_sleeps);
    if (!s.item) {
        *frame = s.frame;
        return SW_TH_ACT_FRAME_DONE;
    }
    *item = s.item;
    return SW_TH_ACT_ITEM;
}

static bool ring_empty(sw_th_spsc *q, uint64_t h)
{
    return atomic_load_explicit(&q->tail, memory_order_seq_cst) == h;
}

static void wait_not_empty(sw_th_spsc *q)
{
    uint64_t h = atomic_load_explicit(&q->head, memory_order_relaxed);
    pthread_mutex_lock(&q->lock);
    atomic_exchange_explicit(&q->consumer_sleeps, 1, memory_order_seq_cst);
    if (ring_empty(q, h)) {
        atomic_fetch_add_explicit(&q->consumer_waits, 1, memory_order_relaxed);
        do
            pthread_cond_wait(&q->cond, &q->lock);
        while (ring_empty(q, h));
    }
    atomic_exchange_explicit(&q->consumer_sleeps, 0, memory_order_seq_cst);
    pthread_mutex_unlock(&q->lock);
}

sw_th_act_status sw_th_spsc_pop_wait_consumer(sw_th_spsc *q, void **item, uint64_t *frame)
{
    for (;;) {
        sw_th_act_status s = sw_th_spsc_try_pop_consumer(q, item, frame);
        if (s != SW_TH_ACT_NOT_YET)
            return s;
        wait_not_empty(q);
    }
}

uint64_t sw_th_spsc_consumer_waits(sw_th_spsc *q)
{
    return atomic_load_explicit(&q->consumer_waits, memory_order_relaxed);
}

uint64_t sw_th_spsc_producer_waits(sw_th_spsc *q)
{
    return atomic_load_explicit(&q->producer_waits, memory_order_relaxed);
}

/* ---- N_p × N_c (§5.3) --------------------------------------------------------------------------
 */

typedef struct act_list {
    sw_th_spsc q;
    /* Dummy lists only (index >= n_consumers): the frame a consumer has claimed the list for
     * (CAS) and the last frame whose marker its consumer has taken (release store). A list is
     * claimable for frame f once done == f - 1, so its consumer changes only after the previous
     * one let go: that acquire/release pair is the happens-before edge the SPSC contract needs. */
    alignas(SW_TH_CACHE_LINE) _Atomic uint64_t claimed, done;
} act_list;

typedef struct act_producer {
    uint32_t next; /* round-robin position among its lists (producer only) */
} act_producer;

typedef struct act_consumer {
    uint64_t frame;  /* the frame being drained */
    int32_t current; /* list being drained, -1 = own list finished, look for dummies */
} act_consumer;

struct sw_th_activity_set {
    uint32_t n_producers, n_consumers, n_lists;
    act_list *lists;
    act_producer *producers;
    act_consumer *consumers;
};

sw_result sw_th_activity_set_create(uint32_t n_producers, uint32_t n_consumers, uint32_t capacity,
                                    sw_th_activity_set **out)
{
    *out = NULL;
    if (n_producers < 1 || n_producers > 64 || n_consumers < 1 || n_consumers > 64)
        return SW_ERR_INVALID_ARGUMENT;
    sw_th_activity_set *set = sw__calloc(1, sizeof *set);
    if (!set)
        return SW_ERR_OUT_OF_MEMORY;
    set->n_producers = n_producers;
    set->n_consumers = n_consumers;
    set->n_lists = n_producers > n_consumers ? n_producers : n_consumers;
    set->lists = sw__aligned_alloc(SW_TH_CACHE_LINE, set->n_lists * sizeof *set->lists);
    set->producers = sw__calloc(n_producers, sizeof *set->producers);
    set->consumers = sw__calloc(n_consumers, sizeof *set->consumers);
    if (!set->lists || !set->producers || !set->consumers) {
        sw__aligned_free(set->lists);
        set->lists = NULL;
        sw_th_activity_set_destroy(set);
        return SW_ERR_OUT_OF_MEMORY;
    }
    memset(set->lists, 0, set->n_lists * sizeof *set->lists);
    for (uint32_t i = 0; i < set->n_lists; ++i) {
        if (sw_th_spsc_init(&set->lists[i].q, capacity) != SW_OK) {
            sw_th_activity_set_destroy(set);
            return SW_ERR_OUT_OF_MEMORY;
        }
    }
    *out = set;
    return SW_OK;
}

void sw_th_activity_set_destroy(sw_th_activity_set *set)
{
    if (!set)
        return;
    for (uint32_t i = 0; set->lists && i < set->n_lists; ++i)
        sw_th_spsc_destroy(&set->lists[i].q);
    sw__aligned_free(set->lists);
    sw__free(set->producers);
    sw__free(set->consumers);
    sw__free(set);
}

/* The lists producer p owns: p, p + N_p, p + 2 N_p, ... below n_lists (just p when N_p >= N_c). */
static uint32_t producer_list_count(const sw_th_activity_set *set, uint32_t p)
{
    return (set->n_lists - p + set->n_producers - 1) / set->n_producers;
}

void sw_th_activity_push_producer(sw_th_activity_set *set, uint32_t p, void *item)
{
    assert(p < set->n_producers);
    act_producer *pr = &set->producers[p];
    uint32_t list = p + pr->next * set->n_producers;
    if (++pr->next == producer_list_count(set, p))
        pr->next = 0;
    sw_th_spsc_push_producer(&set->lists[list].q, item);
}

void sw_th_activity_end_frame_producer(sw_th_activity_set *set, uint32_t p, uint64_t frame)
{
    assert(p < set->n_producers && frame > 0);
    for (uint32_t list = p; list < set->n_lists; list += set->n_producers)
        sw_th_spsc_end_frame_producer(&set->lists[list].q, frame);
}

/* A dummy list nobody drains for `frame` yet, claimed; -1 when none is left to claim (every one
 * is claimed for the frame, or still drained for an earlier frame by a consumer that is behind
 * and will claim it for this frame when it gets there). */
static int32_t claim_dummy(sw_th_activity_set *set, uint64_t frame)
{
    for (uint32_t i = set->n_consumers; i < set->n_lists; ++i) {
        act_list *l = &set->lists[i];
        uint64_t expected = frame - 1;
        /* acquire: pairs with the previous consumer's release of `done` */
        if (atomic_load_explicit(&l->done, memory_order_acquire) != frame - 1)
            continue;
        if (atomic_compare_exchange_strong_explicit(&l->claimed, &expected, frame,
                                                    memory_order_acq_rel, memory_order_relaxed))
            return (int32_t)i;
    }
    return -1;
}

sw_th_act_status sw_th_activity_pop_consumer(sw_th_activity_set *set, uint32_t c, uint64_t frame,
                                             void **item)
{
    assert(c < set->n_consumers && frame > 0);
    act_consumer *cs = &set->consumers[c];
    if (cs->frame != frame) {
        cs->frame = frame;
        cs->current = (int32_t)c;
    }
    for (;;) {
        if (cs->current < 0 && (cs->current = claim_dummy(set, frame)) < 0)
            return SW_TH_ACT_FRAME_DONE;
        act_list *l = &set->lists[cs->current];
        uint64_t marker = 0;
        if (sw_th_spsc_pop_wait_consumer(&l->q, item, &marker) == SW_TH_ACT_ITEM)
            return SW_TH_ACT_ITEM;
        assert(marker == frame); /* each list delivers its frames' markers in order */
        if ((uint32_t)cs->current >= set->n_consumers)
            atomic_store_explicit(&l->done, frame, memory_order_release); /* see act_list */
        cs->current = -1;
    }
}

/* SPDX-License-Identifier: MIT */
/* Chase-Lev work-stealing deque (Lê, Pop, Cohen, Zappa Nardelli, PPoPP 2013, Fig. 1).
 *
 * The paper's take() writes bottom, then a seq_cst fence, then reads top; its steal() reads top,
 * a seq_cst fence, then bottom. Here the fences are folded into the accesses themselves: pop
 * writes bottom with a seq_cst exchange and reads top seq_cst; steal reads top and bottom seq_cst.
 * All writes of `top` are seq_cst CASes, so for the Dekker-style race on the last item the single
 * total order S of seq_cst operations gives what the fences gave: if pop's read of top precedes a
 * thief's CAS in S, pop's write of bottom precedes the thief's read of bottom in S, and the thief
 * sees the shrunken deque (or the owner sees top == bottom and races with a CAS of its own).
 * ThreadSanitizer checks this form; it does not model stand-alone fences.
 *
 * No lock anywhere (tests/threads checks this object file's symbols with nm).
 */
#include "sw_th_deque.h"
#include "sw_hooks.h"

#include <assert.h>
#include <stdlib.h>

static sw_th__deque_ring *ring_alloc(int64_t capacity)
{
    sw_th__deque_ring *r =
        sw__malloc(sizeof(sw_th__deque_ring) + (size_t)capacity * sizeof(_Atomic(void *)));
    if (!r)
        return NULL;
    r->mask = capacity - 1;
    r->retired_next = NULL;
    for (int64_t i = 0; i < capacity; i++)
        atomic_init(&r->slots[i], NULL);
    return r;
}

sw_result sw_th_deque_init_owner(sw_th_deque *q, size_t capacity)
{
    int64_t cap = 64;
    if (capacity) {
        cap = 2;
        while ((size_t)cap < capacity && cap < ((int64_t)1 << 40))
            cap <<= 1;
    }
    atomic_init(&q->top, 0);
    atomic_init(&q->bottom, 0);
    q->retired = NULL;
    q->grow_count = 0;
    sw_th__deque_ring *r = ring_alloc(cap);
    atomic_init(&q->ring, r);
    return r ? SW_OK : SW_ERR_OUT_OF_MEMORY;
}

void sw_th_deque_destroy_owner(sw_th_deque *q)
{
    sw__free(atomic_load_explicit(&q->ring, memory_order_relaxed));
    atomic_store_explicit(&q->ring, NULL, memory_order_relaxed);
    while (q->retired) {
        sw_th__deque_ring *next = q->retired->retired_next;
        sw__free(q->retired);
        q->retired = next;
    }
}

/* Owner only. Copies the live range [t, b) into a ring twice as large and publishes it; the old
 * ring stays readable for thieves that already loaded it (retired, freed at destroy). */
static sw_th__deque_ring *grow(sw_th_deque *q, sw_th__deque_ring *old, int64_t t, int64_t b)
{
    sw_th__deque_ring *r = ring_alloc((old->mask + 1) * 2);
    if (!r)
        return NULL;
    /* relaxed: only the owner writes slots; the new ring is published by the release below. */
    for (int64_t i = t; i < b; i++) {
        void *x = atomic_load_explicit(&old->slots[i & old->mask], memory_order_relaxed);
        atomic_store_explicit(&r->slots[i & r->mask], x, memory_order_relaxed);
    }
    /* release: pairs with the acquire load of `ring` in steal, so a thief that sees the new ring
     * also sees the copied slots. */
    atomic_store_explicit(&q->ring, r, memory_order_release);
    old->retired_next = q->retired;
    q->retired = old;
    q->grow_count++;
    return r;
}

sw_result sw_th_deque_push_owner(sw_th_deque *q, void *item)
{
    assert(item);
    /* relaxed: only the owner writes bottom and ring. */
    int64_t b = atomic_load_explicit(&q->bottom, memory_order_relaxed);
    /* acquire: pairs with the thieves' successful CAS on top, so their reads of the slots we may
     * now overwrite happened before our writes. */
    int64_t t = atomic_load_explicit(&q->top, memory_order_acquire);
    sw_th__deque_ring *r = atomic_load_explicit(&q->ring, memory_order_relaxed);
    if (b - t > r->mask) {
        r = grow(q, r, t, b);
        if (!r)
            return SW_ERR_OUT_OF_MEMORY;
    }
    /* relaxed: published by the store of bottom below. */
    atomic_store_explicit(&r->slots[b & r->mask], item, memory_order_relaxed);
    /* seq_cst (a release is what the paper needs): it publishes the slot and the item's contents
     * to thieves, pairing with their seq_cst (acquiring) load of bottom. seq_cst also orders it
     * before the pool's seq_cst read of its sleeper count (pool.c, wake-up protocol). */
    atomic_store_explicit(&q->bottom, b + 1, memory_order_seq_cst);
    return SW_OK;
}

void *sw_th_deque_pop_owner(sw_th_deque *q)
{
    /* relaxed: bottom and ring are written by the owner only. */
    int64_t b = atomic_load_explicit(&q->bottom, memory_order_relaxed) - 1;
    sw_th__deque_ring *r = atomic_load_explicit(&q->ring, memory_order_relaxed);
    /* seq_cst exchange = the paper's relaxed store + seq_cst fence: it must precede our read of
     * top in S (pairs with the seq_cst loads of top/bottom in steal). */
    atomic_exchange_explicit(&q->bottom, b, memory_order_seq_cst);
    int64_t t = atomic_load_explicit(&q->top, memory_order_seq_cst);
    void *x = NULL;
    if (t <= b) {
        /* relaxed: the owner wrote this slot itself. */
        x = atomic_load_explicit(&r->slots[b & r->mask], memory_order_relaxed);
        if (t == b) {
            /* The last item: race the thieves for it on top (seq_cst, like their CAS). */
            if (!atomic_compare_exchange_strong_explicit(&q->top, &t, t + 1, memory_order_seq_cst,
                                                         memory_order_relaxed))
                x = NULL;
            /* release: a thief acquiring this bottom also sees everything pushed before. */
            atomic_store_explicit(&q->bottom, b + 1, memory_order_release);
        }
    } else {
        /* Empty: undo the decrement (release, as above). */
        atomic_store_explicit(&q->bottom, b + 1, memory_order_release);
    }
    return x;
}

sw_th_steal_result sw_th_deque_steal(sw_th_deque *q, void **out)
{
    /* seq_cst loads of top then bottom: the paper's acquire load, seq_cst fence, acquire load.
     * The load of bottom acquires from the owner's store in push, so the slot and the item's
     * contents written before it are visible. */
    int64_t t = atomic_load_explicit(&q->top, memory_order_seq_cst);
    int64_t b = atomic_load_explicit(&q->bottom, memory_order_seq_cst);
    if (t >= b)
        return SW_TH_STEAL_EMPTY;
    /* acquire (the paper's consume): pairs with the release store in grow. The ring read may be
     * an older, retired one; it still holds item t (see grow). */
    sw_th__deque_ring *r = atomic_load_explicit(&q->ring, memory_order_acquire);
    /* relaxed: ordered after the acquiring loads above; only a successful CAS keeps x. */
    void *x = atomic_load_explicit(&r->slots[t & r->mask], memory_order_relaxed);
    /* seq_cst CAS: claims item t against other thieves and against pop's CAS on the last item;
     * its release half pairs with push's acquire load of top (slot reuse). */
    if (!atomic_compare_exchange_strong_explicit(&q->top, &t, t + 1, memory_order_seq_cst,
                                                 memory_order_relaxed))
        return SW_TH_STEAL_RETRY;
    *out = x;
    return SW_TH_STEAL_OK;
}

int64_t sw_th_deque_size_estimate(sw_th_deque *q)
{
    /* seq_cst: the pool's sleep protocol needs these reads in S after its sleeper-count RMW. */
    int64_t t = atomic_load_explicit(&q->top, memory_order_seq_cst);
    int64_t b = atomic_load_explicit(&q->bottom, memory_order_seq_cst);
    return b > t ? b - t : 0;
}

size_t sw_th_deque_capacity_owner(const sw_th_deque *q)
{
    sw_th__deque_ring *r = atomic_load_explicit(&q->ring, memory_order_relaxed);
    return r ? (size_t)(r->mask + 1) : 0;
}

uint32_t sw_th_deque_grow_count_owner(const sw_th_deque *q)
{
    return q->grow_count;
}

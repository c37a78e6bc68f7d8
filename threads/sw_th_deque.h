/* SPDX-License-Identifier: MIT */
/* splinewalk threads — Chase-Lev work-stealing deque of pointers.
 *
 * Algorithm: Chase & Lev, "Dynamic circular work-stealing deque" (SPAA 2005), in the C11 form of
 * Lê, Pop, Cohen, Zappa Nardelli, "Correct and efficient work-stealing for weak memory models"
 * (PPoPP 2013, Fig. 1). Deviation from their figure: the two stand-alone seq_cst fences are
 * replaced by seq_cst accesses of `top` and `bottom` (an exchange in pop, seq_cst loads in steal),
 * because ThreadSanitizer does not model atomic_thread_fence; deque.c argues why this is enough.
 *
 * Contract (in the names, like GHC's rts/WSDeque.c):
 *  - *_owner calls are made by ONE thread only, the deque's owner (init and destroy too, with no
 *    thief running);
 *  - sw_th_deque_steal and sw_th_deque_size_estimate may be called by any thread at any time.
 * No call takes a lock. Items are non-NULL pointers; the deque never looks into them.
 *
 * Growth doubles the ring; the old ring is RETIRED (kept on an owner-private list) because a
 * thief that loaded the old array pointer may still read a slot from it. Retired rings are freed
 * by sw_th_deque_destroy, when no thief can run; growth doubles, so they total less than the
 * live ring.
 */
#ifndef SPLINEWALK_SW_TH_DEQUE_H
#define SPLINEWALK_SW_TH_DEQUE_H

#include <splinewalk/sw_result.h>

#include <stdalign.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_TH_CACHE_LINE 64

/* A ring of 2^k atomic slots; `retired_next` links the owner's retired rings. */
typedef struct sw_th__deque_ring {
    int64_t mask;
    struct sw_th__deque_ring *retired_next;
    _Atomic(void *) slots[];
} sw_th__deque_ring;

/* Fields are private. top and bottom sit on their own cache lines: thieves hammer `top` with
 * CAS while the owner writes `bottom` on every push and pop. */
typedef struct sw_th_deque {
    alignas(SW_TH_CACHE_LINE) _Atomic int64_t top;
    alignas(SW_TH_CACHE_LINE) _Atomic int64_t bottom;
    alignas(SW_TH_CACHE_LINE) _Atomic(sw_th__deque_ring *) ring;
    sw_th__deque_ring *retired; /* owner only */
    uint32_t grow_count;        /* owner only */
} sw_th_deque;

typedef enum sw_th_steal_result {
    SW_TH_STEAL_OK = 0, /* *out holds an item, now the thief's */
    SW_TH_STEAL_EMPTY,  /* the deque looked empty */
    SW_TH_STEAL_RETRY   /* lost a race with another thief or the owner; the deque may hold more */
} sw_th_steal_result;

/* Owner. capacity: initial slot count, rounded up to a power of two; 0 → 64.
 * Returns SW_OK or SW_ERR_OUT_OF_MEMORY (q is then left destroyed-safe). */
SW_API sw_result sw_th_deque_init_owner(sw_th_deque *q, size_t capacity);
/* Owner, with no thief running. Frees the ring and every retired ring; items are not touched. */
SW_API void sw_th_deque_destroy_owner(sw_th_deque *q);
/* Owner. item != NULL. SW_OK, or SW_ERR_OUT_OF_MEMORY when a full ring could not grow (the item
 * is then not pushed and the deque is unchanged). */
SW_API sw_result sw_th_deque_push_owner(sw_th_deque *q, void *item);
/* Owner. The most recently pushed item still present (LIFO), or NULL when empty. */
SW_API void *sw_th_deque_pop_owner(sw_th_deque *q);
/* Any thread. The oldest item (FIFO) into *out on SW_TH_STEAL_OK; *out untouched otherwise. */
SW_API sw_th_steal_result sw_th_deque_steal(sw_th_deque *q, void **out);
/* Any thread. Item count at some instant during the call (never negative); exact when quiescent. */
SW_API int64_t sw_th_deque_size_estimate(sw_th_deque *q);
/* Owner. Current ring capacity and how many times it grew (for tests and statistics). */
SW_API size_t sw_th_deque_capacity_owner(const sw_th_deque *q);
SW_API uint32_t sw_th_deque_grow_count_owner(const sw_th_deque *q);

#ifdef __cplusplus
}
#endif
#endif

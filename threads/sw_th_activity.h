/* SPDX-License-Identifier: MIT */
/* splinewalk threads — activity lists: the queues from the visibility thread V to the submission
 * thread P (Kumar et al. 1997 §5.2), and their N_p × N_c generalization (§5.3).
 *
 * An activity list is a bounded single-producer single-consumer ring of non-NULL pointers (the
 * visible nodes of a frame) with Kumar's two end markers: a pop that finds the ring empty answers
 * SW_TH_ACT_NOT_YET ("all produced so far are consumed, V is still traversing": Kumar's NULL), and
 * the producer's sw_th_spsc_end_frame_producer appends a frame-done marker (Kumar's NIL) that the
 * consumer receives as SW_TH_ACT_FRAME_DONE with the frame's number, in order after the frame's
 * items. Frames overlap: V may push frame i+1 while P still drains frame i.
 *
 * Kumar's P busy-waits on NULL; here a waiting thread sleeps (the cores belong to llvmpipe's
 * raster threads), with no lock on the path of a push or pop that does not wait: see activity.c
 * for the sleep protocol. The same holds for a producer that finds the ring full.
 *
 * Contract (in the names): *_producer calls by ONE thread, *_consumer calls by ONE thread (they
 * may differ, and may change between frames only through a happens-before edge, e.g. a claim in
 * sw_th_activity_set). init/destroy with neither running.
 */
#ifndef SPLINEWALK_SW_TH_ACTIVITY_H
#define SPLINEWALK_SW_TH_ACTIVITY_H

#include "sw_th_deque.h" /* SW_TH_CACHE_LINE */

#include <pthread.h>
#include <splinewalk/sw_result.h>
#include <stdalign.h>
#include <stdatomic.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sw_th_act_status {
    SW_TH_ACT_ITEM = 0,   /* *item holds the next item */
    SW_TH_ACT_NOT_YET,    /* empty for now: the producer has not ended the frame (Kumar's NULL) */
    SW_TH_ACT_FRAME_DONE, /* the frame-done marker (Kumar's NIL); *frame holds its number */
} sw_th_act_status;

typedef struct sw_th__act_slot {
    void *item; /* NULL: the frame-done marker of `frame` */
    uint64_t frame;
} sw_th__act_slot;

/* Fields are private. head is written by the consumer only, tail by the producer only; each one
 * keeps a private copy of the other's index so that a run of pops (pushes) reads the shared
 * index only when the copy says empty (full). */
typedef struct sw_th_spsc {
    alignas(SW_TH_CACHE_LINE) _Atomic uint64_t head;
    uint64_t tail_seen; /* consumer only */
    alignas(SW_TH_CACHE_LINE) _Atomic uint64_t tail;
    uint64_t head_seen; /* producer only */
    alignas(SW_TH_CACHE_LINE) _Atomic int consumer_sleeps, producer_sleeps;
    uint64_t mask;
    sw_th__act_slot *slots;
    pthread_mutex_t lock; /* only around a sleep and its wake-up (activity.c) */
    pthread_cond_t cond;
    _Atomic uint64_t consumer_waits, producer_waits; /* sleeps, for profiles and tests */
} sw_th_spsc;

/* capacity: rounded up to a power of two; 0 → 1024. SW_OK or SW_ERR_OUT_OF_MEMORY (q is then
 * destroyed-safe). */
SW_API sw_result sw_th_spsc_init(sw_th_spsc *q, uint32_t capacity);
SW_API void sw_th_spsc_destroy(sw_th_spsc *q);

/* Producer. item != NULL. Sleeps while the ring is full. */
SW_API void sw_th_spsc_push_producer(sw_th_spsc *q, void *item);
/* Producer. Appends the frame-done marker of `frame`. Sleeps while the ring is full. */
SW_API void sw_th_spsc_end_frame_producer(sw_th_spsc *q, uint64_t frame);

/* Consumer. Never sleeps: ITEM (*item set), NOT_YET, or FRAME_DONE (*frame set). */
SW_API sw_th_act_status sw_th_spsc_try_pop_consumer(sw_th_spsc *q, void **item, uint64_t *frame);
/* Consumer. Sleeps while the ring is empty: ITEM or FRAME_DONE. */
SW_API sw_th_act_status sw_th_spsc_pop_wait_consumer(sw_th_spsc *q, void **item, uint64_t *frame);

/* Any thread. Times the consumer / producer slept (monotonic). */
SW_API uint64_t sw_th_spsc_consumer_waits(sw_th_spsc *q);
SW_API uint64_t sw_th_spsc_producer_waits(sw_th_spsc *q);

/* ---- N_p producers × N_c consumers (§5.3) ------------------------------------------------------
 * max(N_p, N_c) lists, each still SPSC. If N_c >= N_p, list c is consumer c's and the lists are
 * dealt to the producers round-robin (producer p owns lists p, p + N_p, p + 2 N_p, ...), each
 * producer pushing to its lists in turn. If N_p > N_c, list p is producer p's, lists [0, N_c) are
 * the consumers' own and the N_p − N_c others belong to "dummy consumers": a consumer that has
 * drained its own list for a frame claims a dummy list for that frame (one CAS) and drains it too
 * — the redistribution Kumar leaves to his load-balancing algorithm. A claim is per frame, so
 * every list has exactly one consumer per frame. */
typedef struct sw_th_activity_set sw_th_activity_set;

/* capacity per list as in sw_th_spsc_init. n_producers, n_consumers in [1, 64]. Errors:
 * SW_ERR_INVALID_ARGUMENT, SW_ERR_OUT_OF_MEMORY. */
SW_API sw_result sw_th_activity_set_create(uint32_t n_producers, uint32_t n_consumers,
                                           uint32_t capacity, sw_th_activity_set **out);
SW_API void sw_th_activity_set_destroy(sw_th_activity_set *set); /* NULL allowed */

/* Producer p only. item != NULL. */
SW_API void sw_th_activity_push_producer(sw_th_activity_set *set, uint32_t p, void *item);
/* Producer p only: ends frame `frame` on every list p owns. Frames are numbered from 1, in order.
 */
SW_API void sw_th_activity_end_frame_producer(sw_th_activity_set *set, uint32_t p, uint64_t frame);

/* Consumer c only, for frame `frame` (the consumer's frames in order from 1): the next item of the
 * frame (SW_TH_ACT_ITEM, sleeping while none is ready), or SW_TH_ACT_FRAME_DONE once every list it
 * drains for the frame has delivered the frame's marker. */
SW_API sw_th_act_status sw_th_activity_pop_consumer(sw_th_activity_set *set, uint32_t c,
                                                    uint64_t frame, void **item);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* tests/threads: activity lists (threads/sw_th_activity.h; Kumar et al. 1997 §5.2, §5.3).
 *
 *  1. Markers, single-threaded: an empty list answers NOT_YET, items come out FIFO, a frame's
 *     marker after its items, NOT_YET again after it.
 *  2. SPSC under load: a producer pushes FRAMES frames of random size through a ring of 8 slots
 *     (so it fills and the producer sleeps) and a consumer that sometimes dawdles (so it empties
 *     and the consumer sleeps); the consumer must see every item once, in push order, each
 *     before its frame's marker, the markers in order. Both sides must have slept (the test of
 *     the sleep protocol would be vacuous otherwise).
 *  3. N_p × N_c: every producer/consumer count pair of the given lists; every item (tagged with
 *     its producer, frame and sequence number) delivered exactly once, to a pop for its own frame,
 *     and per producer and list in push order.
 * A lost wake-up shows as a hang (ctest's timeout), a race under ThreadSanitizer.
 *
 * usage: test_th_activity ITEMS NP_LIST NC_LIST       e.g. 1000000 1,2,3,4 1,2,3,4
 */
#include "sw_th_activity.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_failures;
#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            if (g_failures++ < 10) {                                                               \
                fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                               \
                fprintf(stderr, __VA_ARGS__);                                                      \
                fputc('\n', stderr);                                                               \
            }                                                                                      \
        }                                                                                          \
    } while (0)

static uint64_t mix(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdu;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53u;
    return x ^ (x >> 33);
}

/* Items are encoded pointers (never dereferenced): 1 + the item's index. */
static void *as_item(uint64_t i)
{
    return (void *)(uintptr_t)(i + 1);
}
static uint64_t item_index(void *p)
{
    return (uint64_t)(uintptr_t)p - 1;
}

static void test_markers(void)
{
    sw_th_spsc q;
    CHECK(sw_th_spsc_init(&q, 4) == SW_OK, "init");
    void *item = NULL;
    uint64_t frame = 0;
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_NOT_YET, "empty");
    sw_th_spsc_push_producer(&q, as_item(7));
    sw_th_spsc_push_producer(&q, as_item(8));
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_ITEM && item_index(item) == 7,
          "first item");
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_ITEM && item_index(item) == 8,
          "second item");
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_NOT_YET, "frame not ended");
    sw_th_spsc_end_frame_producer(&q, 5);
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_FRAME_DONE && frame == 5,
          "marker of frame 5");
    CHECK(sw_th_spsc_try_pop_consumer(&q, &item, &frame) == SW_TH_ACT_NOT_YET, "after the marker");
    CHECK(sw_th_spsc_consumer_waits(&q) == 0 && sw_th_spsc_producer_waits(&q) == 0,
          "no sleep without a second thread");
    sw_th_spsc_destroy(&q);
}

/* ---- 2. one producer, one consumer ----------------------------------------------------------- */

typedef struct spsc_run {
    sw_th_spsc q;
    uint64_t items, frames;
} spsc_run;

static uint64_t frame_size(uint64_t items, uint64_t frames, uint64_t f)
{
    return f + 1 == frames ? 0 : mix(f) % (2 * items / frames + 1);
}

static void *spsc_producer(void *arg)
{
    spsc_run *r = arg;
    uint64_t next = 0;
    for (uint64_t f = 0; f < r->frames; ++f) {
        uint64_t n = f + 1 == r->frames ? r->items - next : frame_size(r->items, r->frames, f);
        for (uint64_t k = 0; k < n && next < r->items; ++k)
            sw_th_spsc_push_producer(&r->q, as_item(next++));
        sw_th_spsc_end_frame_producer(&r->q, f + 1);
    }
    return NULL;
}

static void dawdle(uint64_t h)
{
    if ((h & 1023) != 0)
        return;
    volatile uint64_t sink = 0;
    for (int i = 0; i < 20000; ++i)
        sink += (uint64_t)i;
}

static void test_spsc(uint64_t items)
{
    spsc_run r = {.items = items, .frames = items / 100 + 2};
    CHECK(sw_th_spsc_init(&r.q, 8) == SW_OK, "init");
    pthread_t producer;
    pthread_create(&producer, NULL, spsc_producer, &r);
    uint64_t expect = 0, frame_expected = 1, got = 0;
    for (;;) {
        void *item = NULL;
        uint64_t frame = 0;
        sw_th_act_status s = sw_th_spsc_pop_wait_consumer(&r.q, &item, &frame);
        if (s == SW_TH_ACT_ITEM) {
            CHECK(item_index(item) == expect, "item %" PRIu64 " where %" PRIu64 " was due",
                  item_index(item), expect);
            expect = item_index(item) + 1;
            ++got;
            dawdle(mix(got));
            continue;
        }
        CHECK(s == SW_TH_ACT_FRAME_DONE && frame == frame_expected,
              "marker %" PRIu64 " where %" PRIu64 " was due", frame, frame_expected);
        if (frame_expected++ == r.frames)
            break;
    }
    pthread_join(producer, NULL);
    uint64_t cw = sw_th_spsc_consumer_waits(&r.q), pw = sw_th_spsc_producer_waits(&r.q);
    CHECK(got == items, "%" PRIu64 " items of %" PRIu64, got, items);
    CHECK(cw > 0 && pw > 0, "both sides must have slept: consumer %" PRIu64 ", producer %" PRIu64,
          cw, pw);
    printf("spsc: %" PRIu64 " items in %" PRIu64 " frames through 8 slots, in order; consumer "
           "slept %" PRIu64 " times, producer %" PRIu64 "\n",
           got, r.frames, cw, pw);
    sw_th_spsc_destroy(&r.q);
}

/* ---- 3. N_p producers, N_c consumers --------------------------------------------------------- */

enum { FRAMES = 50 };

typedef struct set_run {
    sw_th_activity_set *set;
    uint32_t np, nc;
    uint64_t per_producer; /* items per producer, spread over FRAMES frames */
    _Atomic uint8_t *seen;
    _Atomic int bad_frame, bad_order;
} set_run;

typedef struct thread_arg {
    set_run *r;
    uint32_t index;
} thread_arg;

/* item index = (producer * FRAMES + frame - 1) * per_frame + k */
static uint64_t per_frame(const set_run *r)
{
    return r->per_producer / FRAMES;
}

static void *set_producer(void *arg)
{
    thread_arg *a = arg;
    set_run *r = a->r;
    for (uint64_t f = 1; f <= FRAMES; ++f) {
        uint64_t base = ((uint64_t)a->index * FRAMES + f - 1) * per_frame(r);
        for (uint64_t k = 0; k < per_frame(r); ++k)
            sw_th_activity_push_producer(r->set, a->index, as_item(base + k));
        sw_th_activity_end_frame_producer(r->set, a->index, f);
    }
    return NULL;
}

static void *set_consumer(void *arg)
{
    thread_arg *a = arg;
    set_run *r = a->r;
    uint64_t pf = per_frame(r);
    uint64_t *last = calloc(r->np, sizeof *last); /* last sequence per producer in this frame */
    for (uint64_t f = 1; f <= FRAMES; ++f) {
        memset(last, 0, r->np * sizeof *last);
        void *item = NULL;
        while (sw_th_activity_pop_consumer(r->set, a->index, f, &item) == SW_TH_ACT_ITEM) {
            uint64_t i = item_index(item), p = i / (FRAMES * pf), frame = (i / pf) % FRAMES + 1;
            atomic_fetch_add_explicit(&r->seen[i], 1, memory_order_relaxed);
            if (frame != f)
                atomic_store(&r->bad_frame, 1);
            /* A producer's items reach a consumer through one list per frame (its own list,
             * or a claimed dummy list, each filled by one producer), so they arrive in order. */
            uint64_t seq = i % pf + 1;
            if (seq <= last[p])
                atomic_store(&r->bad_order, 1);
            last[p] = seq;
        }
    }
    free(last);
    return NULL;
}

static void test_set(uint32_t np, uint32_t nc, uint64_t items)
{
    set_run r = {.np = np, .nc = nc, .per_producer = items / np / FRAMES * FRAMES};
    if (r.per_producer < FRAMES)
        r.per_producer = FRAMES;
    uint64_t total = r.per_producer * np;
    r.seen = calloc(total, 1);
    CHECK(r.seen && sw_th_activity_set_create(np, nc, 64, &r.set) == SW_OK, "create %u x %u", np,
          nc);
    pthread_t threads[128];
    thread_arg args[128];
    for (uint32_t i = 0; i < np + nc; ++i) {
        args[i] = (thread_arg){&r, i < np ? i : i - np};
        pthread_create(&threads[i], NULL, i < np ? set_producer : set_consumer, &args[i]);
    }
    for (uint32_t i = 0; i < np + nc; ++i)
        pthread_join(threads[i], NULL);
    uint64_t missing = 0, twice = 0;
    for (uint64_t i = 0; i < total; ++i) {
        missing += r.seen[i] == 0;
        twice += r.seen[i] > 1;
    }
    CHECK(missing == 0 && twice == 0, "%u x %u: %" PRIu64 " missing, %" PRIu64 " twice", np, nc,
          missing, twice);
    CHECK(!r.bad_frame, "%u x %u: an item delivered to a pop for another frame", np, nc);
    CHECK(!r.bad_order, "%u x %u: a producer's items out of order", np, nc);
    printf("set %u producers x %u consumers: %" PRIu64 " items in %d frames, each exactly once, in "
           "its own frame\n",
           np, nc, total, FRAMES);
    sw_th_activity_set_destroy(r.set);
    free(r.seen);
}

static int parse_list(const char *s, uint32_t *out, int max)
{
    int n = 0;
    while (*s && n < max) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 64)
            return -1;
        out[n++] = (uint32_t)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return -1;
    }
    return n;
}

int main(int argc, char **argv)
{
    uint32_t nps[16], ncs[16];
    int n_np = argc == 4 ? parse_list(argv[2], nps, 16) : -1;
    int n_nc = argc == 4 ? parse_list(argv[3], ncs, 16) : -1;
    uint64_t items = argc == 4 ? strtoull(argv[1], NULL, 10) : 0;
    if (n_np < 1 || n_nc < 1 || items < 1000) {
        fprintf(stderr, "usage: %s ITEMS NP_LIST NC_LIST   (ITEMS >= 1000, counts in 1..64)\n",
                argv[0]);
        return 2;
    }
    test_markers();
    test_spsc(items);
    for (int i = 0; i < n_np; ++i)
        for (int j = 0; j < n_nc; ++j)
            test_set(nps[i], ncs[j], items / 4);
    printf("%s: %d failure(s)\n", g_failures ? "FAIL" : "ok", g_failures);
    return g_failures ? 1 : 0;
}

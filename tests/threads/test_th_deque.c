/* SPDX-License-Identifier: MIT */
/* tests/threads: the Chase-Lev deque (threads/sw_th_deque.h) — LIFO for the owner, FIFO for
 * thieves, and exactly-once delivery while the ring grows under contention (each item counted in
 * a per-item atomic array, like GHC's testsuite/tests/rts/testwsdeque.c). */
#include "sw_th_deque.h"

#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#define ITEM(i) ((void *)(uintptr_t)((i) + 1))
#define ID(p) ((int64_t)(uintptr_t)(p)-1)

static void test_owner_lifo(void **state)
{
    (void)state;
    sw_th_deque q;
    assert_int_equal(sw_th_deque_init_owner(&q, 2), SW_OK);
    assert_null(sw_th_deque_pop_owner(&q));
    for (int i = 0; i < 1000; i++)
        assert_int_equal(sw_th_deque_push_owner(&q, ITEM(i)), SW_OK);
    assert_int_equal(sw_th_deque_size_estimate(&q), 1000);
    assert_true(sw_th_deque_capacity_owner(&q) >= 1000);
    assert_true(sw_th_deque_grow_count_owner(&q) >= 9); /* 2 → 1024 */
    for (int i = 999; i >= 0; i--)
        assert_int_equal(ID(sw_th_deque_pop_owner(&q)), i);
    assert_null(sw_th_deque_pop_owner(&q));
    assert_int_equal(sw_th_deque_size_estimate(&q), 0);
    sw_th_deque_destroy_owner(&q);
}

static void test_thief_fifo(void **state)
{
    (void)state;
    sw_th_deque q;
    void *x = NULL;
    assert_int_equal(sw_th_deque_init_owner(&q, 4), SW_OK);
    assert_int_equal(sw_th_deque_steal(&q, &x), SW_TH_STEAL_EMPTY);
    for (int i = 0; i < 1000; i++)
        assert_int_equal(sw_th_deque_push_owner(&q, ITEM(i)), SW_OK);
    for (int i = 0; i < 1000; i++) {
        assert_int_equal(sw_th_deque_steal(&q, &x), SW_TH_STEAL_OK);
        assert_int_equal(ID(x), i);
    }
    assert_int_equal(sw_th_deque_steal(&q, &x), SW_TH_STEAL_EMPTY);
    sw_th_deque_destroy_owner(&q);
}

/* Owner and thief work from opposite ends and meet on the last item exactly once. */
static void test_both_ends(void **state)
{
    (void)state;
    sw_th_deque q;
    void *x = NULL;
    assert_int_equal(sw_th_deque_init_owner(&q, 2), SW_OK);
    for (int round = 0; round < 3; round++) {
        for (int i = 0; i < 9; i++)
            assert_int_equal(sw_th_deque_push_owner(&q, ITEM(i)), SW_OK);
        for (int i = 0; i < 4; i++) {
            assert_int_equal(sw_th_deque_steal(&q, &x), SW_TH_STEAL_OK);
            assert_int_equal(ID(x), i);
            assert_int_equal(ID(sw_th_deque_pop_owner(&q)), 8 - i);
        }
        assert_int_equal(ID(sw_th_deque_pop_owner(&q)), 4);
        assert_null(sw_th_deque_pop_owner(&q));
        assert_int_equal(sw_th_deque_steal(&q, &x), SW_TH_STEAL_EMPTY);
    }
    sw_th_deque_destroy_owner(&q);
}

enum { THIEVES = 3 };

typedef struct contention {
    sw_th_deque q;
    int64_t n;
    _Atomic uint8_t *seen;
    _Atomic int done;
    _Atomic int64_t stolen;
} contention;

static void take(contention *c, void *x)
{
    int64_t id = ID(x);
    if (id >= 0 && id < c->n)
        atomic_fetch_add_explicit(&c->seen[id], 1, memory_order_relaxed);
}

static void *thief_main(void *arg)
{
    contention *c = arg;
    int64_t mine = 0;
    while (!atomic_load_explicit(&c->done, memory_order_acquire)) {
        void *x;
        if (sw_th_deque_steal(&c->q, &x) == SW_TH_STEAL_OK) {
            take(c, x);
            mine++;
        }
    }
    atomic_fetch_add(&c->stolen, mine);
    return NULL;
}

/* The owner pushes bursts (which grow a 2-slot ring many times) and pops some of each burst
 * while three thieves steal: every item must come out exactly once. */
static void test_growth_under_contention(void **state)
{
    (void)state;
    contention c = {.n = 200000};
    c.seen = calloc((size_t)c.n, sizeof *c.seen);
    assert_non_null(c.seen);
    assert_int_equal(sw_th_deque_init_owner(&c.q, 2), SW_OK);
    pthread_t t[THIEVES];
    for (int i = 0; i < THIEVES; i++)
        assert_int_equal(pthread_create(&t[i], NULL, thief_main, &c), 0);
    uint64_t rng = 12345;
    int64_t next = 0, popped = 0;
    while (next < c.n) {
        rng = rng * 6364136223846793005u + 1442695040888963407u;
        int64_t burst = 1 + (int64_t)((rng >> 33) % 300);
        for (int64_t i = 0; i < burst && next < c.n; i++)
            assert_int_equal(sw_th_deque_push_owner(&c.q, ITEM(next++)), SW_OK);
        int64_t pops = (int64_t)((rng >> 20) % 200);
        for (int64_t i = 0; i < pops; i++) {
            void *x = sw_th_deque_pop_owner(&c.q);
            if (!x)
                break;
            take(&c, x);
            popped++;
        }
    }
    for (void *x; (x = sw_th_deque_pop_owner(&c.q)) != NULL; popped++)
        take(&c, x);
    atomic_store_explicit(&c.done, 1, memory_order_release);
    for (int i = 0; i < THIEVES; i++)
        pthread_join(t[i], NULL);
    int64_t bad = 0;
    for (int64_t i = 0; i < c.n; i++)
        bad += atomic_load(&c.seen[i]) != 1;
    print_message("items %lld: popped %lld, stolen %lld, ring grew %u times to %zu slots\n",
                  (long long)c.n, (long long)popped, (long long)atomic_load(&c.stolen),
                  sw_th_deque_grow_count_owner(&c.q), sw_th_deque_capacity_owner(&c.q));
    assert_int_equal(bad, 0);
    assert_int_equal(popped + atomic_load(&c.stolen), c.n);
    assert_true(sw_th_deque_grow_count_owner(&c.q) >= 3);
    sw_th_deque_destroy_owner(&c.q);
    free(c.seen);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_owner_lifo),
        cmocka_unit_test(test_thief_fifo),
        cmocka_unit_test(test_both_ends),
        cmocka_unit_test(test_growth_under_contention),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

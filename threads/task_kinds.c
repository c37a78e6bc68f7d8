/* SPDX-License-Identifier: MIT */
/* The pool's task kinds, registered by name by the layers that submit tasks (sw_th_pool.h). The
 * pool only counts and times per value; what a value means is the registering layer's. */
#include "sw_th_pool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static const char *g_kinds[SW_TH_TASK_KIND_MAX] = {"other"};
/* Entries below g_count are complete: published with release after they are written. */
static _Atomic uint32_t g_count = 1;

sw_th_task_kind sw_th_task_kind_register(const char *name)
{
    if (!name)
        return SW_TH_TASK_OTHER;
    pthread_mutex_lock(&g_lock);
    const uint32_t n = atomic_load_explicit(&g_count, memory_order_relaxed);
    sw_th_task_kind kind = SW_TH_TASK_OTHER;
    uint32_t k = 0;
    while (k < n && strcmp(g_kinds[k], name) != 0)
        k++;
    if (k < n) {
        kind = k;
    } else if (n < SW_TH_TASK_KIND_MAX) {
        g_kinds[n] = name;
        atomic_store_explicit(&g_count, n + 1, memory_order_release);
        kind = n;
    }
    pthread_mutex_unlock(&g_lock);
    return kind;
}

sw_th_task_kind sw_th_task_kind_of(sw_th_task_kind_slot *slot)
{
    uint32_t v = atomic_load_explicit(&slot->value, memory_order_acquire);
    if (!v) {
        v = sw_th_task_kind_register(slot->name) + 1;
        atomic_store_explicit(&slot->value, v, memory_order_release);
    }
    return v - 1;
}

uint32_t sw_th_task_kind_count(void)
{
    return atomic_load_explicit(&g_count, memory_order_acquire);
}

const char *sw_th_task_kind_name(sw_th_task_kind kind)
{
    return kind < sw_th_task_kind_count() ? g_kinds[kind] : "?";
}

/* SPDX-License-Identifier: MIT */
/* Generation-checked handle pools (CONVENTIONS.md: handles like sokol's sg_buffer). */
#include "sw_rt.h"
#include "sw_hooks.h"

#include <stdlib.h>

static int grow(sw_rt_pool *pool)
{
    uint32_t cap = pool->capacity ? pool->capacity * 2 : 16;
    if (cap > SW_RT_POOL_MAX_SLOTS)
        cap = SW_RT_POOL_MAX_SLOTS;
    if (cap <= pool->capacity)
        return 0;
    void **items = sw__realloc(pool->items, cap * sizeof *items);
    if (!items)
        return 0;
    pool->items = items;
    uint16_t *gens = sw__realloc(pool->generations, cap * sizeof *gens);
    if (!gens)
        return 0;
    pool->generations = gens;
    for (uint32_t i = pool->capacity; i < cap; i++) {
        items[i] = NULL;
        gens[i] = 1;
    }
    pool->capacity = cap;
    return 1;
}

static uint32_t make_id(uint32_t slot, uint16_t generation)
{
    return ((uint32_t)generation << 16) | (slot + 1);
}

/* Locks pool->lock: protects items/generations/capacity. */
uint32_t sw_rt_pool_add(sw_rt_pool *pool, void *item)
{
    uint32_t id = 0;
    pthread_mutex_lock(&pool->lock);
    for (int attempt = 0; attempt < 2 && !id; attempt++) {
        for (uint32_t i = 0; i < pool->capacity; i++) {
            if (!pool->items[i]) {
                pool->items[i] = item;
                id = make_id(i, pool->generations[i]);
                break;
            }
        }
        if (!id && !grow(pool))
            break;
    }
    pthread_mutex_unlock(&pool->lock);
    return id;
}

static int slot_of(const sw_rt_pool *pool, uint32_t id, uint32_t *slot)
{
    uint32_t index = id & 0xffffu;
    if (index == 0 || index > pool->capacity)
        return 0;
    *slot = index - 1;
    return pool->items[*slot] && pool->generations[*slot] == (uint16_t)(id >> 16);
}

/* Locks pool->lock (see sw_rt_pool_add); `check` runs under it. */
sw_result sw_rt_pool_get_checked(sw_rt_pool *pool, uint32_t id, sw_rt_pool_check_fn check,
                                 void *ctx, void **out)
{
    sw_result r = SW_ERR_STALE_HANDLE;
    uint32_t slot;
    *out = NULL;
    pthread_mutex_lock(&pool->lock);
    if (slot_of(pool, id, &slot)) {
        r = check(pool->items[slot], ctx);
        if (r == SW_OK)
            *out = pool->items[slot];
    }
    pthread_mutex_unlock(&pool->lock);
    return r;
}

/* Locks pool->lock (see sw_rt_pool_add); `check` runs under it, so no other thread can remove
 * the item between the check and the removal. The slot's generation moves on (never to 0), so
 * every handle to the removed item goes stale. */
sw_result sw_rt_pool_remove_checked(sw_rt_pool *pool, uint32_t id, sw_rt_pool_check_fn check,
                                    void *ctx, void **out)
{
    sw_result r = SW_ERR_STALE_HANDLE;
    uint32_t slot;
    *out = NULL;
    pthread_mutex_lock(&pool->lock);
    if (slot_of(pool, id, &slot)) {
        r = check(pool->items[slot], ctx);
        if (r == SW_OK) {
            *out = pool->items[slot];
            pool->items[slot] = NULL;
            uint16_t next = (uint16_t)(pool->generations[slot] + 1);
            pool->generations[slot] = next ? next : 1;
        }
    }
    pthread_mutex_unlock(&pool->lock);
    return r;
}

static sw_result accept_any(void *item, void *ctx)
{
    (void)item;
    (void)ctx;
    return SW_OK;
}

void *sw_rt_pool_remove(sw_rt_pool *pool, uint32_t id)
{
    void *item;
    sw_rt_pool_remove_checked(pool, id, accept_any, NULL, &item);
    return item;
}

/* SPDX-License-Identifier: MIT */
#include <splinewalk/sw_lod_build.h>
#include "hierarchy_support.h"

#include "sw_lod_cache.h"
#include "sw_lod_static_set.h"

#include <stdio.h>
#include <stdlib.h>

struct sw_test_hierarchies {
    sw_th_pool *pool;
    sw_lod_cache *cache;
    const sw_sg_scene *scene;
    sw_lod_static_set *statics; /* made on first ask */
};

sw_test_hierarchies *sw_test_hierarchies_create(const sw_sg_scene *scene)
{
    sw_test_hierarchies *h = calloc(1, sizeof *h);
    sw_th_pool_desc pd = {0};
    sw_status st = {0};
    if (!h || sw_th_pool_create(&pd, &h->pool) != SW_OK) {
        fprintf(stderr, "hierarchies: no worker pool\n");
        free(h);
        return NULL;
    }
    h->scene = scene;
    if (sw_lod_cache_create(scene, h->pool, NULL, &h->cache, &st) != SW_OK) {
        fprintf(stderr, "hierarchies: %s\n", st.message);
        sw_test_hierarchies_free(h);
        return NULL;
    }
    return h;
}

struct sw_lod_cache *sw_test_hierarchies_cache(sw_test_hierarchies *h)
{
    return h ? h->cache : NULL;
}

struct sw_lod_static_set *sw_test_hierarchies_statics(sw_test_hierarchies *h)
{
    sw_status st = {0};
    (void)sw_lod_build_install(); /* the levels are built by the LOD-building module */
    /* every level kept: the tests force fine ones into frames to check their joins */
    const sw_lod_static_set_desc desc = {.keep_undrawn = 1};
    if (h && !h->statics &&
        sw_lod_static_set_create(h->scene, h->pool, &desc, &h->statics, &st) != SW_OK)
        fprintf(stderr, "static LODs: %s\n", st.message);
    return h ? h->statics : NULL;
}

void sw_test_hierarchies_free(sw_test_hierarchies *h)
{
    if (!h)
        return;
    sw_lod_static_set_destroy(h->statics);
    sw_lod_cache_destroy(h->cache);
    sw_th_pool_destroy(h->pool);
    free(h);
}

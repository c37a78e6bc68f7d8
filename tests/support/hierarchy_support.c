#include "hierarchy_support.h"

#include "sw_lod_cache.h"

#include <stdio.h>
#include <stdlib.h>

struct sw_test_hierarchies {
    sw_th_pool *pool;
    sw_lod_cache *cache;
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

void sw_test_hierarchies_free(sw_test_hierarchies *h)
{
    if (!h)
        return;
    sw_lod_cache_destroy(h->cache);
    sw_th_pool_destroy(h->pool);
    free(h);
}

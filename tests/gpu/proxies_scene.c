/* SPDX-License-Identifier: MIT */
#include "proxies_scene.h"

#include "sw_lod_static_set.h"
#include "sw_sg_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

struct proxies_scene {
    sw_sg_scene *scene;
    sw_th_pool *pool;
    sw_lod_static_set *statics;
};

proxies_scene *proxies_scene_open(const char *path)
{
    proxies_scene *ps = calloc(1, sizeof *ps);
    sw_status st = {0};
    sw_th_pool_desc pd = {0};
    const void *cache = NULL;
    size_t bytes = 0;
    uint32_t adopted = 0;
    /* the cache's own proxies are left out: frames are drawn while the pool builds them (the
       same ones: test_proxy_cache) */
    const sw_lod_static_set_desc desc = {.ignore_cached_proxies = 1};
    if (!ps || sw_sg_scene_open(path, &ps->scene, &st) != SW_OK ||
        sw_th_pool_create(&pd, &ps->pool) != SW_OK ||
        sw_lod_static_set_create(ps->scene, ps->pool, &desc, &ps->statics, &st) != SW_OK ||
        sw_sg_scene_lods(ps->scene, &cache, &bytes, &st) != SW_OK ||
        sw_lod_static_set_load(ps->statics, cache, bytes, path, &adopted, &st) != SW_OK ||
        sw_lod_static_set_build_proxies(ps->statics, &st) != SW_OK) {
        fprintf(stderr, "%s: %s\n", path, st.message);
        proxies_scene_free(ps);
        return NULL;
    }
    printf("%s: %u units, %u adopted from its LOD cache\n", path,
           sw_lod_static_set_unit_count(ps->statics), adopted);
    return ps;
}

void proxies_scene_wait(proxies_scene *ps)
{
    sw_lod_static_set_wait_proxies(ps->statics);
}

void proxies_scene_free(proxies_scene *ps)
{
    if (!ps)
        return;
    sw_lod_static_set_destroy(ps->statics);
    if (ps->pool)
        sw_th_pool_destroy(ps->pool);
    sw_sg_scene_free(ps->scene);
    free(ps);
}

const struct sw_sg_scene *proxies_scene_scene(const proxies_scene *ps)
{
    return ps->scene;
}

struct sw_lod_static_set *proxies_scene_statics(const proxies_scene *ps)
{
    return ps->statics;
}

void proxies_scene_box(const proxies_scene *ps, double box[6])
{
    const double *b = sw_lod_static_set_instances(ps->statics)->scene_box;
    for (int k = 0; k < 6; ++k)
        box[k] = b[k];
}

uint32_t proxies_scene_check(const proxies_scene *ps, uint32_t *n, uint64_t *counted)
{
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(ps->statics)->bvh;
    uint32_t bad = 0;
    uint64_t tris = 0;
    *n = 0;
    for (uint32_t k = 0; k < bvh->n_nodes; ++k) {
        const sw_lod_proxy *p = sw_lod_static_set_proxy(ps->statics, k);
        if (!p)
            continue;
        ++*n;
        tris += p->n_triangles;
        /* the clustering moves no vertex farther than its cell's diagonal */
        const double most = p->input_err + sqrt(3.0) * p->cell * (1.0 + 1e-12);
        int ok = isfinite(p->err) && p->err >= p->input_err && p->err <= most && p->n_parts > 0;
        for (uint32_t i = 0; i < p->n_parts; ++i)
            ok = ok && p->parts[i].n_triangles > 0;
        bad += !ok;
    }
    sw_lod_static_set_stats ss;
    sw_lod_static_set_get_stats(ps->statics, &ss);
    printf("  %u proxies, %llu triangles, %.2f MiB, built in %.2f s (%llu nodes could not be)\n",
           *n, (unsigned long long)tris, ss.proxy_bytes / 1048576.0, ss.proxy_seconds,
           (unsigned long long)ss.proxies_failed);
    *counted = ss.proxies;
    return bad;
}

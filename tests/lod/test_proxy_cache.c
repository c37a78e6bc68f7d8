/* SPDX-License-Identifier: MIT */
/* Cluster proxies stored in the LOD cache (lod/static/static_lod_io.c, the LODS section's
 * proxies; `splinewalk build-lod` writes them), on a car park that build-lod gave a cache:
 *  - read from the cache, the proxies are published at once (started, done, adopted) and equal,
 *    node for node and bit for bit (bound, cell, counts, colours, positions, normals, triangles,
 *    open edges), to the proxies a second set builds in its pool from the same chains (catches: a
 *    field written and read in different orders, positions or normals the builder leaves finer
 *    than the cache stores them — then both would hold different meshes —, a build that is not
 *    reproducible, open edges found differently);
 *  - the build's counts (proxies, triangles, nodes that could not have one, proxies dropped over
 *    the budget) read back with them;
 *  - that built set serialized is the cache build-lod wrote, byte for byte;
 *  - the summary `splinewalk info` prints counts the proxies and triangles the set holds;
 *  - refused as a whole (SW_ERR_FORMAT, no chain adopted, no proxy): a cut anywhere in the
 *    proxies, a triangle index out of range, vertices reaching out of their node's box, a bound
 * below its inputs' error, a proxy on a node with too few instances;
 *  - a stale key (other instances or transforms) and a version-2 cache (no proxies) adopt the
 *    chains and leave the proxies to be built.
 * usage: test_proxy_cache SCENE.sws (with a LOD cache holding proxies)
 */
#include "sw_lod_static_set.h"
#include "sw_sg_scene.h"
#include "test_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct fixture {
    sw_sg_scene *scene;
    sw_th_pool *pool;
    const unsigned char *cache;
    size_t cache_size;
    sw_lod_static_set *probe; /* what refused caches are given: a refusal adopts nothing */
} fixture;

static sw_lod_static_set *new_set(const fixture *f, int ignore_cached_proxies)
{
    sw_lod_static_set_desc d = {0};
    d.ignore_cached_proxies = ignore_cached_proxies;
    sw_lod_static_set *set = NULL;
    sw_status st = {0};
    CHECK(sw_lod_static_set_create(f->scene, f->pool, &d, &set, &st) == SW_OK, "set: %s",
          st.message);
    return set;
}

/* Loads `blob` into `set` (NULL: a fresh one); returns the result, *adopted the chains, *proxies
 * whether the proxies were adopted (0 also when they were left to be built). */
static sw_result load(const fixture *f, sw_lod_static_set *into, const void *blob, size_t size,
                      uint32_t *adopted, int *proxies, sw_status *st)
{
    sw_lod_static_set *set = into ? into : new_set(f, 0);
    *adopted = 0;
    const sw_result r = sw_lod_static_set_load(set, blob, size, "cache", adopted, st);
    sw_lod_static_set_stats ss;
    sw_lod_static_set_get_stats(set, &ss);
    *proxies = ss.proxies_adopted;
    CHECK(ss.proxies_adopted == sw_lod_static_set_proxies_started(set),
          "proxies started (%d) without being adopted (%d)", sw_lod_static_set_proxies_started(set),
          ss.proxies_adopted);
    if (!into)
        sw_lod_static_set_destroy(set);
    return r;
}

static int same_part(const sw_lod_proxy *a, const sw_lod_proxy *b, uint32_t k)
{
    const sw_lod_static_level *x = &a->parts[k], *y = &b->parts[k];
    return x->n_vertices == y->n_vertices && x->n_triangles == y->n_triangles &&
           !memcmp(a->colors[k], b->colors[k], sizeof a->colors[k]) &&
           !memcmp(x->positions, y->positions, 3 * (size_t)x->n_vertices * sizeof *x->positions) &&
           !memcmp(x->normals, y->normals, 3 * (size_t)x->n_vertices * sizeof *x->normals) &&
           !memcmp(x->triangles, y->triangles, 3 * (size_t)x->n_triangles * sizeof *x->triangles) &&
           a->n_lines[k] == b->n_lines[k] &&
           !memcmp(a->lines[k], b->lines[k], 2 * (size_t)a->n_lines[k] * sizeof *a->lines[k]);
}

static int same_proxy(const sw_lod_proxy *a, const sw_lod_proxy *b)
{
    if (a->err != b->err || a->input_err != b->input_err || a->cell != b->cell ||
        a->n_parts != b->n_parts || a->n_triangles != b->n_triangles ||
        a->instances != b->instances || a->faces != b->faces ||
        a->input_triangles != b->input_triangles || a->vanished != b->vanished ||
        memcmp(a->centre, b->centre, sizeof a->centre))
        return 0;
    for (uint32_t k = 0; k < a->n_parts; ++k)
        if (!same_part(a, b, k))
            return 0;
    return 1;
}

/* The set read from the cache against one that built its proxies; returns the proxies compared. */
static uint32_t check_same_proxies(const sw_lod_static_set *read, const sw_lod_static_set *built)
{
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(read)->bvh;
    uint32_t n = 0, differ = 0;
    for (uint32_t node = 0; node < bvh->n_nodes; ++node) {
        const sw_lod_proxy *a = sw_lod_static_set_proxy(read, node);
        const sw_lod_proxy *b = sw_lod_static_set_proxy(built, node);
        if (!a && !b)
            continue;
        ++n;
        if (!a || !b || !same_proxy(a, b)) {
            if (differ++ < 5)
                fprintf(stderr, "  node %u: %s\n", node,
                        !a   ? "built, not read"
                        : !b ? "read, not built"
                             : "read != built");
        }
    }
    CHECK(differ == 0, "%u of %u proxies differ between the cache and a build", differ, n);
    return n;
}

/* The offset of the proxies in a blob: where a set without proxies ends its chains. */
static size_t proxies_offset(const fixture *f, size_t size)
{
    sw_lod_static_set *set = new_set(f, 1);
    sw_status st = {0};
    void *blob = NULL;
    size_t bare = 0;
    CHECK(sw_lod_static_set_load(set, f->cache, f->cache_size, "cache", NULL, &st) == SW_OK &&
              sw_lod_static_set_serialize(set, &blob, &bare, &st) == SW_OK,
          "bare cache: %s", st.message);
    free(blob);
    sw_lod_static_set_destroy(set);
    CHECK(bare >= 4 && bare < size, "a set without proxies wrote %zu of %zu bytes", bare, size);
    return bare - 4; /* its flag 0 */
}

static void expect_refused(const fixture *f, const unsigned char *blob, size_t size,
                           const char *what)
{
    uint32_t adopted;
    int proxies;
    sw_status st = {0};
    const sw_result r = load(f, f->probe, blob, size, &adopted, &proxies, &st);
    CHECK(r == SW_ERR_FORMAT && adopted == 0 && !proxies,
          "%s: result %d, %u chains adopted, proxies %d (want SW_ERR_FORMAT, nothing)", what, r,
          adopted, proxies);
    if (r == SW_ERR_FORMAT)
        printf("  %-34s %s\n", what, st.message);
}

/* The first proxy's header and first part in a blob (offsets after the proxies' header). */
typedef struct first_proxy {
    size_t node, err, input_err, range, n_vertices, positions, triangles;
    uint32_t nv;
} first_proxy;

static first_proxy locate_first(const unsigned char *blob, size_t at)
{
    first_proxy p;
    at += 4 + 4 + 4 + 4 + 16; /* flag, key, nodes, count, failed + pruned */
    p.node = at;
    p.err = at + 4;
    p.input_err = at + 12;
    p.range = at + 28;
    at += 4 + 48 + 4 + 24 + 4; /* node, err/input_err/cell/range, instances, 3 counts, parts */
    p.n_vertices = at + 16;    /* after the colour */
    memcpy(&p.nv, blob + p.n_vertices, 4);
    p.positions = at + 24;
    p.triangles = p.positions + 10 * (size_t)p.nv; /* after position and normal codes */
    return p;
}

static void check_damage(const fixture *f, const unsigned char *blob, size_t size, size_t at)
{
    unsigned char *bad = malloc(size);
    const first_proxy p = locate_first(blob, at);
    /* cuts: every byte of the proxies' header and first proxy's header, then spread evenly */
    for (size_t cut = at; cut < size; cut += cut < p.positions ? 1 : (size - at) / 61 + 1) {
        char what[64];
        snprintf(what, sizeof what, "cut at %zu of %zu", cut, size);
        uint32_t adopted;
        int proxies;
        sw_status st = {0};
        const sw_result r = load(f, f->probe, blob, cut, &adopted, &proxies, &st);
        CHECK(r == SW_ERR_FORMAT && adopted == 0 && !proxies, "%s: result %d, %u adopted", what, r,
              adopted);
    }
    printf("  cuts in the proxies: refused\n");
    memcpy(bad, blob, size);
    const uint32_t nv = p.nv; /* one past the last vertex, as u16 or u32 as the part stores it */
    const uint16_t nv16 = (uint16_t)nv;
    if (nv > 65536)
        memcpy(bad + p.triangles + 4, &nv, 4);
    else if (nv < 65536)
        memcpy(bad + p.triangles + 2, &nv16, 2);
    CHECK(nv != 65536, "the first part has 65536 vertices: no u16 index is out of range");
    expect_refused(f, bad, size, "a triangle index out of range:");
    memcpy(bad, blob, size);
    const double far = 1e30;
    memcpy(bad + p.range, &far, 8);
    expect_refused(f, bad, size, "vertices far out of the box:");
    memcpy(bad, blob, size);
    double err;
    memcpy(&err, blob + p.input_err, 8);
    err = 2.0 * err + 1.0;
    memcpy(bad + p.input_err, &err, 8);
    expect_refused(f, bad, size, "a bound below its inputs' error:");
    /* a node with fewer instances than a proxy needs */
    memcpy(bad, blob, size);
    uint32_t small = 0;
    while (small < sw_lod_static_set_instances(f->probe)->bvh->n_nodes &&
           sw__lod_proxy_candidate(f->probe, small))
        ++small;
    memcpy(bad + p.node, &small, 4);
    expect_refused(f, bad, size, "a proxy on a small node:");
    free(bad);
}

static void check_stale_and_old(const fixture *f, const unsigned char *blob, size_t size, size_t at)
{
    unsigned char *b = malloc(size);
    memcpy(b, blob, size);
    b[at + 4] ^= 1; /* the key */
    uint32_t adopted;
    int proxies;
    sw_status st = {0};
    sw_result r = load(f, NULL, b, size, &adopted, &proxies, &st);
    CHECK(r == SW_OK && adopted > 0 && !proxies,
          "a stale key: result %d (%s), %u chains adopted, proxies %d (want the chains only)", r,
          st.message, adopted, proxies);
    /* version 2: the same chains, no proxies block */
    memcpy(b, blob, size);
    const uint32_t v2 = 2;
    memcpy(b + 8, &v2, 4);
    r = load(f, NULL, b, at, &adopted, &proxies, &st);
    CHECK(r == SW_OK && adopted > 0 && !proxies,
          "a version-2 cache: result %d (%s), %u chains adopted, proxies %d", r, st.message,
          adopted, proxies);
    /* ...which still ends after its last chain */
    r = load(f, f->probe, b, at + 4, &adopted, &proxies, &st);
    CHECK(r == SW_ERR_FORMAT, "a version-2 cache with bytes after its chains: result %d", r);
    printf("  stale key and version 2: chains adopted, proxies left to build\n");
    free(b);
}

static void check_summary(const unsigned char *blob, size_t size, const sw_lod_static_set *set)
{
    sw_lod_static_cache_summary sum;
    sw_status st = {0};
    CHECK(sw_lod_static_cache_summarize(blob, size, "cache", &sum, &st) == SW_OK, "summary: %s",
          st.message);
    sw_lod_static_set_stats ss;
    sw_lod_static_set_get_stats(set, &ss);
    CHECK(sum.proxies == ss.proxies && sum.proxy_triangles == ss.proxy_triangles,
          "summary: %u proxies, %llu triangles; the set: %llu, %llu", sum.proxies,
          (unsigned long long)sum.proxy_triangles, (unsigned long long)ss.proxies,
          (unsigned long long)ss.proxy_triangles);
    printf("  summary: %u proxies, %llu triangles, %llu vertices, %.2f MiB stored, %.2f MiB in "
           "memory\n",
           sum.proxies, (unsigned long long)sum.proxy_triangles,
           (unsigned long long)sum.proxy_vertices, sum.proxy_bytes / 1048576.0,
           ss.proxy_bytes / 1048576.0);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_proxy_cache SCENE.sws\n");
        return 2;
    }
    fixture f = {0};
    sw_status st = {0};
    sw_th_pool_desc pd = {0};
    const void *cache = NULL;
    CHECK(sw_sg_scene_open(argv[1], &f.scene, &st) == SW_OK, "%s: %s", argv[1], st.message);
    CHECK(sw_th_pool_create(&pd, &f.pool) == SW_OK, "pool");
    CHECK(sw_sg_scene_lods(f.scene, &cache, &f.cache_size, &st) == SW_OK, "%s: %s", argv[1],
          st.message);
    f.cache = cache;

    sw_lod_static_set *read = new_set(&f, 0), *built = new_set(&f, 1);
    CHECK(sw_lod_static_set_load(read, f.cache, f.cache_size, argv[1], NULL, &st) == SW_OK,
          "read: %s", st.message);
    CHECK(sw_lod_static_set_proxies_done(read), "the cache's proxies were not published on load");
    CHECK(sw_lod_static_set_load(built, f.cache, f.cache_size, argv[1], NULL, &st) == SW_OK &&
              !sw_lod_static_set_proxies_started(built),
          "a set ignoring cached proxies: %s", st.message);
    CHECK(sw_lod_static_set_build_proxies(built, &st) == SW_OK, "build: %s", st.message);
    sw_lod_static_set_wait_proxies(built);
    const uint32_t n = check_same_proxies(read, built);
    sw_lod_static_set_stats rs, bs;
    sw_lod_static_set_get_stats(read, &rs);
    sw_lod_static_set_get_stats(built, &bs);
    CHECK(rs.proxies_failed == bs.proxies_failed && rs.proxies_pruned == bs.proxies_pruned &&
              rs.proxies == bs.proxies && rs.proxy_triangles == bs.proxy_triangles &&
              rs.proxies_adopted && !bs.proxies_adopted,
          "stats read / built: %llu / %llu proxies, %llu / %llu failed, %llu / %llu pruned",
          (unsigned long long)rs.proxies, (unsigned long long)bs.proxies,
          (unsigned long long)rs.proxies_failed, (unsigned long long)bs.proxies_failed,
          (unsigned long long)rs.proxies_pruned, (unsigned long long)bs.proxies_pruned);
    CHECK(n > 0, "no proxies in %s", argv[1]);
    printf("%s: %u proxies read equal to %u built\n", argv[1], n, n);

    void *blob = NULL;
    size_t size = 0;
    CHECK(sw_lod_static_set_serialize(built, &blob, &size, &st) == SW_OK, "%s", st.message);
    CHECK(size == f.cache_size && !memcmp(blob, f.cache, size),
          "the built set serialized (%zu bytes) is not the file's cache (%zu bytes)", size,
          f.cache_size);
    check_summary(blob, size, built);
    const size_t at = proxies_offset(&f, size);
    f.probe = new_set(&f, 0);
    check_damage(&f, blob, size, at);
    check_stale_and_old(&f, blob, size, at);

    free(blob);
    sw_lod_static_set_destroy(f.probe);
    sw_lod_static_set_destroy(read);
    sw_lod_static_set_destroy(built);
    sw_th_pool_destroy(f.pool);
    sw_sg_scene_free(f.scene);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}

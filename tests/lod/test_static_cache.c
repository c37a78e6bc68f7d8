/* SPDX-License-Identifier: MIT */
/* The static-LOD set and its cache (lod/static/sw_lod_static_set.h, lod/static/static_lod_io.c:
 * "cached in the .sws file by splinewalk build-lod"):
 *  - units partition the faces: every face with patches in exactly one unit, each unit's patches
 *    exactly its faces' patches of the clustering, its box holding every vertex of its chain, its
 *    δ (which the frame reads before any build) the one its chain was built with;
 *  - every level of every unit (super-surfaces of several faces, as the frame draws them) within
 *    its declared ε_k both ways, by a measurement independent of the one that declared it (random
 *    points, another seed, other counts); zero violations;
 *  - serialize -> load into a fresh set (a second clustering of the same scene: the cache's key
 *    hashes its units, so this also checks that clustering is reproducible) adopts every chain,
 *    equal to the original byte for byte;
 *  - every truncation of the cache, a wrong key and a triangle index out of range are refused
 *    as a whole (nothing adopted), with SW_ERR_FORMAT / SW_ERR_INVALID_ARGUMENT;
 *  - the summary `splinewalk info` prints (sw_lod_static_cache_summarize) equals the set's own
 *    chains: chains, levels, per level the triangles, vertices and ε range, δ range (catches: a
 *    summary that skips a level's arrays by the wrong size and reads garbage after the first);
 *    every truncation it is given is refused with SW_ERR_FORMAT or SW_ERR_VERSION;
 *  - the .sws LODS section: saved, reopened, the same bytes back; the core sections unchanged; a
 *    flipped byte in it gives SW_ERR_CHECKSUM while the scene itself still opens and validates.
 * usage: test_static_cache MODEL WORKDIR
 */
#include <splinewalk/sw_lod_build.h>
#include "model_import.h"
#include "sw_hooks.h"
#include "sw_lod_static_internal.h"
#include "sw_lod_static_set.h"
#include "sw_sg_scene.h"
#include "test_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check_units(const sw_lod_static_set *set, const sw_sg_scene *scene)
{
    const uint32_t n_faces = sw_sg_scene_view_ptr(scene)->n_faces, n = sw_lod_static_set_unit_count(set);
    const sw_lod_supersurfaces *ss = sw_lod_static_set_supersurfaces(set);
    uint32_t *seen = calloc(n_faces, sizeof *seen), patches = 0;
    for (uint32_t u = 0; u < n; ++u) {
        const sw_lod_static_unit *un = sw_lod_static_set_unit(set, u);
        CHECK(un->n_faces > 0 && un->n_patches >= un->n_faces, "unit %u: %u faces, %u patches", u,
              un->n_faces, un->n_patches);
        for (uint32_t i = 0; i < un->n_faces; ++i) {
            const uint32_t f = sw_lod_static_set_faces(set)[un->first_face + i];
            seen[f]++;
            CHECK(sw_lod_static_set_unit_of(set, f) == u, "face %u: unit_of %u, listed in %u", f,
                  sw_lod_static_set_unit_of(set, f), u);
        }
        for (uint32_t k = 0; k < un->n_patches; ++k) {
            const uint32_t f = sw_lod_static_set_patches(set)[un->first_patch + k].face;
            CHECK(sw_lod_static_set_unit_of(set, f) == u, "unit %u holds a patch of face %u", u, f);
        }
        patches += un->n_patches;
        const sw_lod_static_chain *c = sw_lod_static_set_get(set, u);
        CHECK(!c || c->delta == un->delta, "unit %u: built with δ %.17g, the frame expects %.17g",
              u, c ? c->delta : 0.0, un->delta);
        for (int32_t k = 0; c && k < c->n_levels; ++k)
            for (uint32_t v = 0; v < c->levels[k].n_vertices; ++v)
                for (int a = 0; a < 3; ++a) {
                    const double x = c->levels[k].positions[3 * v + a];
                    const double slack = 1e-9 * (1.0 + fabs(x));
                    CHECK(x >= un->box[a] - slack && x <= un->box[3 + a] + slack,
                          "unit %u level %d: a vertex outside the unit's box", u, k);
                }
    }
    uint32_t with_patches = 0;
    for (uint32_t f = 0; f < n_faces; ++f)
        with_patches += sw_lod_static_set_unit_of(set, f) != SW_LOD_STATIC_NO_UNIT;
    for (uint32_t f = 0; f < n_faces; ++f)
        CHECK(seen[f] <= 1, "face %u in %u units", f, seen[f]);
    CHECK(patches == ss->n_patches, "units hold %u patches, the clustering %u", patches,
          ss->n_patches);
    printf("  %u units over %u of %u faces, %u patches\n", n, with_patches, n_faces, patches);
    free(seen);
}

/* The same mesh, bit for bit (ε not compared). */
static int meshes_equal(const sw_lod_static_level *x, const sw_lod_static_level *y)
{
    const size_t nv = x->n_vertices;
    if (x->n_vertices != y->n_vertices || x->n_triangles != y->n_triangles)
        return 0;
    return nv == 0 ||
           !(memcmp(x->positions, y->positions, 3 * nv * sizeof(double)) ||
             memcmp(x->normals, y->normals, 3 * nv * sizeof(float)) ||
             memcmp(x->uv, y->uv, 2 * nv * sizeof(double)) ||
             memcmp(x->face, y->face, nv * sizeof(uint32_t)) ||
             memcmp(x->triangles, y->triangles, 3 * (size_t)x->n_triangles * sizeof(uint32_t)));
}

/* No two kept levels of a chain hold the same mesh, and a level dropped after a kept one has an
 * ε no smaller than it (a duplicate's ε is taken by the finer level when smaller; catches
 * duplicates stored, or an ε lost with them). Returns the levels dropped. */
static uint32_t check_kept_levels(const sw_lod_static_chain *c, uint32_t unit)
{
    uint32_t dropped = 0;
    int32_t prev = -1;
    for (int32_t k = 0; k < c->n_levels; ++k) {
        const sw_lod_static_level *l = &c->levels[k];
        if (l->n_triangles == 0) {
            dropped += l->n_triangles_dropped > 0;
            CHECK(prev < 0 || c->levels[prev].eps <= l->eps,
                  "unit %u: level %d dropped after level %d, ε %.17g < %.17g kept", unit, k, prev,
                  l->eps, prev < 0 ? 0.0 : c->levels[prev].eps);
            continue;
        }
        CHECK(prev < 0 || !meshes_equal(&c->levels[prev], l),
              "unit %u: levels %d and %d both kept, the same mesh", unit, prev, k);
        prev = k;
    }
    return dropped;
}

/* A level of nt triangles over 3 vertices (the corners of one triangle, repeated), coordinates
 * offset by `shift` so that two levels differ or not; arrays from the library's allocator, which
 * sw_lod_static_free uses. */
static sw_lod_static_level synthetic_level(uint32_t nt, double shift, double eps)
{
    sw_lod_static_level l = {.n_vertices = 3, .n_triangles = nt, .eps = eps, .eps_target = eps};
    l.positions = sw__calloc(9, sizeof *l.positions);
    l.normals = sw__calloc(9, sizeof *l.normals);
    l.uv = sw__calloc(6, sizeof *l.uv);
    l.face = sw__calloc(3, sizeof *l.face);
    l.triangles = sw__calloc(3 * (size_t)nt, sizeof *l.triangles);
    if (!l.positions || !l.normals || !l.uv || !l.face || !l.triangles)
        return l;
    for (int v = 0; v < 3; ++v) {
        l.positions[3 * v + v] = 1.0 + shift;
        l.normals[3 * v + 2] = 1.0f;
    }
    for (uint32_t t = 0; t < nt; ++t)
        for (uint32_t c = 0; c < 3; ++c)
            l.triangles[3 * t + c] = c;
    return l;
}

/* sw_lod_static_drop_undrawn on a chain made here, one patch: level 0 has 30 triangles (over the
 * 24 a frame draws per patch: dropped, its ε kept), levels 1 and 2 differ, level 3 is level 2's
 * mesh bit for bit with a smaller ε (dropped, level 2 takes its ε), level 4 is level 3's mesh
 * with a larger ε (dropped, level 2's ε stays). Catches: a level too fine kept, a duplicate kept,
 * a duplicate's smaller ε lost (a frame would then take a finer mesh than it may) or its larger
 * one taken, a distinct level dropped, a dropped level's ε or triangle count not kept. */
static void check_drop_rules(void)
{
    sw_lod_static_chain *c = sw__calloc(1, sizeof *c);
    if (!c || !(c->levels = sw__calloc(5, sizeof *c->levels))) {
        CHECK(0, "synthetic chain: out of memory");
        sw_lod_static_free(c);
        return;
    }
    c->n_levels = 5;
    c->n_patches = 1;
    c->delta = 0.1;
    c->levels[0] = synthetic_level(30, 0.0, 0.1);
    c->levels[1] = synthetic_level(20, 0.0, 0.3);
    c->levels[2] = synthetic_level(4, 0.5, 0.9);
    c->levels[3] = synthetic_level(4, 0.5, 0.7);
    c->levels[4] = synthetic_level(4, 0.5, 2.0);
    const size_t before = sw_lod_static_memory(c);
    const size_t freed = sw_lod_static_drop_undrawn(c);
    const sw_lod_static_level *l = c->levels;
    CHECK(l[0].n_triangles == 0 && l[0].n_vertices == 0 && l[0].n_triangles_dropped == 30 &&
              l[0].eps == 0.1,
          "level 0 (30 triangles over 1 patch): %u triangles kept, %u dropped, ε %g",
          l[0].n_triangles, l[0].n_triangles_dropped, l[0].eps);
    CHECK(l[1].n_triangles == 20 && l[1].eps == 0.3, "level 1 (distinct, drawable) changed");
    CHECK(l[2].n_triangles == 4 && l[2].eps == 0.7,
          "level 2: %u triangles, ε %g (its duplicate's smaller ε 0.7 expected)", l[2].n_triangles,
          l[2].eps);
    CHECK(l[3].n_triangles == 0 && l[3].n_triangles_dropped == 4 && l[3].eps == 0.7,
          "level 3 (level 2's mesh) kept or its ε changed");
    CHECK(l[4].n_triangles == 0 && l[4].n_triangles_dropped == 4 && l[4].eps == 2.0,
          "level 4 (level 3's mesh) kept or its ε changed");
    CHECK(before - freed == sw_lod_static_memory(c), "freed %zu of %zu bytes, %zu left", freed,
          before, sw_lod_static_memory(c));
    printf("  drop rules on a made chain: levels kept %s%s%s%s%s, %zu bytes freed\n",
           l[0].n_triangles ? "0" : "-", l[1].n_triangles ? "1" : "-", l[2].n_triangles ? "2" : "-",
           l[3].n_triangles ? "3" : "-", l[4].n_triangles ? "4" : "-", freed);
    /* every level too fine: the coarsest mesh stays, the proxies' input; a finer one goes */
    sw_lod_static_level *m = c->levels;
    for (int k = 0; k < 5; ++k)
        sw__sl_level_free(&m[k]);
    m[0] = synthetic_level(40, 0.0, 0.1);
    m[1] = synthetic_level(30, 0.5, 0.3);
    c->n_levels = 2;
    sw_lod_static_drop_undrawn(c);
    CHECK(m[0].n_triangles == 0 && m[1].n_triangles == 30,
          "levels of 40 and 30 triangles over 1 patch: %u and %u kept (0 and 30 expected: the "
          "coarsest stays for the proxies)",
          m[0].n_triangles, m[1].n_triangles);
    sw_lod_static_free(c);
}

/* Re-measures every level of every READY unit; returns the violations. */
static int check_bounds(const sw_lod_static_set *set, const sw_sg_scene *scene)
{
    int checks = 0, violations = 0;
    uint32_t dropped = 0;
    double worst_ratio = 0.0;
    for (uint32_t u = 0; u < sw_lod_static_set_unit_count(set); ++u) {
        const sw_lod_static_chain *c = sw_lod_static_set_get(set, u);
        const sw_lod_static_unit *un = sw_lod_static_set_unit(set, u);
        const sw_lod_static_patch *p = sw_lod_static_set_patches(set) + un->first_patch;
        dropped += c ? check_kept_levels(c, u) : 0;
        int32_t coarsest = c ? c->n_levels - 1 : 0;
        while (c && coarsest > 0 && c->levels[coarsest].n_triangles == 0)
            --coarsest;
        for (int32_t k = 0; c && k < c->n_levels; ++k) {
            const sw_lod_static_level *l = &c->levels[k];
            /* the coarsest mesh stays for the cluster proxies, drawable or not */
            CHECK(l->n_triangles == 0 || k == coarsest || sw_lod_static_level_drawable(c, k),
                  "unit %u level %d: %u triangles over %u patches kept, finer than a frame draws",
                  u, k, l->n_triangles, c->n_patches);
            if (l->n_triangles == 0)
                continue; /* not kept: no frame draws it */
            const sw_lod_static_measure_desc md = {4391u + (uint32_t)k, 11, 5, 1};
            sw_lod_static_distance d;
            sw_status st = {0};
            if (sw_lod_static_measure(scene, p, un->n_patches, l, &c->levels[0], c->delta, l->eps,
                                      &md, &d, &st) != SW_OK) {
                CHECK(0, "unit %u level %d: measure failed: %s", u, k, st.message);
                continue;
            }
            const double worst = fmax(d.surface_to_mesh, d.mesh_to_surface);
            worst_ratio = fmax(worst_ratio, worst / l->eps);
            checks++;
            if (!(worst <= l->eps) || d.n_surface == 0 || d.n_mesh == 0) {
                violations++;
                CHECK(0, "unit %u (%u faces) level %d: surface->mesh %.6g, mesh->surface %.6g > "
                      "eps %.6g", u, un->n_faces, k, d.surface_to_mesh, d.mesh_to_surface, l->eps);
            }
        }
    }
    printf("  bounds: %d kept levels re-measured both ways, %d violations, worst measured / ε "
           "%.3f; %u levels not kept (finer than drawn, or a duplicate)\n",
           checks, violations, worst_ratio, dropped);
    return violations;
}

static int chains_equal(const sw_lod_static_chain *a, const sw_lod_static_chain *b)
{
    if (a->n_levels != b->n_levels || a->n_patches != b->n_patches || a->delta != b->delta)
        return 0;
    for (int32_t k = 0; k < a->n_levels; ++k)
        if (a->levels[k].eps != b->levels[k].eps || !meshes_equal(&a->levels[k], &b->levels[k]))
            return 0;
    return 1;
}

static uint32_t ready_units(const sw_lod_static_set *set)
{
    sw_lod_static_set_stats st;
    sw_lod_static_set_get_stats(set, &st);
    return st.ready;
}

/* Loads data into a fresh set; returns the result, *adopted the chains it took. */
static sw_result load_fresh(const sw_sg_scene *scene, sw_th_pool *pool, const void *data,
                            size_t size, uint32_t *adopted, sw_lod_static_set **keep)
{
    sw_lod_static_set *b = NULL;
    sw_status st = {0};
    if (sw_lod_static_set_create(scene, pool, NULL, &b, &st) != SW_OK)
        return SW_ERR_INTERNAL;
    sw_result r = sw_lod_static_set_load(b, data, size, "test", adopted, &st);
    if (r == SW_OK)
        CHECK(ready_units(b) == *adopted, "load: %u ready, %u adopted", ready_units(b), *adopted);
    else
        CHECK(ready_units(b) == 0, "a refused cache left %u chains behind", ready_units(b));
    if (keep)
        *keep = b;
    else
        sw_lod_static_set_destroy(b);
    return r;
}

static void check_cache(const sw_sg_scene *scene, sw_th_pool *pool, const sw_lod_static_set *a,
                        const unsigned char *blob, size_t size)
{
    uint32_t adopted = 0;
    sw_lod_static_set *b = NULL;
    CHECK(load_fresh(scene, pool, blob, size, &adopted, &b) == SW_OK, "load of the cache failed");
    CHECK(adopted == ready_units(a), "adopted %u of %u chains", adopted, ready_units(a));
    for (uint32_t u = 0; b && u < sw_lod_static_set_unit_count(a); ++u) {
        const sw_lod_static_chain *x = sw_lod_static_set_get(a, u), *y = sw_lod_static_set_get(b, u);
        CHECK((!x && !y) || (x && y && chains_equal(x, y)), "unit %u: chain differs after load", u);
    }
    sw_lod_static_set_destroy(b);
    /* every truncation (a few hundred, spread over the string) is refused as a whole */
    unsigned char *copy = malloc(size);
    const size_t step = size / 300 + 1;
    int refused = 0, tried = 0;
    for (size_t cut = 0; cut < size; cut += step, ++tried) {
        const sw_result r = load_fresh(scene, pool, blob, cut, &adopted, NULL);
        /* inside the 24-byte header: FORMAT, VERSION or a stale key; after it: FORMAT */
        refused += cut < 24 ? r != SW_OK : r == SW_ERR_FORMAT;
    }
    CHECK(refused == tried, "%d of %d truncations refused", refused, tried);
    memcpy(copy, blob, size);
    copy[16] ^= 1u; /* the key */
    CHECK(load_fresh(scene, pool, copy, size, &adopted, NULL) == SW_ERR_INVALID_ARGUMENT,
          "a cache of another key was not refused as stale");
    memcpy(copy, blob, size);
    uint32_t huge = 0xFFFFFFF0u; /* the last triangle index of the string */
    memcpy(copy + size - 4, &huge, 4);
    CHECK(load_fresh(scene, pool, copy, size, &adopted, NULL) == SW_ERR_FORMAT,
          "a triangle index out of range was not refused");
    free(copy);
    printf("  cache of %zu bytes: reloaded equal; %d truncations, a stale key, a bad index "
           "refused\n", size, tried);
}

/* The summary against the chains themselves. */
static void check_summary(const sw_lod_static_set *a, const unsigned char *blob, size_t size)
{
    sw_lod_static_cache_summary sum, want;
    sw_status st = {0};
    memset(&want, 0, sizeof want);
    CHECK(sw_lod_static_cache_summarize(blob, size, "cache", &sum, &st) == SW_OK, "summary: %s",
          st.message);
    want.units = sw_lod_static_set_unit_count(a);
    for (uint32_t u = 0; u < want.units; ++u) {
        const sw_lod_static_chain *c = sw_lod_static_set_get(a, u);
        if (!c)
            continue;
        want.delta_min = want.chains ? fmin(want.delta_min, c->delta) : c->delta;
        want.delta_max = want.chains ? fmax(want.delta_max, c->delta) : c->delta;
        want.chains++;
        want.max_levels =
            (uint32_t)c->n_levels > want.max_levels ? (uint32_t)c->n_levels : want.max_levels;
        for (int32_t k = 0; k < c->n_levels; ++k) {
            const sw_lod_static_level *l = &c->levels[k];
            const int first = want.level_chains[k]++ == 0;
            want.level_vertices[k] += l->n_vertices;
            want.level_triangles[k] += l->n_triangles;
            want.level_eps_min[k] = first ? l->eps : fmin(want.level_eps_min[k], l->eps);
            want.level_eps_max[k] = first ? l->eps : fmax(want.level_eps_max[k], l->eps);
        }
    }
    int same = sum.units == want.units && sum.chains == want.chains &&
               sum.max_levels == want.max_levels && sum.delta_min == want.delta_min &&
               sum.delta_max == want.delta_max;
    for (uint32_t k = 0; k < want.max_levels; ++k)
        same = same && sum.level_chains[k] == want.level_chains[k] &&
               sum.level_vertices[k] == want.level_vertices[k] &&
               sum.level_triangles[k] == want.level_triangles[k] &&
               sum.level_eps_min[k] == want.level_eps_min[k] &&
               sum.level_eps_max[k] == want.level_eps_max[k];
    /* the settings it was built with: the set's resolved ones */
    const sw_lod_static_desc *lv = sw__lod_static_set_levels(a), *got = &sum.settings.levels;
    CHECK(got->delta == lv->delta && got->n_levels == lv->n_levels &&
              got->eps_first == lv->eps_first && got->eps_growth == lv->eps_growth &&
              got->max_vertices == lv->max_vertices &&
              got->max_vertices_per_patch == lv->max_vertices_per_patch &&
              sum.settings.delta_rel == (lv->delta > 0.0 ? 0.0 : SW_LOD_STATIC_DELTA_REL) &&
              sum.settings.eps_rule == SW_LOD_STATIC_EPS_RULE,
          "summary: settings δ %g (rel %g), %d levels, ε %g x %g^k, rule %g; the set's δ %g, %d, "
          "%g, %g",
          got->delta, sum.settings.delta_rel, (int)got->n_levels, got->eps_first, got->eps_growth,
          sum.settings.eps_rule, lv->delta, (int)lv->n_levels, lv->eps_first, lv->eps_growth);
    CHECK(same && want.chains > 0 && want.max_levels > 1,
          "summary: %u chains, %u levels, level 0 %llu triangles; the chains: %u, %u, %llu",
          sum.chains, sum.max_levels, (unsigned long long)sum.level_triangles[0], want.chains,
          want.max_levels, (unsigned long long)want.level_triangles[0]);
    const size_t step = size / 300 + 1;
    int refused = 0, tried = 0;
    for (size_t cut = 0; cut < size; cut += step, ++tried) {
        const sw_result r = sw_lod_static_cache_summarize(blob, cut, "cache", &sum, &st);
        refused += r == SW_ERR_FORMAT || r == SW_ERR_VERSION;
    }
    CHECK(refused == tried, "summary: %d of %d truncations refused", refused, tried);
    printf("  summary: %u chains, %u levels, level 0 %llu triangles, as the chains; %d "
           "truncations refused\n",
           want.chains, want.max_levels, (unsigned long long)want.level_triangles[0], tried);
}

static void check_file(sw_sg_scene *scene, const void *blob, size_t size, const char *dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/cache.sws", dir);
    sw_status st = {0};
    CHECK(sw_sg_scene_save_lods(scene, path, blob, size, &st) == SW_OK, "save: %s", st.message);
    sw_sg_scene *back = NULL;
    const void *data = NULL;
    size_t n = 0;
    CHECK(sw_sg_scene_open(path, &back, &st) == SW_OK, "reopen: %s", st.message);
    if (!back)
        return;
    CHECK(sw_sg_scene_require(back, SW_SG_SEC_ALL, &st) == SW_OK, "require: %s", st.message);
    CHECK(sw_sg_scene_lods(back, &data, &n, &st) == SW_OK && n == size &&
              memcmp(data, blob, size) == 0,
          "LODS section not read back as written");
    CHECK(sw_sg_scene_view_ptr(back)->n_faces == sw_sg_scene_view_ptr(scene)->n_faces,
          "faces changed");
    /* saving the reopened scene keeps its LODS section */
    char path2[4096];
    snprintf(path2, sizeof path2, "%s/cache2.sws", dir);
    CHECK(sw_sg_scene_save(back, path2, &st) == SW_OK, "resave: %s", st.message);
    sw_sg_scene_free(back);
    sw_sg_scene *again = NULL;
    CHECK(sw_sg_scene_open(path2, &again, &st) == SW_OK &&
              sw_sg_scene_lods(again, &data, &n, &st) == SW_OK && n == size,
          "sw_sg_scene_save dropped the LODS section");
    sw_sg_scene_free(again);
    /* a flipped byte in the LODS section (the file's last bytes): checksum error, scene fine */
    FILE *fp = fopen(path, "r+b");
    if (fp && fseek(fp, -5, SEEK_END) == 0) {
        int c = fgetc(fp);
        fseek(fp, -5, SEEK_END);
        fputc(c ^ 0x40, fp);
    }
    if (fp)
        fclose(fp);
    CHECK(sw_sg_scene_open(path, &back, &st) == SW_OK, "reopen damaged: %s", st.message);
    if (back) {
        CHECK(sw_sg_scene_require(back, SW_SG_SEC_ALL, &st) == SW_OK,
              "a damaged LODS section broke the scene: %s", st.message);
        CHECK(sw_sg_scene_lods(back, &data, &n, &st) == SW_ERR_CHECKSUM,
              "a damaged LODS section was not reported");
        printf("  damaged LODS section: %s\n", st.message);
        sw_sg_scene_free(back);
    }
}

/* Resident KiB of the mapping holding p (/proc/self/smaps), -1 when not found. */
static long mapping_rss_kib(const void *p)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return -1;
    char line[512];
    int inside = 0;
    long kib = -1;
    const uintptr_t at = (uintptr_t)p;
    while (kib < 0 && fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' '))
            inside = at >= lo && at < hi;
        else if (inside && sscanf(line, "Rss: %ld kB", &kib) == 1)
            break;
    }
    fclose(f);
    return kib;
}

/* The LODS section's pages are handed back once read (a 10^6-surface cache is hundreds of MiB
 * that its reader copies out at once): after the checksum pass and after
 * sw_sg_scene_lods_release the mapping holds a few pages, and the bytes still read back. Catches
 * the section's pages kept in memory beside the decoded cache. */
static void check_pages_released(sw_sg_scene *scene, const char *dir)
{
    enum { BLOB = 24u << 20 };
    unsigned char *blob = malloc(BLOB);
    if (!blob)
        return;
    for (size_t i = 0; i < BLOB; ++i)
        blob[i] = (unsigned char)(i * 2654435761u >> 24);
    char path[4096];
    snprintf(path, sizeof path, "%s/pages.sws", dir);
    sw_status st = {0};
    sw_sg_scene *back = NULL;
    const void *data = NULL;
    size_t n = 0;
    CHECK(sw_sg_scene_save_lods(scene, path, blob, BLOB, &st) == SW_OK &&
              sw_sg_scene_open(path, &back, &st) == SW_OK &&
              sw_sg_scene_lods(back, &data, &n, &st) == SW_OK && n == BLOB,
          "a 24 MiB LODS section: %s", st.message);
    if (data) {
        const long after_sum = mapping_rss_kib(data);
        const int same = memcmp(data, blob, BLOB) == 0;
        const long read = mapping_rss_kib(data);
        sw_sg_scene_lods_release(back);
        const long released = mapping_rss_kib(data);
        const int same_again = memcmp(data, blob, BLOB) == 0;
        printf("  24 MiB LODS section mapped: %ld KiB resident after the checksum, %ld read, %ld "
               "released\n",
               after_sum, read, released);
        CHECK(same && same_again, "the LODS bytes changed across a release");
        CHECK(read >= (long)(BLOB >> 10) && after_sum >= 0 && after_sum < 4096 && released >= 0 &&
                  released < 4096,
              "LODS pages kept: %ld KiB after the checksum, %ld after the release", after_sum,
              released);
    }
    sw_sg_scene_free(back);
    free(blob);
}

int main(int argc, char **argv)
{
    (void)sw_lod_build_install(); /* static LODs are built by the LOD-building module */
    if (argc != 3) {
        fprintf(stderr, "usage: %s MODEL WORKDIR\n", argv[0]);
        return 2;
    }
    sw_sg_scene *scene = NULL;
    if (sw_test_import_model(argv[1], &scene) != 1)
        return 1;
    sw_status st = {0};
    sw_th_pool *pool = NULL;
    sw_lod_static_set *a = NULL;
    if (sw_sg_scene_require(scene, SW_SG_SEC_ALL, &st) != SW_OK ||
        sw_th_pool_create(NULL, &pool) != SW_OK ||
        sw_lod_static_set_create(scene, pool, NULL, &a, &st) != SW_OK) {
        printf("FAIL: set up: %s\n", st.message);
        return 1;
    }
    const uint32_t n = sw_lod_static_set_unit_count(a);
    for (uint32_t u = 0; u < n; ++u)
        sw_lod_static_set_request(a, u, SW_TH_PRIORITY_FRAME);
    for (uint32_t u = 0; u < n; ++u)
        CHECK(sw_lod_static_set_wait(a, u) == SW_LOD_STATIC_READY, "unit %u not built", u);
    printf("%s:\n", argv[1]);
    check_units(a, scene);
    check_bounds(a, scene);
    void *blob = NULL;
    size_t size = 0;
    CHECK(sw_lod_static_set_serialize(a, &blob, &size, &st) == SW_OK, "serialize: %s", st.message);
    if (blob) {
        check_cache(scene, pool, a, blob, size);
        check_summary(a, blob, size);
        check_file(scene, blob, size, argv[2]);
    }
    check_pages_released(scene, argv[2]);
    check_drop_rules();
    free(blob);
    sw_lod_static_set_destroy(a);
    sw_th_pool_destroy(pool);
    sw_sg_scene_free(scene);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures != 0;
}

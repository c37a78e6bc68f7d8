/* SPDX-License-Identifier: MIT */
/* The static-LOD cache: a set's READY chains as one byte string and back (the layout is in
 * lod/static/sw_lod_static_set.h). Reading trusts nothing: every count is checked against the bytes
 * left before anything is allocated, every value against what a chain may hold, and the whole
 * string is parsed into new chains before the first one is adopted. */
#include "sw_lod_static_set.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LODS_MAGIC "SWLODS\0"
#define LODS_VERSION 3u     /* 2: the level settings after the key; 3: the proxies at the end */
#define LODS_OLDEST_READ 2u /* version 2 is read as a cache without proxies */
#define LODS_MAX_LEVELS SW_LOD_CACHE_MAX_LEVELS

/* ---- the key ----------------------------------------------------------------------------------
 */

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/* The units' faces and patches, and the level settings the set builds with (resolved: a change
 * of a default, SW_LOD_STATIC_DELTA_REL included, makes older caches stale). */
static uint64_t set_key(const sw_lod_static_set *set, const sw_lod_static_desc *levels)
{
    uint64_t h = 1469598103934665603ull;
    const uint32_t n = sw_lod_static_set_unit_count(set);
    h = fnv(h, &n, sizeof n);
    const uint32_t *faces = sw_lod_static_set_faces(set);
    const sw_lod_static_patch *patches = sw_lod_static_set_patches(set);
    for (uint32_t u = 0; u < n; ++u) {
        const sw_lod_static_unit *un = sw_lod_static_set_unit(set, u);
        h = fnv(h, &un->n_faces, sizeof un->n_faces);
        h = fnv(h, faces + un->first_face, un->n_faces * sizeof *faces);
        for (uint32_t k = 0; k < un->n_patches; ++k) {
            const sw_lod_static_patch *p = &patches[un->first_patch + k];
            const uint32_t rec[3] = {p->face, p->iu, p->iv};
            h = fnv(h, rec, sizeof rec);
        }
    }
    const double d[5] = {levels->delta, levels->eps_first, levels->eps_growth,
                         SW_LOD_STATIC_EPS_RULE,
                         levels->delta > 0.0 ? 0.0 : SW_LOD_STATIC_DELTA_REL};
    const int32_t i[3] = {levels->n_levels, (int32_t)levels->max_vertices,
                          (int32_t)levels->max_vertices_per_patch};
    h = fnv(h, d, sizeof d);
    return fnv(h, i, sizeof i);
}

/* ---- writing ----------------------------------------------------------------------------------
 */

typedef struct writer {
    unsigned char *p;
    size_t n, cap;
    int oom;
} writer;

static void put(writer *w, const void *data, size_t n)
{
    if (w->oom || n == 0)
        return; /* n == 0: data may be NULL (an empty level's arrays) */
    if (w->n + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->n + n)
            cap *= 2;
        unsigned char *g = sw__realloc(w->p, cap);
        if (!g) {
            w->oom = 1;
            return;
        }
        w->p = g;
        w->cap = cap;
    }
    memcpy(w->p + w->n, data, n);
    w->n += n;
}

static void put_u32(writer *w, uint32_t x)
{
    put(w, &x, sizeof x);
}

static void put_level(writer *w, const sw_lod_static_level *l)
{
    put_u32(w, l->n_vertices);
    put_u32(w, l->n_triangles);
    const double d[4] = {l->eps, l->eps_target, l->bound[0], l->bound[1]};
    put(w, d, sizeof d);
    put(w, l->positions, (size_t)l->n_vertices * 3 * sizeof *l->positions);
    put(w, l->normals, (size_t)l->n_vertices * 3 * sizeof *l->normals);
    put(w, l->uv, (size_t)l->n_vertices * 2 * sizeof *l->uv);
    put(w, l->face, (size_t)l->n_vertices * sizeof *l->face);
    put(w, l->triangles, (size_t)l->n_triangles * 3 * sizeof *l->triangles);
}

/* The level settings the set was built with (resolved), so that a reader can say how. */
static void put_settings(writer *w, const sw_lod_static_desc *d)
{
    const double f[5] = {d->delta, d->delta > 0.0 ? 0.0 : SW_LOD_STATIC_DELTA_REL, d->eps_first,
                         d->eps_growth, SW_LOD_STATIC_EPS_RULE};
    const int32_t n_levels = d->n_levels;
    put(w, f, sizeof f);
    put(w, &n_levels, sizeof n_levels);
    put_u32(w, d->max_vertices);
    put_u32(w, d->max_vertices_per_patch);
}

/* Positions as their codes within +-range (rounded so by their builder: exact). */
static void put_positions(writer *w, const double *v, size_t n_vertices, const double range[3])
{
    uint16_t buf[3 * 512];
    for (size_t at = 0; at < n_vertices; at += 512) {
        const size_t m = n_vertices - at < 512 ? n_vertices - at : 512;
        for (size_t i = 0; i < 3 * m; ++i)
            buf[i] = sw__lod_proxy_coord_pack(v[3 * at + i], range[i % 3]);
        put(w, buf, 3 * m * sizeof *buf);
    }
}

/* Normals as their octahedral codes (a proxy's are rounded so by its builder: exact). */
static void put_normals(writer *w, const float *n, size_t count)
{
    int16_t buf[2 * 512];
    for (size_t at = 0; at < count; at += 512) {
        const size_t m = count - at < 512 ? count - at : 512;
        for (size_t i = 0; i < m; ++i)
            sw__lod_proxy_normal_pack(n + 3 * (at + i), buf + 2 * i);
        put(w, buf, 2 * m * sizeof *buf);
    }
}

/* Triangle indices, u16 when every index fits (a part of at most 65536 vertices). */
static void put_indices(writer *w, const uint32_t *t, size_t count, uint32_t n_vertices)
{
    if (n_vertices > 65536) {
        put(w, t, count * sizeof *t);
        return;
    }
    uint16_t buf[1024];
    for (size_t at = 0; at < count; at += 1024) {
        const size_t m = count - at < 1024 ? count - at : 1024;
        for (size_t i = 0; i < m; ++i)
            buf[i] = (uint16_t)t[at + i];
        put(w, buf, m * sizeof *buf);
    }
}

static void put_proxy(writer *w, uint32_t node, const sw_lod_proxy *x)
{
    put_u32(w, node);
    const double d[6] = {x->err, x->input_err, x->cell, x->range[0], x->range[1], x->range[2]};
    put(w, d, sizeof d);
    put_u32(w, x->instances);
    const uint64_t c[3] = {x->faces, x->input_triangles, x->vanished};
    put(w, c, sizeof c);
    put_u32(w, x->n_parts);
    for (uint32_t k = 0; k < x->n_parts; ++k) {
        const sw_lod_static_level *l = &x->parts[k];
        put(w, x->colors[k], sizeof x->colors[k]);
        put_u32(w, l->n_vertices);
        put_u32(w, l->n_triangles);
        put_positions(w, l->positions, l->n_vertices, x->range);
        put_normals(w, l->normals, l->n_vertices);
        put_indices(w, l->triangles, 3 * (size_t)l->n_triangles, l->n_vertices);
    }
}

/* The proxies once every build has finished (none while some are still being built). */
static void put_proxies(writer *w, const sw_lod_static_set *set)
{
    if (!sw_lod_static_set_proxies_done(set)) {
        put_u32(w, 0);
        return;
    }
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(set)->bvh;
    sw_lod_static_set_stats ss;
    sw_lod_static_set_get_stats(set, &ss);
    uint32_t n = 0;
    for (uint32_t node = 0; node < bvh->n_nodes; ++node)
        n += sw_lod_static_set_proxy(set, node) != NULL;
    put_u32(w, 1);
    put_u32(w, sw__lod_proxies_key(set));
    put_u32(w, bvh->n_nodes);
    put_u32(w, n);
    const uint64_t c[2] = {ss.proxies_failed, ss.proxies_pruned};
    put(w, c, sizeof c);
    for (uint32_t node = 0; node < bvh->n_nodes; ++node) {
        const sw_lod_proxy *x = sw_lod_static_set_proxy(set, node);
        if (x)
            put_proxy(w, node, x);
    }
}

sw_result sw_lod_static_set_serialize(const sw_lod_static_set *set, void **out, size_t *size,
                                      sw_status *status)
{
    *out = NULL;
    *size = 0;
    writer w = {0};
    const uint32_t n = sw_lod_static_set_unit_count(set);
    put(&w, LODS_MAGIC, 8);
    put_u32(&w, LODS_VERSION);
    put_u32(&w, n);
    const uint64_t key = set_key(set, sw__lod_static_set_levels(set));
    put(&w, &key, sizeof key);
    put_settings(&w, sw__lod_static_set_levels(set));
    for (uint32_t u = 0; u < n; ++u) {
        const sw_lod_static_chain *c = sw_lod_static_set_get(set, u);
        put_u32(&w, c ? 1u : 0u);
        if (!c)
            continue;
        put(&w, &c->n_levels, sizeof c->n_levels);
        put_u32(&w, c->n_patches);
        put(&w, &c->delta, sizeof c->delta);
        for (int32_t k = 0; k < c->n_levels; ++k)
            put_level(&w, &c->levels[k]);
    }
    put_proxies(&w, set);
    if (w.oom) {
        sw__free(w.p);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LOD cache: out of memory");
    }
    *out = w.p;
    *size = w.n;
    return SW_OK;
}

/* ---- reading ----------------------------------------------------------------------------------
 */

typedef struct reader {
    const unsigned char *p;
    size_t n, at;
    const char *what;
    sw_status *status;
} reader;

static int take(reader *r, void *out, size_t n)
{
    if (n > r->n - r->at)
        return 0;
    memcpy(out, r->p + r->at, n);
    r->at += n;
    return 1;
}

static sw_result bad(reader *r, const char *fmt, const char *detail)
{
    return sw__fail(r->status, SW_ERR_FORMAT, "%s: LODS offset %zu: %s%s", r->what, r->at, fmt,
                    detail ? detail : "");
}

/* An array of count elements of elem bytes, checked against the bytes left first. */
static void *take_array(reader *r, uint64_t count, size_t elem)
{
    if (count > (r->n - r->at) / elem)
        return NULL;
    void *a = sw__malloc(count ? (size_t)count * elem : 1);
    if (a)
        take(r, a, (size_t)count * elem);
    return a;
}

static int finite_all(const double *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static int finite_all_f(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Whether `face` is one of the unit's faces (sorted ascending: units list faces in order). */
static int unit_has_face(const sw_lod_static_set *set, const sw_lod_static_unit *un, uint32_t face)
{
    const uint32_t *f = sw_lod_static_set_faces(set) + un->first_face;
    uint32_t lo = 0, hi = un->n_faces;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (f[mid] < face)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < un->n_faces && f[lo] == face;
}

static sw_result take_settings(reader *r, sw_lod_static_cache_settings *out)
{
    double f[5];
    int32_t n_levels;
    uint32_t max_v, max_vp;
    if (!take(r, f, sizeof f) || !take(r, &n_levels, 4) || !take(r, &max_v, 4) ||
        !take(r, &max_vp, 4))
        return bad(r, "truncated level settings", NULL);
    if (!finite_all(f, 5) || !(f[0] >= 0.0) || !(f[0] > 0.0 || f[1] > 0.0) || !(f[2] > 1.0) ||
        !(f[3] > 1.0) || !(f[4] > 0.0) || n_levels < -1 || n_levels > LODS_MAX_LEVELS - 1)
        return bad(r, "level settings out of range", NULL);
    *out = (sw_lod_static_cache_settings){{.delta = f[0],
                                           .n_levels = n_levels,
                                           .eps_first = f[2],
                                           .eps_growth = f[3],
                                           .max_vertices = max_v,
                                           .max_vertices_per_patch = max_vp},
                                          f[1],
                                          f[4]};
    return SW_OK;
}

static sw_result read_level(reader *r, const sw_lod_static_set *set, const sw_lod_static_unit *un,
                            sw_lod_static_level *l)
{
    double d[4];
    if (!take(r, &l->n_vertices, 4) || !take(r, &l->n_triangles, 4) || !take(r, d, sizeof d))
        return bad(r, "truncated level header", NULL);
    l->eps = d[0], l->eps_target = d[1], l->bound[0] = d[2], l->bound[1] = d[3];
    if (!finite_all(d, 4) || !(l->eps >= 0.0))
        return bad(r, "a level's ε is not a finite non-negative number", NULL);
    const uint64_t nv = l->n_vertices, nt = l->n_triangles;
    if (nv == 0 && nt == 0)
        return SW_OK; /* a level not stored (no frame draws it): its ε alone */
    if (!(l->positions = take_array(r, 3 * nv, sizeof *l->positions)) ||
        !(l->normals = take_array(r, 3 * nv, sizeof *l->normals)) ||
        !(l->uv = take_array(r, 2 * nv, sizeof *l->uv)) ||
        !(l->face = take_array(r, nv, sizeof *l->face)) ||
        !(l->triangles = take_array(r, 3 * nt, sizeof *l->triangles)))
        return bad(r, "a level's arrays run past the end (or out of memory)", NULL);
    if (!finite_all(l->positions, 3 * nv) || !finite_all_f(l->normals, 3 * nv) ||
        !finite_all(l->uv, 2 * nv))
        return bad(r, "a vertex with a non-finite coordinate", NULL);
    for (uint64_t t = 0; t < 3 * nt; ++t)
        if (l->triangles[t] >= nv)
            return bad(r, "a triangle names a vertex out of range", NULL);
    for (uint64_t v = 0; v < nv; ++v)
        if (!unit_has_face(set, un, l->face[v]))
            return bad(r, "a vertex on a face outside its super-surface", NULL);
    return SW_OK;
}

static sw_result read_chain(reader *r, const sw_lod_static_set *set, uint32_t unit,
                            sw_lod_static_chain **out)
{
    sw_lod_static_chain *c = sw__calloc(1, sizeof *c);
    if (!c)
        return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
    *out = c;
    int32_t n_levels;
    if (!take(r, &n_levels, 4) || !take(r, &c->n_patches, 4) || !take(r, &c->delta, 8))
        return bad(r, "truncated chain header", NULL);
    const sw_lod_static_unit *un = sw_lod_static_set_unit(set, unit);
    if (n_levels < 1 || n_levels > LODS_MAX_LEVELS || c->n_patches != un->n_patches ||
        !(c->delta > 0.0) || !isfinite(c->delta))
        return bad(r, "a chain's level count, patch count or δ does not fit its super-surface",
                   NULL);
    if (!(c->levels = sw__calloc((size_t)n_levels, sizeof *c->levels)))
        return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
    for (int32_t k = 0; k < n_levels; ++k) {
        c->n_levels = k + 1; /* what sw_lod_static_free frees */
        sw_result res = read_level(r, set, un, &c->levels[k]);
        if (res != SW_OK)
            return res;
    }
    sw__lod_static_set_trim(set, c); /* now, not at adoption: a cache written before levels
                                        were dropped is not held whole while it is parsed */
    return SW_OK;
}

/* count triangle indices of a part of nv vertices (u16 when nv <= 65536), as u32. */
static uint32_t *take_indices(reader *r, uint64_t count, uint64_t nv)
{
    if (nv > 65536)
        return take_array(r, count, sizeof(uint32_t));
    uint16_t *s = take_array(r, count, sizeof *s);
    uint32_t *t = s ? sw__malloc((size_t)(count ? count : 1) * sizeof *t) : NULL;
    for (uint64_t i = 0; t && i < count; ++i)
        t[i] = s[i];
    sw__free(s);
    return t;
}

/* Positions stored as codes within the proxy's range, back to double. */
static sw_result read_positions(reader *r, const double range[3], sw_lod_static_level *l)
{
    const uint64_t n = 3 * (uint64_t)l->n_vertices;
    uint16_t *q = take_array(r, n, sizeof *q);
    if (q)
        l->positions = sw__malloc((size_t)(n ? n : 1) * sizeof *l->positions);
    if (!q || !l->positions) {
        sw__free(q);
        return bad(r, "a proxy's positions run past the end (or out of memory)", NULL);
    }
    int ok = 1;
    for (uint64_t i = 0; i < n; ++i) {
        l->positions[i] = sw__lod_proxy_coord_unpack(q[i], range[i % 3]);
        ok &= isfinite(l->positions[i]);
    }
    sw__free(q);
    return ok ? SW_OK : bad(r, "a proxy position is not finite", NULL);
}

static sw_result read_part(reader *r, sw_lod_proxy *x, uint32_t k)
{
    sw_lod_static_level *l = &x->parts[k];
    if (!take(r, x->colors[k], sizeof x->colors[k]) || !take(r, &l->n_vertices, 4) ||
        !take(r, &l->n_triangles, 4))
        return bad(r, "truncated proxy part", NULL);
    if (!finite_all_f(x->colors[k], 4) || l->n_vertices == 0 || l->n_triangles == 0)
        return bad(r, "a proxy part with a non-finite colour or no triangle", NULL);
    sw_result res = read_positions(r, x->range, l);
    if (res != SW_OK)
        return res;
    const uint64_t nv = l->n_vertices, nt = l->n_triangles;
    int16_t *codes = take_array(r, 2 * nv, sizeof *codes);
    if (codes)
        l->normals = sw__malloc((size_t)nv * 3 * sizeof *l->normals);
    for (uint64_t v = 0; l->normals && v < nv; ++v)
        sw__lod_proxy_normal_unpack(codes + 2 * v, l->normals + 3 * v);
    sw__free(codes);
    if (!l->normals || !(l->triangles = take_indices(r, 3 * nt, nv)))
        return bad(r, "a proxy's arrays run past the end (or out of memory)", NULL);
    for (uint64_t t = 0; t < 3 * nt; ++t)
        if (l->triangles[t] >= nv)
            return bad(r, "a proxy triangle names a vertex out of range", NULL);
    x->n_triangles += l->n_triangles;
    return SW_OK;
}

/* One proxy after its node (checked by the caller): header, parts, centre from the node's box. */
static sw_result read_proxy(reader *r, const sw_sg_bvh *bvh, uint32_t node, sw_lod_proxy *x)
{
    double d[6];
    uint64_t c[3];
    uint32_t n_parts;
    if (!take(r, d, sizeof d) || !take(r, &x->instances, 4) || !take(r, c, sizeof c) ||
        !take(r, &n_parts, 4))
        return bad(r, "truncated proxy header", NULL);
    x->err = d[0], x->input_err = d[1], x->cell = d[2];
    x->faces = c[0], x->input_triangles = c[1], x->vanished = c[2];
    if (!finite_all(d, 6) || !(x->input_err >= 0.0) || !(x->err >= x->input_err) ||
        !(x->cell > 0.0) || x->instances > bvh->nodes[node].count || n_parts == 0 ||
        n_parts > (r->n - r->at) / 24)
        return bad(r, "a proxy's bound, cell, instance or part count is out of range", NULL);
    x->parts = sw__calloc(n_parts, sizeof *x->parts);
    x->colors = sw__calloc(n_parts, sizeof *x->colors);
    if (!x->parts || !x->colors)
        return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
    /* the vertices lie within ±range of the centre, which lies within the node's box grown by
       the bound (a proxy is within it of the surfaces the box holds) */
    double box[6];
    sw_sg_bvh_node_box(bvh, node, box);
    sw__lod_proxy_centre(box, x->centre);
    for (int k = 0; k < 3; ++k) {
        x->range[k] = d[3 + k];
        const double reach = 0.5 * (box[3 + k] - box[k]) + x->err;
        if (!(x->range[k] >= 0.0) || !isfinite(reach) || x->range[k] > reach * (1.0 + 1e-9))
            return bad(r, "a proxy's vertices reach outside its node's box", NULL);
    }
    for (uint32_t k = 0; k < n_parts; ++k) {
        x->n_parts = k + 1; /* what sw__lod_proxy_free frees */
        sw_result res = read_part(r, x, k);
        if (res != SW_OK)
            return res;
    }
    if (!sw__lod_proxy_find_lines(x))
        return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
    return SW_OK;
}

static void free_proxies(sw_lod_proxy **by_node, uint32_t n)
{
    if (!by_node)
        return;
    for (uint32_t i = 0; i < n; ++i)
        sw__lod_proxy_free(by_node[i]);
    sw__free(by_node);
}

/* The flag and header in front of the proxies (has 0: none stored, the rest unset). */
typedef struct proxies_header {
    uint32_t has, key, n_nodes, n;
    uint64_t failed, pruned;
} proxies_header;

static sw_result take_proxies_header(reader *r, proxies_header *h)
{
    memset(h, 0, sizeof *h);
    if (!take(r, &h->has, 4) || h->has > 1)
        return bad(r, "the proxies' flag is not 0 or 1", NULL);
    if (!h->has)
        return SW_OK;
    if (!take(r, &h->key, 4) || !take(r, &h->n_nodes, 4) || !take(r, &h->n, 4) ||
        !take(r, &h->failed, 8) || !take(r, &h->pruned, 8))
        return bad(r, "truncated proxies header", NULL);
    if (h->n > h->n_nodes)
        return bad(r, "more proxies than nodes", NULL);
    return SW_OK;
}

/* The proxies after the chains: *by_node (one per BVH node) when stored, current and wanted; NULL
 * when none are stored, they are stale (another BVH, other instances) or the set ignores them:
 * then the rest of the string is not read. */
static sw_result read_proxies(reader *r, const sw_lod_static_set *set, sw_lod_proxy ***by_node,
                              uint64_t *failed, uint64_t *pruned)
{
    *by_node = NULL;
    proxies_header h;
    sw_result res = take_proxies_header(r, &h);
    if (res != SW_OK || !h.has)
        return res;
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(set)->bvh;
    if (h.n_nodes != bvh->n_nodes || h.key != sw__lod_proxies_key(set) ||
        sw__lod_static_set_ignores_cached_proxies(set)) {
        r->at = r->n; /* stale or not wanted: built again */
        return SW_OK;
    }
    if (!(*by_node = sw__calloc(h.n_nodes ? h.n_nodes : 1, sizeof **by_node)))
        return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
    *failed = h.failed;
    *pruned = h.pruned;
    int64_t last = -1;
    for (uint32_t i = 0; i < h.n; ++i) {
        uint32_t node;
        if (!take(r, &node, 4))
            return bad(r, "truncated proxy", NULL);
        if ((int64_t)node <= last || !sw__lod_proxy_candidate(set, node))
            return bad(r, "a proxy's node is out of order or has too few instances", NULL);
        last = node;
        sw_lod_proxy *x = (*by_node)[node] = sw__calloc(1, sizeof *x);
        if (!x)
            return sw__fail(r->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", r->what);
        res = read_proxy(r, bvh, node, x);
        if (res != SW_OK)
            return res;
    }
    return SW_OK;
}

static void free_chains(sw_lod_static_chain **chains, uint32_t n)
{
    for (uint32_t u = 0; u < n; ++u)
        sw_lod_static_free(chains[u]);
    sw__free(chains);
}

sw_result sw_lod_static_set_load(sw_lod_static_set *set, const void *data, size_t size,
                                 const char *what, uint32_t *adopted, sw_status *status)
{
    if (adopted)
        *adopted = 0;
    reader r = {data, size, 0, what, status};
    char magic[8];
    uint32_t version = 0, n = 0;
    uint64_t key = 0;
    if (!take(&r, magic, 8) || memcmp(magic, LODS_MAGIC, 8) != 0)
        return bad(&r, "not a static LOD cache (bad magic)", NULL);
    if (!take(&r, &version, 4) || version < LODS_OLDEST_READ || version > LODS_VERSION)
        return sw__fail(status, SW_ERR_VERSION,
                        "%s: LODS offset 8: cache version %u, this program reads %u to %u: run "
                        "`splinewalk build-lod` again",
                        what, version, LODS_OLDEST_READ, LODS_VERSION);
    sw_lod_static_cache_settings settings;
    if (!take(&r, &n, 4) || !take(&r, &key, 8))
        return bad(&r, "truncated header", NULL);
    sw_result head = take_settings(&r, &settings);
    if (head != SW_OK)
        return head;
    if (n != sw_lod_static_set_unit_count(set) ||
        key != set_key(set, sw__lod_static_set_levels(set)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "%s: the static LOD cache was made for other super-surfaces or settings "
                        "(%u units, this scene has %u): run `splinewalk build-lod` again",
                        what, n, sw_lod_static_set_unit_count(set));
    sw_lod_static_chain **chains = sw__calloc(n ? n : 1, sizeof *chains);
    if (!chains)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    sw_result res = SW_OK;
    for (uint32_t u = 0; u < n && res == SW_OK; ++u) {
        uint32_t has;
        if (!take(&r, &has, 4) || has > 1)
            res = bad(&r, "a unit's chain flag is not 0 or 1", NULL);
        else if (has)
            res = read_chain(&r, set, u, &chains[u]);
    }
    sw_lod_proxy **proxies = NULL;
    uint64_t failed = 0, pruned = 0; /* the build's counts, kept for a later write */
    if (res == SW_OK && version >= 3)
        res = read_proxies(&r, set, &proxies, &failed, &pruned);
    const uint32_t n_nodes = sw_lod_static_set_instances(set)->bvh->n_nodes;
    if (res == SW_OK && r.at != r.n)
        res = bad(&r, version >= 3 ? "bytes after the last proxy" : "bytes after the last chain",
                  NULL);
    if (res != SW_OK) {
        free_chains(chains, n);
        free_proxies(proxies, n_nodes);
        return res;
    }
    for (uint32_t u = 0; u < n; ++u) {
        /* adopt owns the chain whatever the result (a unit built meanwhile keeps its own) */
        if (chains[u] && sw_lod_static_set_adopt(set, u, chains[u]) == SW_OK && adopted)
            (*adopted)++;
        chains[u] = NULL;
    }
    sw__free(chains);
    /* refused when proxies were started before (built here): those stay, these go */
    if (proxies)
        (void)sw__lod_static_set_adopt_proxies(set, proxies, failed, pruned);
    free_proxies(proxies, n_nodes);
    return SW_OK;
}

/* Skips count elements of elem bytes; 0 when they run past the end. */
static int skip(reader *r, uint64_t count, size_t elem)
{
    if (count > (r->n - r->at) / elem)
        return 0;
    r->at += (size_t)count * elem;
    return 1;
}

/* One level's header into the summary, its arrays skipped. */
static sw_result summarize_level(reader *r, int32_t k, sw_lod_static_cache_summary *out)
{
    uint32_t nv, nt;
    double d[4];
    if (!take(r, &nv, 4) || !take(r, &nt, 4) || !take(r, d, sizeof d))
        return bad(r, "truncated level header", NULL);
    if (!finite_all(d, 4) || !(d[0] >= 0.0))
        return bad(r, "a level's ε is not a finite non-negative number", NULL);
    if (!skip(r, nv, SW_LOD_STATIC_VERTEX_BYTES) || !skip(r, nt, SW_LOD_STATIC_TRIANGLE_BYTES))
        return bad(r, "a level's arrays run past the end", NULL);
    out->level_dropped[k] += nv == 0 && nt == 0;
    const int first = out->level_chains[k]++ == 0;
    out->level_vertices[k] += nv;
    out->level_triangles[k] += nt;
    out->level_eps_min[k] = first ? d[0] : fmin(out->level_eps_min[k], d[0]);
    out->level_eps_max[k] = first ? d[0] : fmax(out->level_eps_max[k], d[0]);
    return SW_OK;
}

static sw_result summarize_chain(reader *r, sw_lod_static_cache_summary *out)
{
    int32_t n_levels;
    uint32_t patches;
    double delta;
    if (!take(r, &n_levels, 4) || !take(r, &patches, 4) || !take(r, &delta, 8))
        return bad(r, "truncated chain header", NULL);
    if (n_levels < 1 || n_levels > LODS_MAX_LEVELS || !(delta > 0.0) || !isfinite(delta))
        return bad(r, "a chain's level count or δ is out of range", NULL);
    out->delta_min = out->chains ? fmin(out->delta_min, delta) : delta;
    out->delta_max = out->chains ? fmax(out->delta_max, delta) : delta;
    out->chains++;
    out->max_levels = (uint32_t)n_levels > out->max_levels ? (uint32_t)n_levels : out->max_levels;
    sw_result res = SW_OK;
    for (int32_t k = 0; k < n_levels && res == SW_OK; ++k)
        res = summarize_level(r, k, out);
    return res;
}

/* The proxies after the chains into the summary, their arrays skipped. */
static sw_result summarize_proxies(reader *r, sw_lod_static_cache_summary *out)
{
    const size_t start = r->at;
    proxies_header h;
    sw_result res = take_proxies_header(r, &h);
    if (res != SW_OK || !h.has)
        return res;
    for (uint32_t i = 0; i < h.n; ++i) {
        uint32_t node, instances, n_parts;
        double d[6];
        uint64_t c[3];
        if (!take(r, &node, 4) || !take(r, d, sizeof d) || !take(r, &instances, 4) ||
            !take(r, c, sizeof c) || !take(r, &n_parts, 4))
            return bad(r, "truncated proxy header", NULL);
        if (!finite_all(d, 6) || !(d[0] >= 0.0))
            return bad(r, "a proxy's bound is not a finite non-negative number", NULL);
        out->proxy_err_min = i ? fmin(out->proxy_err_min, d[0]) : d[0];
        out->proxy_err_max = i ? fmax(out->proxy_err_max, d[0]) : d[0];
        out->proxy_instances = instances > out->proxy_instances ? instances : out->proxy_instances;
        for (uint32_t k = 0; k < n_parts; ++k) {
            float color[4];
            uint32_t nv, nt;
            if (!take(r, color, sizeof color) || !take(r, &nv, 4) || !take(r, &nt, 4))
                return bad(r, "truncated proxy part", NULL);
            if (!skip(r, nv, 3 * sizeof(uint16_t) + 2 * sizeof(int16_t)) ||
                !skip(r, nt, 3 * (nv > 65536 ? sizeof(uint32_t) : sizeof(uint16_t))))
                return bad(r, "a proxy's arrays run past the end", NULL);
            out->proxy_vertices += nv;
            out->proxy_triangles += nt;
        }
    }
    out->proxies = h.n;
    out->proxy_bytes = r->at - start;
    return SW_OK;
}

sw_result sw_lod_static_cache_summarize(const void *data, size_t size, const char *what,
                                        sw_lod_static_cache_summary *out, sw_status *status)
{
    memset(out, 0, sizeof *out);
    reader r = {data, size, 0, what, status};
    char magic[8];
    if (!take(&r, magic, 8) || memcmp(magic, LODS_MAGIC, 8) != 0)
        return bad(&r, "not a static LOD cache (bad magic)", NULL);
    if (!take(&r, &out->version, 4) || out->version < LODS_OLDEST_READ ||
        out->version > LODS_VERSION)
        return sw__fail(status, SW_ERR_VERSION,
                        "%s: LODS offset 8: cache version %u, this program reads %u to %u: run "
                        "`splinewalk build-lod` again",
                        what, out->version, LODS_OLDEST_READ, LODS_VERSION);
    if (!take(&r, &out->units, 4) || !take(&r, &out->key, 8))
        return bad(&r, "truncated header", NULL);
    sw_result res = take_settings(&r, &out->settings);
    for (uint32_t u = 0; u < out->units && res == SW_OK; ++u) {
        uint32_t has;
        if (!take(&r, &has, 4) || has > 1)
            res = bad(&r, "a unit's chain flag is not 0 or 1", NULL);
        else if (has)
            res = summarize_chain(&r, out);
    }
    if (res == SW_OK && out->version >= 3)
        res = summarize_proxies(&r, out);
    if (res == SW_OK && r.at != r.n)
        res =
            bad(&r, out->version >= 3 ? "bytes after the last proxy" : "bytes after the last chain",
                NULL);
    return res;
}

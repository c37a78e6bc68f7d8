/* SPDX-License-Identifier: MIT */
/* Vertex clustering with a certified two-sided bound (sw_lod_proxy.h argues it). Sorting, not
 * hashing: vertices are sorted by (part, cell, normal class) and each run becomes one vertex, so
 * the output is the same on every run and platform. */
#include "sw_lod_proxy.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cells per axis beyond which an index would lose integers in double. */
static const double k_max_cells = 1099511627776.0; /* 2^40 */

typedef struct vkey {
    uint32_t part;
    int64_t c[3];
    uint32_t cls;
    uint32_t vertex;
} vkey;

static int key_cmp_cell(const vkey *a, const vkey *b)
{
    if (a->part != b->part)
        return a->part < b->part ? -1 : 1;
    for (int k = 0; k < 3; ++k)
        if (a->c[k] != b->c[k])
            return a->c[k] < b->c[k] ? -1 : 1;
    return 0;
}

static int key_cmp(const void *pa, const void *pb)
{
    const vkey *a = pa, *b = pb;
    const int c = key_cmp_cell(a, b);
    if (c)
        return c;
    if (a->cls != b->cls)
        return a->cls < b->cls ? -1 : 1;
    return (a->vertex > b->vertex) - (a->vertex < b->vertex);
}

static int u32x3_cmp(const void *pa, const void *pb)
{
    const uint32_t *a = pa, *b = pb;
    for (int k = 0; k < 3; ++k)
        if (a[k] != b[k])
            return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int u64_cmp(const void *pa, const void *pb)
{
    const uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* The dominant axis of n with its sign: 0..5. */
static uint32_t normal_class(const float n[3])
{
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (fabsf(n[k]) > fabsf(n[axis]))
            axis = k;
    return (uint32_t)(2 * axis + (n[axis] < 0.0f));
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double dist3(const double a[3], const double b[3])
{
    const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(dot3(d, d));
}

void sw_lod_proxy_mesh_free(sw_lod_proxy_mesh *m)
{
    if (!m)
        return;
    sw__free(m->pos);
    sw__free(m->nrm);
    sw__free(m->part);
    sw__free(m->tri);
    memset(m, 0, sizeof *m);
}

/* ---- the working state ------------------------------------------------------------------------
 */
typedef struct cluster {
    const sw_lod_proxy_input *in;
    vkey *keys;    /* sorted by (part, cell, class) */
    uint32_t *rep; /* per input vertex: its representative */
    double *d;     /* per input vertex: |v - r(v)| */
    uint32_t n_reps;
    uint32_t *tri; /* surviving triangles (3 each, representatives), sorted, unique */
    uint32_t n_tri;
    uint64_t *edges; /* their undirected edges, (lo << 32 | hi), sorted */
    size_t n_edges;
    uint8_t *used;  /* per representative: a corner of a surviving triangle */
    uint32_t *kept; /* input triangles kept as they are: their image is not on the output */
    uint32_t n_kept;
} cluster;

static void cluster_free(cluster *c)
{
    sw__free(c->keys);
    sw__free(c->rep);
    sw__free(c->d);
    sw__free(c->tri);
    sw__free(c->edges);
    sw__free(c->used);
    sw__free(c->kept);
}

static sw_result check_input(const sw_lod_proxy_input *in, double cell, const double origin[3],
                             sw_status *status)
{
    if (!(cell > 0.0) || !isfinite(cell))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "proxy: cell size %g", cell);
    for (uint32_t i = 0; i < in->n_vertices; ++i) {
        if (in->part[i] >= in->n_parts)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "proxy: vertex %u: part %u of %u", i,
                            in->part[i], in->n_parts);
        for (int k = 0; k < 3; ++k) {
            const double x = (in->pos[3 * (size_t)i + (size_t)k] - origin[k]) / cell;
            if (!(fabs(x) < k_max_cells))
                return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                                "proxy: vertex %u lies %g cells from the grid's corner", i, x);
        }
    }
    for (size_t i = 0; i < 3 * (size_t)in->n_triangles; ++i)
        if (in->tri[i] >= in->n_vertices)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "proxy: triangle %zu: vertex %u of %u",
                            i / 3, in->tri[i], in->n_vertices);
    return SW_OK;
}

/* Sorts the vertices into runs of one (part, cell, class); each run a representative. */
static int make_reps(cluster *c, double cell, const double origin[3])
{
    const sw_lod_proxy_input *in = c->in;
    const size_t n = in->n_vertices ? in->n_vertices : 1;
    c->keys = sw__malloc(n * sizeof *c->keys);
    c->rep = sw__malloc(n * sizeof *c->rep);
    c->d = sw__malloc(n * sizeof *c->d);
    if (!c->keys || !c->rep || !c->d)
        return 0;
    for (uint32_t i = 0; i < in->n_vertices; ++i) {
        vkey *k = &c->keys[i];
        k->part = in->part[i];
        for (int a = 0; a < 3; ++a)
            k->c[a] = (int64_t)floor((in->pos[3 * (size_t)i + (size_t)a] - origin[a]) / cell);
        k->cls = normal_class(in->nrm + 3 * (size_t)i);
        k->vertex = i;
    }
    qsort(c->keys, in->n_vertices, sizeof *c->keys, key_cmp);
    c->n_reps = 0;
    for (uint32_t i = 0; i < in->n_vertices; ++i) {
        const vkey *k = &c->keys[i];
        if (i == 0 || key_cmp_cell(k, k - 1) || k->cls != k[-1].cls)
            c->n_reps++;
        c->rep[k->vertex] = c->n_reps - 1;
    }
    return 1;
}

/* Each representative's position (its vertices' mean: inside their cell) and normal; every
 * input vertex's distance to it. */
static int place_reps(cluster *c, sw_lod_proxy_mesh *out)
{
    const sw_lod_proxy_input *in = c->in;
    const size_t n = c->n_reps ? c->n_reps : 1;
    out->pos = sw__calloc(3 * n, sizeof *out->pos);
    out->nrm = sw__calloc(3 * n, sizeof *out->nrm);
    out->part = sw__malloc(n * sizeof *out->part);
    double *nsum = sw__calloc(3 * n, sizeof *nsum);
    uint32_t *count = sw__calloc(n, sizeof *count);
    if (!out->pos || !out->nrm || !out->part || !nsum || !count) {
        sw__free(nsum);
        sw__free(count);
        return 0;
    }
    out->n_vertices = c->n_reps;
    for (uint32_t i = 0; i < in->n_vertices; ++i) {
        const uint32_t r = c->rep[i];
        count[r]++;
        out->part[r] = in->part[i];
        for (int k = 0; k < 3; ++k) {
            out->pos[3 * (size_t)r + (size_t)k] += in->pos[3 * (size_t)i + (size_t)k];
            nsum[3 * (size_t)r + (size_t)k] += in->nrm[3 * (size_t)i + (size_t)k];
        }
    }
    for (uint32_t r = 0; r < c->n_reps; ++r) {
        double *p = out->pos + 3 * (size_t)r, *m = nsum + 3 * (size_t)r;
        const double len = sqrt(dot3(m, m));
        /* normals of one class share a dominant axis and sign: their sum cannot cancel */
        for (int k = 0; k < 3; ++k) {
            p[k] /= count[r];
            out->nrm[3 * (size_t)r + (size_t)k] = len > 0.0 ? (float)(m[k] / len) : 0.0f;
        }
    }
    for (uint32_t i = 0; i < in->n_vertices; ++i)
        c->d[i] = dist3(in->pos + 3 * (size_t)i, out->pos + 3 * (size_t)c->rep[i]);
    sw__free(nsum);
    sw__free(count);
    return 1;
}

/* A triangle's corners rotated so that the least comes first (orientation kept). */
static void canonical(uint32_t t[3])
{
    while (t[0] > t[1] || t[0] > t[2]) {
        const uint32_t x = t[0];
        t[0] = t[1];
        t[1] = t[2];
        t[2] = x;
    }
}

/* The surviving triangles, sorted and unique; their edges and corners. */
static int survivors(cluster *c)
{
    const sw_lod_proxy_input *in = c->in;
    c->tri = sw__malloc((3 * (size_t)in->n_triangles + 3) * sizeof *c->tri);
    c->used = sw__calloc(c->n_reps ? c->n_reps : 1, 1);
    if (!c->tri || !c->used)
        return 0;
    size_t n = 0;
    for (uint32_t t = 0; t < in->n_triangles; ++t) {
        uint32_t r[3];
        for (int k = 0; k < 3; ++k)
            r[k] = c->rep[in->tri[3 * (size_t)t + (size_t)k]];
        if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2])
            continue;
        canonical(r);
        memcpy(c->tri + 3 * n++, r, sizeof r);
    }
    qsort(c->tri, n, 3 * sizeof *c->tri, u32x3_cmp);
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (m == 0 || u32x3_cmp(c->tri + 3 * i, c->tri + 3 * (m - 1)))
            memmove(c->tri + 3 * m++, c->tri + 3 * i, 3 * sizeof *c->tri);
    c->n_tri = (uint32_t)m;
    c->edges = sw__malloc((3 * m + 1) * sizeof *c->edges);
    if (!c->edges)
        return 0;
    for (size_t i = 0; i < m; ++i)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = c->tri[3 * i + (size_t)k], b = c->tri[3 * i + (size_t)(k + 1) % 3];
            c->edges[c->n_edges++] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
            c->used[a] = 1;
        }
    qsort(c->edges, c->n_edges, sizeof *c->edges, u64_cmp);
    return 1;
}

static int has_edge(const cluster *c, uint32_t a, uint32_t b)
{
    const uint64_t e = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
    return bsearch(&e, c->edges, c->n_edges, sizeof *c->edges, u64_cmp) != NULL;
}

/* The bound over the triangles that survive or collapse onto the output (sw_lod_proxy.h); the
 * others (vanished) are listed to be kept as they are. */
static int measure(cluster *c, sw_lod_proxy_mesh *out)
{
    const sw_lod_proxy_input *in = c->in;
    c->kept = sw__malloc((in->n_triangles ? in->n_triangles : 1) * sizeof *c->kept);
    if (!c->kept)
        return 0;
    for (uint32_t t = 0; t < in->n_triangles; ++t) {
        const uint32_t *v = in->tri + 3 * (size_t)t;
        const uint32_t r[3] = {c->rep[v[0]], c->rep[v[1]], c->rep[v[2]]};
        const double dmax = fmax(c->d[v[0]], fmax(c->d[v[1]], c->d[v[2]]));
        if (r[0] != r[1] && r[1] != r[2] && r[0] != r[2]) {
            out->bound = fmax(out->bound, dmax);
            continue;
        }
        out->collapsed++;
        const uint32_t a = r[0], b = r[0] != r[1] ? r[1] : r[2];
        if (a == b ? c->used[a] : has_edge(c, a, b)) {
            out->bound = fmax(out->bound, dmax);
            continue;
        }
        c->kept[c->n_kept++] = t;
    }
    out->vanished = c->n_kept;
    return 1;
}

/* The output: the used representatives and the kept triangles' own vertices, grouped by part
 * (counting sort, stable), and the triangles renumbered. */
static int assemble(cluster *c, sw_lod_proxy_mesh *out)
{
    const sw_lod_proxy_input *in = c->in;
    const size_t n_src = (size_t)c->n_reps + in->n_vertices; /* reps, then input vertices */
    uint32_t *index = sw__malloc((n_src + 1) * sizeof *index);
    uint32_t *start = sw__calloc((size_t)in->n_parts + 1, sizeof *start);
    uint8_t *take = sw__calloc(n_src + 1, 1);
    double *pos = NULL;
    float *nrm = NULL;
    uint32_t *part = NULL, *tri = NULL;
    int ok = index && start && take;
    for (uint32_t r = 0; ok && r < c->n_reps; ++r)
        take[r] = c->used[r];
    for (uint32_t k = 0; ok && k < c->n_kept; ++k)
        for (int j = 0; j < 3; ++j)
            take[c->n_reps + in->tri[3 * (size_t)c->kept[k] + (size_t)j]] = 1;
    size_t n_out = 0;
    for (size_t i = 0; ok && i < n_src; ++i)
        if (take[i]) {
            start[(i < c->n_reps ? out->part[i] : in->part[i - c->n_reps]) + 1]++;
            n_out++;
        }
    if (ok) {
        pos = sw__malloc((3 * n_out + 3) * sizeof *pos);
        nrm = sw__malloc((3 * n_out + 3) * sizeof *nrm);
        part = sw__malloc((n_out + 1) * sizeof *part);
        tri = sw__malloc((3 * ((size_t)c->n_tri + c->n_kept) + 3) * sizeof *tri);
        ok = pos && nrm && part && tri;
    }
    for (uint32_t p = 0; ok && p < in->n_parts; ++p)
        start[p + 1] += start[p];
    for (size_t i = 0; ok && i < n_src; ++i) {
        if (!take[i])
            continue;
        const int rep = i < c->n_reps;
        const size_t src = rep ? i : i - c->n_reps;
        const uint32_t pt = rep ? out->part[i] : in->part[src];
        const uint32_t at = start[pt]++;
        index[i] = at;
        part[at] = pt;
        for (int k = 0; k < 3; ++k) {
            pos[3 * (size_t)at + (size_t)k] =
                rep ? out->pos[3 * src + (size_t)k] : in->pos[3 * src + (size_t)k];
            nrm[3 * (size_t)at + (size_t)k] =
                rep ? out->nrm[3 * src + (size_t)k] : in->nrm[3 * src + (size_t)k];
        }
    }
    size_t nt = 0;
    for (size_t i = 0; ok && i < 3 * (size_t)c->n_tri; ++i)
        tri[nt++] = index[c->tri[i]];
    for (uint32_t k = 0; ok && k < c->n_kept; ++k)
        for (int j = 0; j < 3; ++j)
            tri[nt++] = index[c->n_reps + in->tri[3 * (size_t)c->kept[k] + (size_t)j]];
    if (ok) {
        sw__free(out->pos);
        sw__free(out->nrm);
        sw__free(out->part);
        out->pos = pos;
        out->nrm = nrm;
        out->part = part;
        out->tri = tri;
        out->n_vertices = (uint32_t)n_out;
        out->n_triangles = (uint32_t)(nt / 3);
    } else {
        sw__free(pos);
        sw__free(nrm);
        sw__free(part);
        sw__free(tri);
    }
    sw__free(index);
    sw__free(start);
    sw__free(take);
    return ok;
}

sw_result sw_lod_proxy_cluster(const sw_lod_proxy_input *in, double cell, const double origin[3],
                               sw_lod_proxy_mesh *out, sw_status *status)
{
    memset(out, 0, sizeof *out);
    sw_result r = check_input(in, cell, origin, status);
    if (r != SW_OK)
        return r;
    cluster c;
    memset(&c, 0, sizeof c);
    c.in = in;
    if (!make_reps(&c, cell, origin) || !place_reps(&c, out) || !survivors(&c) ||
        !measure(&c, out) || !assemble(&c, out))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "proxy: out of memory");
    cluster_free(&c);
    if (r != SW_OK)
        sw_lod_proxy_mesh_free(out);
    return r;
}

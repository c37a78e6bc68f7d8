/* SPDX-License-Identifier: MIT */
/* Cluster proxies of a static set (sw_lod_proxy.h says what a proxy is and why its bound holds;
 * sw_lod_static_set.h how frames use them).
 *
 * Which nodes. Every node of the unit-instance BVH with at least k_min_instances instances under
 * it is a candidate. A proxy aims at an error that is a fixed share of its node's diagonal
 * (k_aim_of_diagonal), so that the cut takes it where the node spans a few tens of pixels. Its
 * inputs are, per child, the child's proxy, else every instance under the child at the coarsest
 * stored level within most of that aim (else its finest), placed in the world by the instance's
 * transform; the clustering's cells take the rest of the aim, and grow where a proxy made from
 * proxies would otherwise keep more than half their triangles (k_max_cells_of_aim). A node with
 * an instance that has no stored level (a face with no unit, a failed or missing chain) gets no
 * proxy, nor do its ancestors.
 *
 * Builds. Pool tasks, one per subtree at depth k_split_depth (the nodes below it built bottom-up in
 * the task); the last of them builds the nodes above. A task stages what it builds, then publishes
 * its subtree's proxies breadth first (larger nodes first) within its share of k_proxy_budget and
 * drops the rest; each proxy is published by one pointer store (release) and never changes, so
 * frames read it with no lock and draw what exists. */
#include "sw_clock.h"
#include "sw_crc32c.h"
#include "sw_hooks.h"
#include "sw_lod_proxy.h"
#include "sw_lod_static_set.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

enum {
    k_min_instances = 8, /* a proxy stands for at least this many instances */
    k_split_depth = 6,   /* subtrees built by tasks of their own */
    k_max_parts = 1024,  /* colours one proxy keeps apart; more fail the proxy */
};
/* The error a proxy aims at, as a share of its node's diagonal: the cut takes it where the node
 * spans about 1 / (2 x this) = 64 px at ε_img = 0.5. Of it, the inputs take k_input_share (their
 * levels as coarse as that allows: fewest triangles) and the clustering's cells k_cell_share (the
 * clustering bound is at most a cell's diagonal, about half a cell in practice). Measured on the
 * 10^5-surface car park's fly-through (docs/performance.md): aiming at a 128th with 0.8 / 0.2
 * draws 15 % fewer triangles than a 256th with cells as large as the inputs' error. */
static const double k_aim_of_diagonal = 1.0 / 128.0;
static const double k_input_share = 0.8, k_cell_share = 0.2;
/* A proxy made from its children's proxies keeps at most half their triangles: its cells double
 * (its error grows) until it does, up to this many aims. Inputs are copies placed in the world (an
 * instanced unit's level once per instance), so without it the 10^6 building's proxies copied its
 * walls' levels at every depth of the tree (peak RSS 4.8 GB). */
static const double k_max_cells_of_aim = 8.0;
/* Bytes of proxies a set keeps, shared evenly by the subtree tasks, each publishing its larger
 * nodes first (the far field) and dropping what does not fit: proxies copy instanced geometry into
 * the world, so their memory follows the scene's occurrences, not its units. */
static const size_t k_proxy_budget = (size_t)384 << 20;

static sw_th_task_kind_slot k_proxy_kind = SW_TH_TASK_KIND_SLOT("static_proxy");

struct sw__lod_proxies {
    _Atomic(sw_lod_proxy *) *node; /* per BVH node: its proxy once published */
    sw_lod_proxy **staged;         /* per BVH node: built, not yet published (its task's alone) */
    size_t share;                  /* bytes each subtree task may publish */
    uint32_t n_nodes;
    _Atomic int started;
    _Atomic int64_t subtrees_left;
    _Atomic int done;    /* every build finished (the last task's nodes above included) */
    _Atomic int adopted; /* read from a cache, not built */
    _Atomic uint32_t next_key;
    _Atomic uint64_t built, failed, pruned, triangles, bytes, ns;
    sw_th_group group;
};

sw_result sw__lod_proxies_create(uint32_t n_nodes, sw__lod_proxies **out, sw_status *status)
{
    sw__lod_proxies *p = sw__calloc(1, sizeof *p);
    if (p) {
        p->node = sw__calloc(n_nodes ? n_nodes : 1, sizeof *p->node);
        p->staged = sw__calloc(n_nodes ? n_nodes : 1, sizeof *p->staged);
    }
    if (!p || !p->node || !p->staged) {
        if (p) {
            sw__free(p->node);
            sw__free(p->staged);
        }
        sw__free(p);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "proxies: out of memory");
    }
    p->n_nodes = n_nodes;
    *out = p;
    return SW_OK;
}

void sw__lod_proxy_free(sw_lod_proxy *x)
{
    if (!x)
        return;
    for (uint32_t k = 0; k < x->n_parts; ++k) {
        sw__free(x->parts[k].positions);
        sw__free(x->parts[k].normals);
        sw__free(x->parts[k].triangles);
        if (x->lines)
            sw__free(x->lines[k]);
    }
    sw__free(x->parts);
    sw__free(x->colors);
    sw__free(x->lines);
    sw__free(x->n_lines);
    sw__free(x);
}

void sw__lod_proxies_destroy(sw_th_pool *pool, sw__lod_proxies *p)
{
    if (!p)
        return;
    sw_th_group_wait(pool, &p->group);
    for (uint32_t n = 0; n < p->n_nodes; ++n) {
        sw__lod_proxy_free(atomic_load(&p->node[n]));
        sw__lod_proxy_free(p->staged[n]); /* a cancelled build's */
    }
    sw__free(p->node);
    sw__free(p->staged);
    sw__free(p);
}

int sw__lod_proxies_started(const sw__lod_proxies *p)
{
    return atomic_load_explicit(&p->started, memory_order_acquire);
}

int sw__lod_proxies_done(const sw__lod_proxies *p)
{
    return atomic_load_explicit(&p->done, memory_order_acquire);
}

void sw__lod_proxies_wait(sw_th_pool *pool, sw__lod_proxies *p)
{
    if (sw_th_group_pending(&p->group) == 0)
        return;
    sw_th_wait_begin();
    sw_th_group_wait(pool, &p->group);
    sw_th_wait_end();
}

const sw_lod_proxy *sw__lod_proxies_get(const sw__lod_proxies *p, uint32_t node)
{
    return node < p->n_nodes ? atomic_load_explicit(&p->node[node], memory_order_acquire) : NULL;
}

void sw__lod_proxies_stats(const sw__lod_proxies *p, sw_lod_static_set_stats *out)
{
    out->proxies = atomic_load(&p->built);
    out->proxies_failed = atomic_load(&p->failed);
    out->proxies_pruned = atomic_load(&p->pruned);
    out->proxy_triangles = atomic_load(&p->triangles);
    out->proxy_bytes = (size_t)atomic_load(&p->bytes);
    out->proxy_seconds = 1e-9 * (double)atomic_load(&p->ns);
    out->proxies_building = atomic_load(&p->started) && !atomic_load(&p->done);
    out->proxies_adopted = atomic_load(&p->adopted);
}

/* ---- one proxy's inputs ------------------------------------------------------------------------
 */
typedef struct gather {
    const sw_lod_static_set *set;
    const sw_lod_static_instances *in;
    double centre[3];
    double *pos;
    float *nrm;
    uint32_t *part, *tri;
    size_t n_v, cap_pos, cap_nrm, cap_part, n_t, cap_tri;
    float (*colors)[4];
    uint32_t n_colors;
    double err; /* the inputs' own error, world units */
    uint32_t instances;
    uint64_t faces;
} gather;

static void gather_free(gather *g)
{
    sw__free(g->pos);
    sw__free(g->nrm);
    sw__free(g->part);
    sw__free(g->tri);
    sw__free(g->colors);
}

/* The part of colour c, added when new; -1 past k_max_parts or out of memory. */
static int32_t part_of(gather *g, const float c[4])
{
    for (uint32_t k = 0; k < g->n_colors; ++k)
        if (!memcmp(g->colors[k], c, sizeof g->colors[k]))
            return (int32_t)k;
    if (g->n_colors == k_max_parts) /* colours beyond it: the proxy is not made */
        return -1;
    float(*colors)[4] = sw__realloc(g->colors, (g->n_colors + 1) * sizeof *colors);
    if (!colors)
        return -1;
    g->colors = colors;
    memcpy(g->colors[g->n_colors], c, sizeof g->colors[0]);
    return (int32_t)g->n_colors++;
}

static int reserve(gather *g, size_t nv, size_t nt)
{
    return sw__grow((void **)&g->pos, &g->cap_pos, 3 * (g->n_v + nv), sizeof *g->pos) &&
           sw__grow((void **)&g->nrm, &g->cap_nrm, 3 * (g->n_v + nv), sizeof *g->nrm) &&
           sw__grow((void **)&g->part, &g->cap_part, g->n_v + nv, sizeof *g->part) &&
           sw__grow((void **)&g->tri, &g->cap_tri, 3 * (g->n_t + nt), sizeof *g->tri);
}

/* Appends a mesh: positions mapped by m (3 x 4, row-major; NULL: moved by `shift`), normals by its
 * linear part (similarities: shading is two-sided, as the static levels' draws), one part. */
static int append_mesh(gather *g, const sw_lod_static_level *lv, const double *m,
                       const double shift[3], int32_t part)
{
    if (part < 0 || g->n_v + lv->n_vertices > UINT32_MAX ||
        !reserve(g, lv->n_vertices, lv->n_triangles))
        return 0;
    for (uint32_t i = 0; i < lv->n_vertices; ++i) {
        const double *p = lv->positions + 3 * (size_t)i;
        const float *n = lv->normals + 3 * (size_t)i;
        double *q = g->pos + 3 * g->n_v;
        float *qn = g->nrm + 3 * g->n_v;
        double nn[3], len = 0.0;
        for (int r = 0; r < 3; ++r) {
            q[r] = m ? m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3]
                     : p[r] + shift[r];
            q[r] -= m ? g->centre[r] : 0.0;
            nn[r] = m ? m[4 * r] * n[0] + m[4 * r + 1] * n[1] + m[4 * r + 2] * n[2] : n[r];
            len += nn[r] * nn[r];
        }
        len = sqrt(len);
        for (int r = 0; r < 3; ++r)
            qn[r] = len > 0.0 ? (float)(nn[r] / len) : 0.0f;
        g->part[g->n_v++] = (uint32_t)part;
    }
    const uint32_t base = (uint32_t)(g->n_v - lv->n_vertices);
    for (size_t k = 0; k < 3 * (size_t)lv->n_triangles; ++k)
        g->tri[3 * g->n_t + k] = base + lv->triangles[k];
    g->n_t += lv->n_triangles;
    return 1;
}

/* The coarsest stored level of a chain whose error under a transform of stretch s is within
 * `within`, else its finest stored level. */
static const sw_lod_static_level *level_for(const sw_lod_static_chain *c, double s, double within)
{
    const sw_lod_static_level *finest = NULL;
    for (int32_t k = c->n_levels - 1; k >= 0; --k) {
        const sw_lod_static_level *lv = &c->levels[k];
        if (lv->n_triangles == 0)
            continue;
        if (lv->eps * s <= within)
            return lv;
        finest = lv;
    }
    return finest;
}

/* Every instance under BVH node `node`, each at its coarsest level within `within`: 0 when one has
 * no stored level (or out of memory). */
static int gather_instances(gather *g, uint32_t node, double within)
{
    const sw_sg_bvh *bvh = g->in->bvh;
    const sw_sg_bvh_node *nd = &bvh->nodes[node];
    for (uint32_t i = nd->first; i < nd->first + nd->count; ++i) {
        sw_sg_bvh_item_view it;
        sw_sg_bvh_item_at(bvh, i, &it);
        const sw_lod_static_instance *ins = &g->in->instances[it.face];
        if (ins->unit == SW_LOD_STATIC_NO_UNIT)
            return 0;
        const sw_lod_static_chain *c = sw_lod_static_set_get(g->set, ins->unit);
        const double s = sw_sg_stretch_bound(it.world);
        const sw_lod_static_level *lv = c ? level_for(c, s, within) : NULL;
        if (!lv)
            return 0;
        if (!append_mesh(g, lv, it.world, NULL, part_of(g, g->in->occs[ins->first_occ].color)))
            return 0;
        g->err = fmax(g->err, lv->eps * s);
        g->instances++;
        g->faces += ins->n_occ;
    }
    return 1;
}

static int gather_proxy(gather *g, const sw_lod_proxy *x)
{
    const double shift[3] = {x->centre[0] - g->centre[0], x->centre[1] - g->centre[1],
                             x->centre[2] - g->centre[2]};
    for (uint32_t k = 0; k < x->n_parts; ++k)
        if (!append_mesh(g, &x->parts[k], NULL, shift, part_of(g, x->colors[k])))
            return 0;
    g->err = fmax(g->err, x->err);
    g->instances += x->instances;
    g->faces += x->faces;
    return 1;
}

/* ---- one proxy
 * ----------------------------------------------------------------------------------- */

static int u64_cmp(const void *pa, const void *pb)
{
    const uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* The edges of a part used by one triangle only, as vertex pairs (lower index first). */
static int open_edges(const sw_lod_static_level *lv, uint32_t **out, uint32_t *n_out)
{
    const size_t n = 3 * (size_t)lv->n_triangles;
    uint64_t *e = sw__malloc((n + 1) * sizeof *e);
    uint32_t *lines = sw__malloc((2 * n + 2) * sizeof *lines);
    if (!e || !lines) {
        sw__free(e);
        sw__free(lines);
        return 0;
    }
    for (size_t t = 0; t < lv->n_triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = lv->triangles[3 * t + (size_t)k];
            const uint32_t b = lv->triangles[3 * t + (size_t)(k + 1) % 3];
            e[3 * t + (size_t)k] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    qsort(e, n, sizeof *e, u64_cmp);
    uint32_t m = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && e[j] == e[i])
            ++j;
        if (j - i == 1) {
            lines[2 * m] = (uint32_t)(e[i] >> 32);
            lines[2 * m + 1] = (uint32_t)e[i];
            ++m;
        }
        i = j;
    }
    sw__free(e);
    *out = lines;
    *n_out = m;
    return 1;
}

int sw__lod_proxy_find_lines(sw_lod_proxy *x)
{
    if (!x->lines)
        x->lines = sw__calloc(x->n_parts ? x->n_parts : 1, sizeof *x->lines);
    if (!x->n_lines)
        x->n_lines = sw__calloc(x->n_parts ? x->n_parts : 1, sizeof *x->n_lines);
    if (!x->lines || !x->n_lines)
        return 0;
    for (uint32_t k = 0; k < x->n_parts; ++k)
        if (!x->lines[k] && !open_edges(&x->parts[k], &x->lines[k], &x->n_lines[k]))
            return 0;
    return 1;
}

/* The sign bit's: -0.0 is negative, so that a normal decoded on the fold's seam encodes to the
 * code it came from (the cache stores what the builder kept). */
static double sign_of(double x)
{
    return signbit(x) ? -1.0 : 1.0;
}

/* Octahedral normal encoding (Meyer et al. 2010, "On floating-point normal vectors"): the unit
 * sphere projected on the octahedron |x| + |y| + |z| = 1, its lower half folded over the upper,
 * two snorm16 of the square that results: 4 bytes instead of 12, within about 1e-4 rad, which
 * shading does not show. A zero normal reads back as +z. */
void sw__lod_proxy_normal_pack(const float n[3], int16_t q[2])
{
    const double s = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
    double u = s > 0.0 ? n[0] / s : 0.0, v = s > 0.0 ? n[1] / s : 0.0;
    if (n[2] < 0.0f) {
        const double pu = u;
        u = (1.0 - fabs(v)) * sign_of(pu);
        v = (1.0 - fabs(pu)) * sign_of(v);
    }
    q[0] = (int16_t)lrint(fmax(-1.0, fmin(1.0, u)) * 32767.0);
    q[1] = (int16_t)lrint(fmax(-1.0, fmin(1.0, v)) * 32767.0);
}

void sw__lod_proxy_normal_unpack(const int16_t q[2], float n[3])
{
    double u = fmax(-1.0, q[0] / 32767.0), v = fmax(-1.0, q[1] / 32767.0);
    const double z = 1.0 - fabs(u) - fabs(v);
    if (z < 0.0) {
        const double pu = u;
        u = (1.0 - fabs(v)) * sign_of(pu);
        v = (1.0 - fabs(pu)) * sign_of(v);
    }
    const double len = sqrt(u * u + v * v + z * z);
    n[0] = (float)(u / len);
    n[1] = (float)(v / len);
    n[2] = (float)(z / len);
}

uint16_t sw__lod_proxy_coord_pack(double x, double range)
{
    if (!(range > 0.0))
        return 0;
    return (uint16_t)lrint(fmax(0.0, fmin(65535.0, (x + range) * (32767.5 / range))));
}

double sw__lod_proxy_coord_unpack(uint16_t q, double range)
{
    return range > 0.0 ? (double)q * (range / 32767.5) - range : 0.0;
}

/* Rounds the parts' vertices as the LOD cache stores them — each coordinate (relative to the
 * centre) to one of 65536 steps across ±range, range the largest extent of the proxy's vertices
 * along that axis; normals to their octahedral code — and returns the farthest a position moved:
 * what the bound grows by (the affine argument of sw_lod_proxy.h again: no point of a triangle
 * moves farther than its corners do; at most half a step per axis, 1/75,000 of the extent). A
 * proxy built and one read back from a cache are then the same, bit for bit. */
static double round_as_stored(sw_lod_proxy *x)
{
    for (int c = 0; c < 3; ++c)
        x->range[c] = 0.0;
    for (uint32_t k = 0; k < x->n_parts; ++k)
        for (uint32_t i = 0; i < 3 * x->parts[k].n_vertices; ++i)
            x->range[i % 3] = fmax(x->range[i % 3], fabs(x->parts[k].positions[i]));
    double most = 0.0;
    for (uint32_t k = 0; k < x->n_parts; ++k) {
        double *p = x->parts[k].positions;
        float *nrm = x->parts[k].normals;
        for (uint32_t v = 0; v < x->parts[k].n_vertices; ++v, p += 3, nrm += 3) {
            double d2 = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double r = sw__lod_proxy_coord_unpack(
                    sw__lod_proxy_coord_pack(p[c], x->range[c]), x->range[c]);
                d2 += (r - p[c]) * (r - p[c]);
                p[c] = r;
            }
            most = fmax(most, sqrt(d2));
            int16_t q[2];
            sw__lod_proxy_normal_pack(nrm, q);
            sw__lod_proxy_normal_unpack(q, nrm);
        }
    }
    return most;
}

/* The output split into one level per part (its vertices are grouped by part). */
static sw_lod_proxy *split_parts(const gather *g, const sw_lod_proxy_mesh *m)
{
    sw_lod_proxy *x = sw__calloc(1, sizeof *x);
    if (!x)
        return NULL;
    const size_t np = g->n_colors ? g->n_colors : 1;
    x->parts = sw__calloc(np, sizeof *x->parts);
    x->colors = sw__calloc(np, sizeof *x->colors);
    x->lines = sw__calloc(np, sizeof *x->lines);
    x->n_lines = sw__calloc(np, sizeof *x->n_lines);
    uint32_t *first = sw__calloc((size_t)g->n_colors + 1, sizeof *first);
    if (!x->parts || !x->colors || !x->lines || !x->n_lines || !first) {
        sw__free(first);
        sw__lod_proxy_free(x);
        return NULL;
    }
    for (uint32_t v = 0; v < m->n_vertices; ++v)
        first[m->part[v] + 1]++;
    for (uint32_t k = 0; k < g->n_colors; ++k)
        first[k + 1] += first[k];
    uint32_t *nt = sw__calloc(g->n_colors ? g->n_colors : 1, sizeof *nt);
    int ok = nt != NULL;
    for (uint32_t t = 0; ok && t < m->n_triangles; ++t)
        nt[m->part[m->tri[3 * (size_t)t]]]++;
    for (uint32_t k = 0; ok && k < g->n_colors; ++k) {
        const uint32_t nv = first[k + 1] - first[k];
        if (nv == 0 || nt[k] == 0)
            continue;
        sw_lod_static_level *lv = &x->parts[x->n_parts];
        memcpy(x->colors[x->n_parts++], g->colors[k], sizeof x->colors[0]);
        lv->positions = sw__malloc(3 * (size_t)nv * sizeof *lv->positions);
        lv->normals = sw__malloc(3 * (size_t)nv * sizeof *lv->normals);
        lv->triangles = sw__malloc(3 * (size_t)nt[k] * sizeof *lv->triangles);
        if (!lv->positions || !lv->normals || !lv->triangles) {
            ok = 0;
            break;
        }
        memcpy(lv->positions, m->pos + 3 * (size_t)first[k], 3 * (size_t)nv * sizeof *m->pos);
        memcpy(lv->normals, m->nrm + 3 * (size_t)first[k], 3 * (size_t)nv * sizeof *m->nrm);
        lv->n_vertices = nv;
        for (uint32_t t = 0; t < m->n_triangles; ++t) {
            const uint32_t *tr = m->tri + 3 * (size_t)t;
            if (m->part[tr[0]] != k)
                continue;
            for (int c = 0; c < 3; ++c)
                lv->triangles[3 * (size_t)lv->n_triangles + (size_t)c] = tr[c] - first[k];
            lv->n_triangles++;
        }
    }
    sw__free(nt);
    sw__free(first);
    if (!ok || !sw__lod_proxy_find_lines(x)) {
        sw__lod_proxy_free(x);
        return NULL;
    }
    return x;
}

static double box_diagonal(const double b[6])
{
    return sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                (b[5] - b[2]) * (b[5] - b[2]));
}

/* Clusters the gathered inputs on cells of size h, doubled while the output has more than
 * `limit` triangles, up to k_max_cells_of_aim aims (the top of the file). */
static sw_lod_proxy *cluster_inputs(const gather *g, double diag, double h, double aim,
                                    uint64_t limit, sw_status *st)
{
    const sw_lod_proxy_input in = {g->pos,      g->nrm, g->part,         (uint32_t)g->n_v,
                                   g->n_colors, g->tri, (uint32_t)g->n_t};
    const double origin[3] = {-0.5 * diag, -0.5 * diag, -0.5 * diag};
    sw_lod_proxy_mesh m;
    for (;;) {
        if (sw_lod_proxy_cluster(&in, h, origin, &m, st) != SW_OK)
            return NULL;
        if (m.n_triangles <= limit || 2.0 * h > k_max_cells_of_aim * aim)
            break;
        sw_lod_proxy_mesh_free(&m);
        h *= 2.0;
    }
    sw_lod_proxy *x = m.n_triangles && isfinite(m.bound) ? split_parts(g, &m) : NULL;
    if (x) {
        x->err = g->err + m.bound + round_as_stored(x);
        x->input_err = g->err;
        x->n_triangles = m.n_triangles;
        x->vanished = m.vanished;
        x->cell = h;
    }
    sw_lod_proxy_mesh_free(&m);
    return x;
}

static size_t proxy_bytes(const sw_lod_proxy *x)
{
    size_t b = sizeof *x + x->n_parts * (sizeof *x->parts + sizeof *x->colors);
    for (uint32_t k = 0; k < x->n_parts; ++k)
        b += (size_t)x->parts[k].n_vertices * (3 * sizeof(double) + 3 * sizeof(float)) +
             (size_t)x->parts[k].n_triangles * 3 * sizeof(uint32_t) +
             (size_t)x->n_lines[k] * 2 * sizeof(uint32_t);
    return b;
}

/* A child's proxy as its parent's build sees it: staged by the same task, or published. */
static const sw_lod_proxy *built(const sw__lod_proxies *p, uint32_t node)
{
    return p->staged[node] ? p->staged[node] : sw__lod_proxies_get(p, node);
}

/* Makes a staged proxy visible to frames (one release store: it is complete and never changes). */
static void publish(sw__lod_proxies *p, uint32_t node)
{
    sw_lod_proxy *x = p->staged[node];
    p->staged[node] = NULL;
    x->key = atomic_fetch_add(&p->next_key, x->n_parts);
    atomic_fetch_add(&p->built, 1);
    atomic_fetch_add(&p->triangles, x->n_triangles);
    atomic_fetch_add(&p->bytes, proxy_bytes(x));
    atomic_store_explicit(&p->node[node], x, memory_order_release);
}

static void drop_staged(sw__lod_proxies *p, uint32_t node)
{
    sw__lod_proxy_free(p->staged[node]);
    p->staged[node] = NULL;
    atomic_fetch_add(&p->pruned, 1);
}

/* Publishes the staged proxies of root's subtree breadth first — larger nodes (farther views,
 * fewer triangles each) first — while they fit in `share` bytes; drops the others. */
static void publish_within(const sw_sg_bvh *bvh, sw__lod_proxies *p, uint32_t root, size_t share)
{
    const uint32_t end = root + 2 * bvh->nodes[root].count; /* past the subtree's nodes */
    uint32_t *queue = sw__malloc(((size_t)bvh->nodes[root].count * 2 + 1) * sizeof *queue);
    size_t head = 0, tail = 0, used = 0;
    if (!queue) { /* out of memory: what was built goes, nothing half-published */
        for (uint32_t n = root; n < bvh->n_nodes && n < end; ++n)
            if (p->staged[n])
                drop_staged(p, n);
        return;
    }
    queue[tail++] = root;
    while (head < tail) {
        const uint32_t n = queue[head++];
        sw_lod_proxy *x = p->staged[n];
        if (x && used + proxy_bytes(x) <= share) {
            used += proxy_bytes(x);
            publish(p, n);
        } else if (x) {
            drop_staged(p, n);
        }
        for (int c = 0; c < 2; ++c) {
            const int32_t child = sw_sg_bvh_child(bvh, n, c);
            if (child >= 0 && bvh->nodes[child].count >= k_min_instances)
                queue[tail++] = (uint32_t)child;
        }
    }
    sw__free(queue);
}

static int is_candidate(const sw_sg_bvh *bvh, int32_t node)
{
    return node >= 0 && bvh->nodes[node].count >= k_min_instances;
}

void sw__lod_proxy_centre(const double box[6], double centre[3])
{
    for (int k = 0; k < 3; ++k)
        centre[k] = 0.5 * (box[k] + box[3 + k]);
}

int sw__lod_proxy_candidate(const sw_lod_static_set *set, uint32_t node)
{
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(set)->bvh;
    return node < bvh->n_nodes && is_candidate(bvh, (int32_t)node);
}

/* What a set's proxies are made from besides the chains: its instances (units, transforms,
 * colours), their BVH and the rules of this file. A proxy is in world coordinates, so a cache's
 * proxies are stale when any of it differs. */
uint32_t sw__lod_proxies_key(const sw_lod_static_set *set)
{
    const sw_lod_static_instances *in = sw_lod_static_set_instances(set);
    const sw_sg_bvh *bvh = in->bvh;
    const double rules[6] = {k_aim_of_diagonal,  k_input_share,          k_cell_share,
                             k_max_cells_of_aim, (double)k_proxy_budget, (double)k_min_instances};
    const int32_t more[2] = {k_split_depth, k_max_parts};
    uint32_t h = sw__crc32c(0, rules, sizeof rules);
    h = sw__crc32c(h, more, sizeof more);
    h = sw__crc32c(h, &bvh->n_nodes, sizeof bvh->n_nodes);
    h = sw__crc32c(h, bvh->nodes, (size_t)bvh->n_nodes * sizeof *bvh->nodes);
    h = sw__crc32c(h, bvh->items, (size_t)bvh->n_items * sizeof *bvh->items);
    h = sw__crc32c(h, bvh->places, (size_t)bvh->n_places * sizeof *bvh->places);
    h = sw__crc32c(h, bvh->origin, sizeof bvh->origin);
    h = sw__crc32c(h, in->instances, (size_t)in->n_instances * sizeof *in->instances);
    return sw__crc32c(h, in->occs, (size_t)in->n_occs * sizeof *in->occs);
}

sw_result sw__lod_proxies_adopt(sw__lod_proxies *p, sw_lod_proxy **by_node, uint64_t failed,
                                uint64_t pruned)
{
    int expect = 0;
    if (!atomic_compare_exchange_strong(&p->started, &expect, 1))
        return SW_ERR_INVALID_ARGUMENT; /* built or being built here: those stay */
    for (uint32_t n = 0; n < p->n_nodes; ++n)
        if (by_node[n]) {
            p->staged[n] = by_node[n];
            by_node[n] = NULL;
            publish(p, n);
        }
    atomic_store(&p->failed, failed);
    atomic_store(&p->pruned, pruned);
    atomic_store(&p->adopted, 1);
    atomic_store_explicit(&p->done, 1, memory_order_release);
    return SW_OK;
}

/* Builds node's proxy from its children's proxies or instances, and publishes it. */
static void build_node(const sw_lod_static_set *set, sw__lod_proxies *p, uint32_t node)
{
    const sw_lod_static_instances *in = sw_lod_static_set_instances(set);
    const sw_sg_bvh *bvh = in->bvh;
    if (!is_candidate(bvh, (int32_t)node) || sw__lod_static_set_cancelled(set))
        return;
    const uint64_t t0 = sw__clock_ns();
    gather g;
    memset(&g, 0, sizeof g);
    g.set = set;
    g.in = in;
    double box[6];
    sw_sg_bvh_node_box(bvh, node, box);
    sw__lod_proxy_centre(box, g.centre);
    const double diag = box_diagonal(box), aim = diag * k_aim_of_diagonal;
    const double within = k_input_share * aim, cell = k_cell_share * aim;
    int ok = 1, from_proxies = 0;
    if (bvh->nodes[node].second < 0) {
        ok = gather_instances(&g, node, within);
    } else {
        for (int c = 0; c < 2 && ok; ++c) {
            const int32_t child = sw_sg_bvh_child(bvh, node, c);
            const sw_lod_proxy *x = built(p, (uint32_t)child);
            from_proxies |= x != NULL;
            ok = x ? gather_proxy(&g, x) : gather_instances(&g, (uint32_t)child, within);
        }
    }
    sw_status st = {0};
    const uint64_t limit = from_proxies ? g.n_t / 2 : UINT64_MAX;
    sw_lod_proxy *x = ok && g.n_t ? cluster_inputs(&g, diag, cell, aim, limit, &st) : NULL;
    if (x) {
        for (int k = 0; k < 3; ++k)
            x->centre[k] = g.centre[k];
        x->instances = g.instances;
        x->faces = g.faces;
        x->input_triangles = g.n_t;
        p->staged[node] = x;
    } else {
        atomic_fetch_add(&p->failed, 1);
    }
    atomic_fetch_add(&p->ns, sw__clock_ns() - t0);
    gather_free(&g);
}

/* Post-order over node's subtree down to depth `stop` (exclusive; -1: no limit): children first. */
static void build_subtree(const sw_lod_static_set *set, sw__lod_proxies *p, uint32_t node,
                          int depth, int stop)
{
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(set)->bvh;
    if (!is_candidate(bvh, (int32_t)node) || depth == stop)
        return;
    if (stop >= 0 && bvh->nodes[node].second < 0)
        return; /* a leaf above the split depth is a task's root, built by it */
    for (int c = 0; c < 2; ++c) {
        const int32_t child = sw_sg_bvh_child(bvh, node, c);
        if (child >= 0)
            build_subtree(set, p, (uint32_t)child, depth + 1, stop);
    }
    build_node(set, p, node);
}

typedef struct subtree_job {
    const sw_lod_static_set *set;
    sw__lod_proxies *p;
    uint32_t node;
} subtree_job;

static void subtree_task(void *ctx)
{
    subtree_job *job = ctx;
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(job->set)->bvh;
    build_subtree(job->set, job->p, job->node, k_split_depth, -1);
    publish_within(bvh, job->p, job->node, job->p->share);
    if (atomic_fetch_sub(&job->p->subtrees_left, 1) == 1) { /* the last: the nodes above */
        build_subtree(job->set, job->p, 0, 0, k_split_depth);
        for (uint32_t n = 0; n < bvh->n_nodes; ++n) /* the few above the split, whole */
            if (job->p->staged[n])
                publish(job->p, n);
        atomic_store_explicit(&job->p->done, 1, memory_order_release);
    }
    sw__free(job);
}

/* The nodes at depth k_split_depth (or leaves above it) that are candidates. */
static uint32_t split_roots(const sw_sg_bvh *bvh, uint32_t node, int depth, uint32_t *out)
{
    if (!is_candidate(bvh, (int32_t)node))
        return 0;
    if (depth == k_split_depth || bvh->nodes[node].second < 0) {
        if (out)
            out[0] = node;
        return 1;
    }
    uint32_t n = 0;
    for (int c = 0; c < 2; ++c)
        n += split_roots(bvh, (uint32_t)sw_sg_bvh_child(bvh, node, c), depth + 1,
                         out ? out + n : NULL);
    return n;
}

sw_result sw__lod_proxies_start(const sw_lod_static_set *set, sw__lod_proxies *p, sw_th_pool *pool,
                                sw_status *status)
{
    int expect = 0;
    if (!atomic_compare_exchange_strong(&p->started, &expect, 1))
        return SW_OK;
    const sw_sg_bvh *bvh = sw_lod_static_set_instances(set)->bvh;
    const uint32_t n = bvh->n_nodes ? split_roots(bvh, 0, 0, NULL) : 0;
    if (n == 0) {
        atomic_store_explicit(&p->done, 1, memory_order_release);
        return SW_OK;
    }
    uint32_t *roots = sw__malloc(n * sizeof *roots);
    if (!roots)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "proxies: out of memory");
    split_roots(bvh, 0, 0, roots);
    /* a root at depth < k_split_depth is a leaf: built whole by its task, as deeper roots are */
    atomic_store(&p->subtrees_left, n);
    p->share = k_proxy_budget / n;
    sw_result r = SW_OK;
    for (uint32_t i = 0; i < n; ++i) {
        subtree_job *job = sw__malloc(sizeof *job);
        const sw_th_task task = {subtree_task,
                                 job,
                                 SW_TH_PRIORITY_BACKGROUND,
                                 NULL,
                                 0,
                                 &p->group,
                                 sw_th_task_kind_of(&k_proxy_kind)};
        if (job)
            *job = (subtree_job){set, p, roots[i]};
        if (!job || sw_th_pool_submit(pool, &task) != SW_OK) {
            sw__free(job);
            /* the ones not submitted are built here, so that the count still ends at 0 */
            subtree_job here = {set, p, roots[i]};
            subtree_job *copy = sw__malloc(sizeof *copy);
            if (copy) {
                *copy = here;
                subtree_task(copy);
            } else {
                if (atomic_fetch_sub(&p->subtrees_left, 1) == 1)
                    atomic_store_explicit(&p->done, 1, memory_order_release);
                r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "proxies: out of memory");
            }
        }
    }
    sw__free(roots);
    return r;
}

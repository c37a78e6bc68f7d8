/* SPDX-License-Identifier: MIT */
/* Super-surface clustering, Kumar et al. 1997 §3: greedy growth over patch adjacency under a
 * bound on the cluster's normal cone, then a second pass that merges small clusters (§7.1).
 *
 * Adjacency. Inside a face, Bézier-grid neighbours (they share a knot line). Across faces, the
 * scene records only which faces share a B-rep edge; which of their patches touch along it is
 * found by sampling both faces' trim boundaries in 3D (each sample labelled with the patch whose
 * rectangle holds it) and pairing a sample of one face with a chord of the other's sampled
 * boundary when it lies within the faces' edge tolerances (plus 1 % of the chord, for its sagitta)
 * of that chord: a point of the common edge is that close to the other face's copy of the edge.
 * Chords rather than points, so that a sparse sampling of one side cannot reach around a corner.
 *
 * Growth (§3 steps 1a-1f). Seeds are taken in patch order — (face, iv, iu) ascending, the lowest
 * not yet clustered — instead of the paper's random pick, so builds are reproducible. The frontier
 * is a heap keyed by the half-angle the cluster's cone would have with the patch added (1a, "the
 * one that increases the span by the minimum amount"); the cone only grows, so a key computed
 * earlier is a lower bound of the current one and is re-evaluated lazily when it reaches the top
 * (1e). Growth stops when the smallest current key exceeds alpha (1b). The cone is kept as a
 * running merge of the patch cones (exact for two caps, looser over many); whenever the cluster
 * doubles, it is recomputed from all member cones (sw_lod_cone_enclose) and the heap re-keyed.
 *
 * Where the paper is loose: it bounds the span (largest angle between two control rays) by alpha
 * and gives no value. We bound the cone's half-angle, because back-patch culling tests a cone.
 * Default alpha = 45 degrees, i.e. no two normals of a super-surface more than 90 degrees apart
 * (a span of at most 90): the widest patches CAD kernels emit are quarter circles (rational
 * quadratic arcs, whose cone is 45 degrees), below 45 hardly any two patches of a cylinder or a
 * fillet could join (measured: at 30 degrees 331 of Motor-c's 450 patches are wider than alpha and
 * stay alone, 1.22 patches per cluster; at 45, 164 and 1.91), while a cone of 45 degrees is still
 * back-facing for (1 - sin 45) / 2 = 15 % of view directions and leaves the merge pass room below
 * 90 (merge_alpha 67.5).
 *
 * Second pass (§7.1, "a second pass, combining small super-surfaces"). A cluster with fewer than
 * min_patches patches merges into the adjacent cluster whose merged cone is smallest (tie: lower
 * index) when that cone is within merge_alpha (default 1.5 alpha); failing that, a "tiny" one —
 * box diagonal below tiny_rel of that neighbour's — merges as long as the cone stays below
 * 90 degrees (a sliver fillet is not worth its own LOD; the cone still lies in a half-space).
 * Passes repeat in cluster order until nothing merges. Merging only adjacent clusters keeps every
 * cluster connected.
 */
#include "sw_lod_hierarchy.h"
#include "sw_hooks.h"
#include "sw_lod_supersurface.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sw_lod_ss_desc_defaults(sw_lod_ss_desc *d)
{
    if (!(d->alpha_deg > 0.0))
        d->alpha_deg = 45.0;
    if (d->min_patches == 0)
        d->min_patches = 4;
    if (!(d->merge_alpha_deg > 0.0))
        d->merge_alpha_deg = 1.5 * d->alpha_deg;
    if (d->tiny_rel == 0.0)
        d->tiny_rel = 0.02;
}

/* ---- a face's patches ------------------------------------------------------------------------ */
sw_result sw_lod_face_patches(const sw_sg_scene *scene, uint32_t face, sw_sg_bezier_set *out,
                              sw_status *status)
{
    const sw_sg_face_rec *f = &sw_sg_scene_view_ptr(scene)->faces[face];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, face, &s);
    const double *box = f->uv_box;
    sw_result res =
        sw_sg_surface_extract_bezier_in(&s, box[0], box[1], box[2], box[3], out, status);
    if (res != SW_OK)
        return res;
    const int32_t np = out->n_u * out->n_v;
    if (np > 0 && (res = sw_lod_bezier_set_cut(out, box, status)) != SW_OK) {
        sw_sg_bezier_set_free(out);
        return res;
    }
    if (np == 0) {
        sw_sg_bezier_set_free(out);
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "face %u: uv box misses the domain", face);
    }
    return SW_OK;
}

/* ---- build state ----------------------------------------------------------------------------- */
typedef struct bsample {
    double p[3];
    double q[3];                 /* the next sample of its loop: the chord p-q */
    double uv[2];                /* of p */
    double mid;                  /* the chord's midpoint along its face's sweep axis (sort key) */
    uint32_t patch, chord_patch; /* global patch of p and of the chord; SW_SG_NONE: off patches */
} bsample;

typedef struct face_info {
    uint32_t first_patch, n_u, n_v;
    uint32_t first_sample, n_samples;
    double box[6]; /* of its boundary samples */
    int axis;      /* the box's longest axis: its samples are sorted along it */
} face_info;

typedef struct heap_item {
    double key;
    uint32_t patch;
} heap_item;

typedef struct state {
    const sw_sg_scene *scene;
    const sw_sg_scene_view *view;
    sw_lod_ss_desc desc;
    double alpha, merge_alpha;
    face_info *faces;
    uint32_t n_patches;
    sw_lod_ss_patch *patch;
    sw_lod_cone *cone;
    double (*box)[6];
    bsample *samples;
    size_t n_samples, cap_samples;
    sw_lod_ss_pair *pairs;
    size_t n_pairs, cap_pairs;
    uint32_t *adj_first, *adj; /* CSR over patches */
    sw_status *status;
} state;

static sw_result oom(state *st, const char *what)
{
    return sw__fail(st->status, SW_ERR_OUT_OF_MEMORY, "super-surfaces: %s", what);
}

static int push_pair(state *st, uint32_t a, uint32_t b)
{
    if (a == b)
        return 1;
    if (st->n_pairs == st->cap_pairs) {
        const size_t cap = st->cap_pairs ? 2 * st->cap_pairs : 1024;
        sw_lod_ss_pair *g = sw__realloc(st->pairs, cap * sizeof *g);
        if (!g)
            return 0;
        st->pairs = g, st->cap_pairs = cap;
    }
    st->pairs[st->n_pairs++] = (sw_lod_ss_pair){a < b ? a : b, a < b ? b : a};
    return 1;
}

static void box_empty(double *b)
{
    for (int a = 0; a < 3; ++a)
        b[a] = INFINITY, b[3 + a] = -INFINITY;
}

static void box_add_point(double *b, const double *p)
{
    for (int a = 0; a < 3; ++a)
        b[a] = fmin(b[a], p[a]), b[3 + a] = fmax(b[3 + a], p[a]);
}

static void box_add_box(double *b, const double *c)
{
    for (int a = 0; a < 3; ++a)
        b[a] = fmin(b[a], c[a]), b[3 + a] = fmax(b[3 + a], c[3 + a]);
}

static double box_diagonal(const double *b)
{
    double d = 0.0;
    for (int a = 0; a < 3; ++a)
        d += (b[3 + a] - b[a]) * (b[3 + a] - b[a]);
    return sqrt(d);
}

/* ---- patches: cones, boxes, grid adjacency --------------------------------------------------- */
static sw_result face_patches(state *st, uint32_t f, sw_sg_bezier_set *set, double **scratch,
                              size_t *cap)
{
    face_info *fi = &st->faces[f];
    const int reversed = (st->view->faces[f].flags & SW_SG_FACE_REVERSED) != 0;
    for (int32_t iv = 0; iv < set->n_v; ++iv)
        for (int32_t iu = 0; iu < set->n_u; ++iu) {
            const sw_sg_bezier_patch *p = &set->patches[iv * set->n_u + iu];
            const uint32_t g = fi->first_patch + (uint32_t)(iv * set->n_u + iu);
            st->patch[g] = (sw_lod_ss_patch){f, (uint16_t)iu, (uint16_t)iv};
            const size_t need = sw_lod_gauss_scratch_bound(p->deg_u, p->deg_v);
            if (p->deg_u <= SW_LOD_GAUSS_MAX_DEGREE && p->deg_v <= SW_LOD_GAUSS_MAX_DEGREE &&
                need > *cap) {
                double *grown = sw__realloc(*scratch, need * sizeof *grown);
                if (!grown)
                    return oom(st, "Gauss-map scratch");
                *scratch = grown, *cap = need;
            }
            sw_lod_cone *c = &st->cone[g];
            sw_lod_gauss_cone(p->deg_u, p->deg_v, p->cpw, *scratch, c);
            if (reversed)
                for (int a = 0; a < 3; ++a)
                    c->axis[a] = -c->axis[a];
            box_empty(st->box[g]);
            const int32_t ncp = (p->deg_u + 1) * (p->deg_v + 1);
            for (int32_t k = 0; k < ncp; ++k) {
                const double *h = p->cpw + 4 * k;
                const double x[3] = {h[0] / h[3], h[1] / h[3], h[2] / h[3]};
                box_add_point(st->box[g], x);
            }
            if ((iu > 0 && !push_pair(st, g - 1, g)) ||
                (iv > 0 && !push_pair(st, g - (uint32_t)set->n_u, g)))
                return oom(st, "adjacency");
        }
    return SW_OK;
}

/* ---- boundary samples ------------------------------------------------------------------------ */
/* Index of the cell of the sorted breakpoints lo[0..n) (cell k spans [lo[k], next lo)) holding t.
 */
static uint32_t cell_of(const sw_sg_bezier_set *set, int dir, double t)
{
    const int32_t n = dir ? set->n_v : set->n_u;
    int32_t a = 0, b = n - 1;
    while (a < b) {
        const int32_t m = (a + b + 1) / 2;
        const sw_sg_bezier_patch *p = &set->patches[dir ? m * set->n_u : m];
        if ((dir ? p->v0 : p->u0) <= t)
            a = m;
        else
            b = m - 1;
    }
    return (uint32_t)a;
}

static uint32_t patch_at(const sw_sg_bezier_set *set, uint32_t first_patch, double u, double v)
{
    return first_patch + cell_of(set, 1, v) * (uint32_t)set->n_u + cell_of(set, 0, u);
}

/* Appends a sample at (u, v); one outside the extracted patches (a loop bulging past uv_box) lies
 * on none of them and is kept unlabelled (patch SW_SG_NONE), so no chord spans the gap. */
static int push_sample(state *st, const sw_sg_surface *s, const sw_sg_bezier_set *set,
                       uint32_t first_patch, double u, double v)
{
    if (st->n_samples == st->cap_samples) {
        const size_t cap = st->cap_samples ? 2 * st->cap_samples : 4096;
        bsample *g = sw__realloc(st->samples, cap * sizeof *g);
        if (!g)
            return 0;
        st->samples = g, st->cap_samples = cap;
    }
    bsample *b = &st->samples[st->n_samples++];
    b->uv[0] = u, b->uv[1] = v;
    const sw_sg_bezier_patch *lo = &set->patches[0], *hi = &set->patches[set->n_u * set->n_v - 1];
    const double su = 1e-9 * (hi->u1 - lo->u0), sv = 1e-9 * (hi->v1 - lo->v0);
    sw_sg_surface_eval(s, u, v, b->p);
    b->patch = u < lo->u0 - su || u > hi->u1 + su || v < lo->v0 - sv || v > hi->v1 + sv
                   ? SW_SG_NONE
                   : patch_at(set, first_patch, u, v);
    return 1;
}

#define SW__SAMPLES_PER_FACE 4096

static int cmp_t(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Appends to ts the parameters in (0, 1) where the segment a-b of one coordinate crosses a knot
 * line of the patch grid along dir. */
static size_t crossings(const sw_sg_bezier_set *set, int dir, double a, double b, double *ts,
                        size_t n)
{
    const double lo = fmin(a, b), hi = fmax(a, b);
    const int32_t cells = dir ? set->n_v : set->n_u;
    for (int32_t c = 1; c < cells && hi > lo; ++c) {
        const double x = dir ? set->patches[c * set->n_u].v0 : set->patches[c].u0;
        if (lo < x && x < hi)
            ts[n++] = (x - a) / (b - a);
    }
    return n;
}

/* Samples one closed polyline of the face's boundary at uv steps of at most h and at every knot
 * line it crosses, so that each chord between consecutive samples lies in one patch. */
static int sample_polyline(state *st, const sw_sg_surface *s, const sw_sg_bezier_set *set,
                           uint32_t first_patch, const double *uv, uint32_t count, double h)
{
    const size_t start = st->n_samples;
    double *ts = sw__malloc(
        ((size_t)SW__SAMPLES_PER_FACE + (size_t)set->n_u + (size_t)set->n_v + 1) * sizeof *ts);
    if (!ts)
        return 0;
    for (uint32_t k = 0; k < count; ++k) {
        const double *a = uv + 2 * k, *b = uv + 2 * ((k + 1) % count);
        const double len = hypot(b[0] - a[0], b[1] - a[1]);
        const int32_t steps = (int32_t)fmin(ceil(len / h), SW__SAMPLES_PER_FACE);
        size_t n = 0;
        for (int32_t i = 0; i < (steps > 0 ? steps : 1); ++i)
            ts[n++] = steps > 0 ? (double)i / steps : 0.0;
        n = crossings(set, 0, a[0], b[0], ts, n);
        n = crossings(set, 1, a[1], b[1], ts, n);
        qsort(ts, n, sizeof *ts, cmp_t);
        for (size_t i = 0; i < n; ++i)
            if (!push_sample(st, s, set, first_patch, a[0] + ts[i] * (b[0] - a[0]),
                             a[1] + ts[i] * (b[1] - a[1]))) {
                sw__free(ts);
                return 0;
            }
    }
    sw__free(ts);
    const size_t n = st->n_samples - start;
    for (size_t k = 0; k < n; ++k) {
        bsample *c = &st->samples[start + k];
        const bsample *nx = &st->samples[start + (k + 1) % n];
        memcpy(c->q, nx->p, sizeof c->q);
        c->chord_patch = c->patch == SW_SG_NONE || nx->patch == SW_SG_NONE
                             ? SW_SG_NONE
                             : patch_at(set, first_patch, 0.5 * (c->uv[0] + nx->uv[0]),
                                        0.5 * (c->uv[1] + nx->uv[1]));
    }
    return 1;
}

static sw_result face_samples(state *st, uint32_t f, const sw_sg_bezier_set *set)
{
    const sw_sg_face_rec *rec = &st->view->faces[f];
    face_info *fi = &st->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(st->scene, f, &s);
    const double *bx = rec->uv_box;
    /* steps: a quarter of the narrowest patch and 1/256 of the box's perimeter (short chords keep
     * their sagitta small), but not more than the per-face budget */
    const double perimeter = 2.0 * ((bx[1] - bx[0]) + (bx[3] - bx[2]));
    double h = perimeter / 256.0;
    for (int32_t k = 0; k < set->n_u * set->n_v; ++k) {
        const sw_sg_bezier_patch *p = &set->patches[k];
        h = fmin(h, 0.25 * fmin(p->u1 - p->u0, p->v1 - p->v0));
    }
    h = fmax(h, perimeter / SW__SAMPLES_PER_FACE);
    fi->first_sample = (uint32_t)st->n_samples;
    if (rec->n_loops == 0) {
        const double rect[8] = {bx[0], bx[2], bx[1], bx[2], bx[1], bx[3], bx[0], bx[3]};
        if (!sample_polyline(st, &s, set, fi->first_patch, rect, 4, h))
            return oom(st, "boundary samples");
    }
    for (uint32_t l = 0; l < rec->n_loops; ++l) {
        sw_sg_polyline poly;
        const double tol = 1e-4 * fmax(bx[1] - bx[0], bx[3] - bx[2]);
        sw_result r = sw_sg_trim_flatten_loop(st->scene, rec->first_loop + l, tol, 1u << 16, &poly,
                                              st->status);
        if (r != SW_OK)
            return r;
        const int ok = sample_polyline(st, &s, set, fi->first_patch, poly.uv, poly.count, h);
        sw_sg_polyline_free(&poly);
        if (!ok)
            return oom(st, "boundary samples");
    }
    fi->n_samples = (uint32_t)(st->n_samples - fi->first_sample);
    box_empty(fi->box);
    for (uint32_t k = 0; k < fi->n_samples; ++k)
        if (st->samples[fi->first_sample + k].patch != SW_SG_NONE)
            box_add_point(fi->box, st->samples[fi->first_sample + k].p);
    return SW_OK;
}

static int cmp_sample_mid(const void *a, const void *b)
{
    const bsample *x = a, *y = b;
    if (x->mid != y->mid)
        return x->mid < y->mid ? -1 : 1;
    return (x->patch > y->patch) - (x->patch < y->patch);
}

static double dist2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
           (a[2] - b[2]) * (a[2] - b[2]);
}

/* Distance from x to the chord p-q; *t gets the parameter of the nearest point. */
static double chord_distance(const double *x, const double *p, const double *q, double *t)
{
    double d[3], w[3];
    for (int a = 0; a < 3; ++a)
        d[a] = q[a] - p[a], w[a] = x[a] - p[a];
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    double s = dd > 0.0 ? (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    const double y[3] = {p[0] + s * d[0], p[1] + s * d[1], p[2] + s * d[2]};
    *t = s;
    return sqrt(dist2(x, y));
}

/* Patch pairs from the samples of face fa near the chords of face fb (fb's sorted by mid). */
static int match_faces(state *st, uint32_t fa, uint32_t fb)
{
    const face_info *A = &st->faces[fa], *B = &st->faces[fb];
    const double tol = st->view->faces[fa].tolerance + st->view->faces[fb].tolerance +
                       1e-9 * fmax(box_diagonal(A->box), box_diagonal(B->box));
    const bsample *sb = st->samples + B->first_sample;
    double half = 0.0;
    for (uint32_t k = 0; k < B->n_samples; ++k)
        if (sb[k].chord_patch != SW_SG_NONE)
            half = fmax(half, 0.5 * sqrt(dist2(sb[k].p, sb[k].q)));
    const double reach = 1.03 * half + tol;
    const int ax = B->axis;
    for (uint32_t i = 0; i < A->n_samples; ++i) {
        const bsample *a = &st->samples[A->first_sample + i];
        if (a->patch == SW_SG_NONE || a->p[0] < B->box[0] - reach || a->p[0] > B->box[3] + reach ||
            a->p[1] < B->box[1] - reach || a->p[1] > B->box[4] + reach ||
            a->p[2] < B->box[2] - reach || a->p[2] > B->box[5] + reach)
            continue;
        uint32_t lo = 0, hi = B->n_samples;
        while (lo < hi) {
            const uint32_t m = (lo + hi) / 2;
            if (sb[m].mid < a->p[ax] - reach)
                lo = m + 1;
            else
                hi = m;
        }
        for (uint32_t k = lo; k < B->n_samples && sb[k].mid <= a->p[ax] + reach; ++k) {
            if (sb[k].chord_patch == SW_SG_NONE)
                continue;
            double t;
            const double d = chord_distance(a->p, sb[k].p, sb[k].q, &t);
            if (d <= tol + 0.01 * sqrt(dist2(sb[k].p, sb[k].q)) &&
                !push_pair(st, a->patch, sb[k].chord_patch))
                return 0;
        }
    }
    return 1;
}

static int cmp_pair(const void *a, const void *b)
{
    const sw_lod_ss_pair *x = a, *y = b;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    return (x->b > y->b) - (x->b < y->b);
}

/* Sorts and dedups the pairs and builds the CSR neighbour lists. */
static sw_result build_adjacency(state *st)
{
    if (st->n_pairs)
        qsort(st->pairs, st->n_pairs, sizeof *st->pairs, cmp_pair);
    size_t n = 0;
    for (size_t k = 0; k < st->n_pairs; ++k)
        if (n == 0 || cmp_pair(&st->pairs[n - 1], &st->pairs[k]) != 0)
            st->pairs[n++] = st->pairs[k];
    st->n_pairs = n;
    st->adj_first = sw__calloc((size_t)st->n_patches + 1, sizeof *st->adj_first);
    st->adj = sw__malloc((2 * n + 1) * sizeof *st->adj);
    if (!st->adj_first || !st->adj)
        return oom(st, "adjacency lists");
    for (size_t k = 0; k < n; ++k)
        ++st->adj_first[st->pairs[k].a + 1], ++st->adj_first[st->pairs[k].b + 1];
    for (uint32_t p = 0; p < st->n_patches; ++p)
        st->adj_first[p + 1] += st->adj_first[p];
    uint32_t *fill = sw__malloc(((size_t)st->n_patches + 1) * sizeof *fill);
    if (!fill)
        return oom(st, "adjacency lists");
    memcpy(fill, st->adj_first, (size_t)st->n_patches * sizeof *fill);
    for (size_t k = 0; k < n; ++k) {
        st->adj[fill[st->pairs[k].a]++] = st->pairs[k].b;
        st->adj[fill[st->pairs[k].b]++] = st->pairs[k].a;
    }
    sw__free(fill);
    return SW_OK;
}

/* ---- growth ---------------------------------------------------------------------------------- */
typedef struct heap {
    heap_item *items;
    size_t n, cap;
} heap;

static int item_less(const heap_item *a, const heap_item *b)
{
    return a->key < b->key || (a->key == b->key && a->patch < b->patch);
}

static int heap_push(heap *h, heap_item it)
{
    if (h->n == h->cap) {
        const size_t cap = h->cap ? 2 * h->cap : 256;
        heap_item *g = sw__realloc(h->items, cap * sizeof *g);
        if (!g)
            return 0;
        h->items = g, h->cap = cap;
    }
    size_t i = h->n++;
    while (i > 0 && item_less(&it, &h->items[(i - 1) / 2])) {
        h->items[i] = h->items[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->items[i] = it;
    return 1;
}

static void sift_down(heap *h, size_t i)
{
    const heap_item it = h->items[i];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && item_less(&h->items[c + 1], &h->items[c]))
            ++c;
        if (!item_less(&h->items[c], &it))
            break;
        h->items[i] = h->items[c];
        i = c;
    }
    h->items[i] = it;
}

static heap_item heap_pop(heap *h)
{
    const heap_item top = h->items[0];
    h->items[0] = h->items[--h->n];
    if (h->n)
        sift_down(h, 0);
    return top;
}

static void heapify(heap *h)
{
    for (size_t i = h->n / 2; i-- > 0;)
        sift_down(h, i);
}

typedef struct grow {
    uint32_t *cluster_of; /* per patch, UINT32_MAX while unclustered */
    uint32_t *members;    /* scratch: patches of the cluster being grown */
    sw_lod_cone *scratch_cones;
    heap frontier;
} grow;

static double merged_angle(const sw_lod_cone *c, const sw_lod_cone *p)
{
    sw_lod_cone m;
    sw_lod_cone_merge(c, p, &m);
    return m.half_angle;
}

static void enclose_members(const state *st, grow *g, uint32_t n, sw_lod_cone *out)
{
    for (uint32_t k = 0; k < n; ++k)
        g->scratch_cones[k] = st->cone[g->members[k]];
    sw_lod_cone_enclose(g->scratch_cones, n, out);
}

/* Pushes the unclustered neighbours of patch p, keyed against cone c. */
static int push_neighbours(const state *st, grow *g, uint32_t p, const sw_lod_cone *c)
{
    for (uint32_t k = st->adj_first[p]; k < st->adj_first[p + 1]; ++k) {
        const uint32_t q = st->adj[k];
        if (g->cluster_of[q] == UINT32_MAX &&
            !heap_push(&g->frontier, (heap_item){merged_angle(c, &st->cone[q]), q}))
            return 0;
    }
    return 1;
}

/* Grows the cluster `id` from `seed`; returns its size, 0 when out of memory. */
static uint32_t grow_cluster(const state *st, grow *g, uint32_t id, uint32_t seed,
                             sw_lod_cone *cone)
{
    *cone = st->cone[seed];
    g->cluster_of[seed] = id;
    g->members[0] = seed;
    uint32_t n = 1, next_tighten = 8;
    g->frontier.n = 0;
    if (cone->half_angle > st->alpha)
        return 1; /* cannot take a neighbour: any merge is at least this wide */
    if (!push_neighbours(st, g, seed, cone))
        return 0;
    while (g->frontier.n) {
        heap_item it = heap_pop(&g->frontier);
        if (g->cluster_of[it.patch] != UINT32_MAX)
            continue;
        const double key = merged_angle(cone, &st->cone[it.patch]);
        if (key > it.key && g->frontier.n && key > g->frontier.items[0].key) {
            it.key = key; /* stale: the cone grew since it was pushed */
            if (!heap_push(&g->frontier, it))
                return 0;
            continue;
        }
        if (key > st->alpha)
            break; /* the smallest widening already exceeds alpha (§3 step 1b) */
        sw_lod_cone merged;
        sw_lod_cone_merge(cone, &st->cone[it.patch], &merged);
        *cone = merged;
        g->cluster_of[it.patch] = id;
        g->members[n++] = it.patch;
        if (n == next_tighten) {
            next_tighten *= 2;
            sw_lod_cone tight;
            enclose_members(st, g, n, &tight);
            if (tight.half_angle < cone->half_angle) {
                *cone = tight;
                for (size_t k = 0; k < g->frontier.n; ++k)
                    g->frontier.items[k].key =
                        merged_angle(cone, &st->cone[g->frontier.items[k].patch]);
                heapify(&g->frontier);
            }
        }
        if (!push_neighbours(st, g, it.patch, cone))
            return 0;
    }
    return n;
}

/* ---- second pass ----------------------------------------------------------------------------- */
typedef struct cl {
    sw_lod_cone cone;
    double box[6];
    uint32_t count, flags, parent; /* union-find parent (itself when a root) */
    uint32_t next, tail;           /* chain of the grown clusters merged into a root */
} cl;

/* The grown clusters' patches, grouped: cluster k's are patches[first[k], first[k + 1]). */
typedef struct members_csr {
    uint32_t *first, *patches;
} members_csr;

static uint32_t find_root(cl *c, uint32_t k)
{
    while (c[k].parent != k) {
        c[k].parent = c[c[k].parent].parent;
        k = c[k].parent;
    }
    return k;
}

/* One merge pass; returns how many clusters merged. */
static uint32_t merge_pass(const state *st, cl *c, uint32_t n_cl, const uint32_t *cluster_of,
                           const members_csr *mem)
{
    uint32_t merged = 0;
    for (uint32_t s = 0; s < n_cl; ++s) {
        if (c[s].parent != s || c[s].count >= st->desc.min_patches || c[s].cone.half_angle >= M_PI)
            continue;
        uint32_t best = UINT32_MAX;
        sw_lod_cone best_cone = {{0, 0, 1}, M_PI, -1.0};
        /* neighbours: clusters of the patches adjacent to s's patches */
        for (uint32_t o = s; o != UINT32_MAX; o = c[o].next)
            for (uint32_t i = mem->first[o]; i < mem->first[o + 1]; ++i) {
                const uint32_t p = mem->patches[i];
                for (uint32_t k = st->adj_first[p]; k < st->adj_first[p + 1]; ++k) {
                    const uint32_t t = find_root(c, cluster_of[st->adj[k]]);
                    if (t == s)
                        continue;
                    sw_lod_cone m;
                    sw_lod_cone_merge(&c[s].cone, &c[t].cone, &m);
                    if (m.half_angle < best_cone.half_angle ||
                        (m.half_angle == best_cone.half_angle && t < best))
                        best = t, best_cone = m;
                }
            }
        if (best == UINT32_MAX)
            continue;
        uint32_t flag = 0;
        if (best_cone.half_angle <= st->merge_alpha)
            flag = SW_LOD_SS_MERGED;
        else if (st->desc.tiny_rel > 0.0 && best_cone.half_angle < 0.5 * M_PI &&
                 box_diagonal(c[s].box) < st->desc.tiny_rel * box_diagonal(c[best].box))
            flag = SW_LOD_SS_MERGED_TINY;
        if (!flag)
            continue;
        /* the lower index survives, so the survivor's seed stays its smallest patch */
        const uint32_t keep = s < best ? s : best, gone = s < best ? best : s;
        c[keep].cone = best_cone;
        box_add_box(c[keep].box, c[gone].box);
        c[keep].count += c[gone].count;
        c[keep].flags |= c[gone].flags | flag;
        c[gone].parent = keep;
        c[c[keep].tail].next = gone;
        c[keep].tail = c[gone].tail;
        ++merged;
    }
    return merged;
}

/* ---- output ---------------------------------------------------------------------------------- */

/* Kumar §4.4: a super-surface may be culled from behind only when every face of it belongs to a
 * closed, consistently oriented shell (the importer's SW_SG_FACE_CLOSED_SHELL). */
static int all_closed_shell(const sw_sg_scene *scene, const sw_lod_supersurfaces *ss,
                            const sw_lod_ss_cluster *cluster)
{
    const sw_sg_face_rec *faces = sw_sg_scene_view_ptr(scene)->faces;
    for (uint32_t k = cluster->first; k < cluster->first + cluster->count; ++k)
        if (!(faces[ss->patches[k].face].flags & SW_SG_FACE_CLOSED_SHELL))
            return 0;
    return cluster->count > 0;
}

static sw_result make_output(state *st, cl *c, uint32_t n_cl, const uint32_t *cluster_of,
                             sw_lod_supersurfaces **out)
{
    sw_lod_supersurfaces *ss = sw__calloc(1, sizeof *ss);
    if (!ss)
        return oom(st, "output");
    *out = ss;
    const uint32_t np = st->n_patches;
    uint32_t *out_index = sw__malloc((size_t)n_cl * sizeof *out_index);
    uint32_t *pos = sw__malloc((size_t)np * sizeof *pos);
    ss->patches = sw__malloc((size_t)np * sizeof *ss->patches);
    ss->patch_cones = sw__malloc((size_t)np * sizeof *ss->patch_cones);
    ss->cluster_of = sw__malloc((size_t)np * sizeof *ss->cluster_of);
    ss->clusters = sw__calloc((size_t)n_cl, sizeof *ss->clusters);
    ss->adjacency = sw__malloc((st->n_pairs + 1) * sizeof *ss->adjacency);
    if (!out_index || !pos || !ss->patches || !ss->patch_cones || !ss->cluster_of ||
        !ss->clusters || !ss->adjacency) {
        sw__free(out_index);
        sw__free(pos);
        return oom(st, "output");
    }
    /* clusters numbered by their smallest patch, i.e. in order of first appearance */
    uint32_t n_out = 0;
    for (uint32_t k = 0; k < n_cl; ++k)
        out_index[k] = UINT32_MAX;
    for (uint32_t p = 0; p < np; ++p) {
        const uint32_t r = find_root(c, cluster_of[p]);
        if (out_index[r] == UINT32_MAX)
            out_index[r] = n_out++;
        ++ss->clusters[out_index[r]].count;
    }
    uint32_t at = 0;
    for (uint32_t k = 0; k < n_out; ++k) {
        ss->clusters[k].first = at;
        at += ss->clusters[k].count;
        ss->clusters[k].count = 0;
    }
    for (uint32_t p = 0; p < np; ++p) {
        const uint32_t r = find_root(c, cluster_of[p]);
        sw_lod_ss_cluster *o = &ss->clusters[out_index[r]];
        const uint32_t i = o->first + o->count++;
        pos[p] = i;
        ss->patches[i] = st->patch[p];
        ss->patch_cones[i] = st->cone[p];
        ss->cluster_of[i] = out_index[r];
    }
    for (uint32_t r = 0; r < n_cl; ++r) {
        if (out_index[r] == UINT32_MAX)
            continue;
        sw_lod_ss_cluster *o = &ss->clusters[out_index[r]];
        /* the tighter of the grown cone and one enclosing all member cones: both contain them */
        sw_lod_cone cone = c[r].cone;
        if (cone.half_angle < M_PI) {
            sw_lod_cone tight;
            sw_lod_cone_enclose(ss->patch_cones + o->first, o->count, &tight);
            if (tight.half_angle < cone.half_angle)
                cone = tight;
        }
        memcpy(o->axis, cone.axis, sizeof o->axis);
        o->cos_half_angle = cone.cos_half_angle;
        o->half_angle = cone.half_angle;
        memcpy(o->box, c[r].box, sizeof o->box);
        o->flags = c[r].flags | (all_closed_shell(st->scene, ss, o) ? SW_LOD_SS_BACK_CULLABLE : 0);
    }
    for (size_t k = 0; k < st->n_pairs; ++k) {
        const uint32_t a = pos[st->pairs[k].a], b = pos[st->pairs[k].b];
        ss->adjacency[k] = (sw_lod_ss_pair){a < b ? a : b, a < b ? b : a};
    }
    ss->n_adjacency = (uint32_t)st->n_pairs;
    if (st->n_pairs)
        qsort(ss->adjacency, st->n_pairs, sizeof *ss->adjacency, cmp_pair);
    ss->n_patches = np;
    ss->n_clusters = n_out;
    ss->alpha = st->alpha;
    ss->merge_alpha = st->merge_alpha;
    sw__free(out_index);
    sw__free(pos);
    return SW_OK;
}

/* ---- driver ---------------------------------------------------------------------------------- */
/* The faces of the scene's adjacency records (cross_face_pairs matches their boundary samples);
 * NULL when out of memory. */
static unsigned char *faces_paired(const state *st)
{
    const uint32_t nf = st->view->n_faces;
    unsigned char *paired = sw__calloc((size_t)nf + 1, 1);
    for (uint32_t k = 0; paired && k < st->view->n_adjacency; ++k) {
        const sw_sg_adjacency_rec *a = &st->view->adjacency[k];
        if (a->face_a < nf && a->face_b < nf && a->face_a != a->face_b)
            paired[a->face_a] = paired[a->face_b] = 1;
    }
    return paired;
}

static sw_result collect_patches(state *st)
{
    const uint32_t nf = st->view->n_faces;
    uint64_t total = 0;
    double *scratch = NULL;
    size_t cap = 0;
    /* boundary samples only for faces with an adjacency record: no other face's are read, and a
     * generated building of 10^6 surfaces (1,737 records) sampled every face, ~10 GB at once */
    unsigned char *paired = faces_paired(st);
    sw_result res = paired ? SW_OK : oom(st, "faces");
    /* two sweeps over the faces: counts first (to size the arrays), then cones and samples */
    for (int sweep = 0; sweep < 2 && res == SW_OK; ++sweep) {
        if (sweep == 1) {
            if (total > UINT32_MAX - 1) {
                res = sw__fail(st->status, SW_ERR_LIMIT, "super-surfaces: %llu patches",
                               (unsigned long long)total);
                break;
            }
            st->n_patches = (uint32_t)total;
            st->patch = sw__malloc((total + 1) * sizeof *st->patch);
            st->cone = sw__malloc((total + 1) * sizeof *st->cone);
            st->box = sw__malloc((total + 1) * sizeof *st->box);
            if (!st->patch || !st->cone || !st->box) {
                res = oom(st, "patches");
                break;
            }
        }
        total = 0;
        for (uint32_t f = 0; f < nf && res == SW_OK; ++f) {
            sw_sg_bezier_set set;
            res = sw_lod_face_patches(st->scene, f, &set, st->status);
            if (res != SW_OK)
                break;
            if (set.n_u > 65535 || set.n_v > 65535)
                res = sw__fail(st->status, SW_ERR_LIMIT, "face %u: %d x %d patches", f,
                               (int)set.n_u, (int)set.n_v);
            else if (sweep == 0) {
                st->faces[f].first_patch = (uint32_t)total;
                st->faces[f].n_u = (uint32_t)set.n_u;
                st->faces[f].n_v = (uint32_t)set.n_v;
            } else {
                res = face_patches(st, f, &set, &scratch, &cap);
                st->faces[f].first_sample = (uint32_t)st->n_samples;
                if (res == SW_OK && paired[f])
                    res = face_samples(st, f, &set);
            }
            total += (uint64_t)set.n_u * (uint64_t)set.n_v;
            sw_sg_bezier_set_free(&set);
        }
    }
    sw__free(scratch);
    sw__free(paired);
    return res;
}

static sw_result cross_face_pairs(state *st)
{
    const uint32_t nf = st->view->n_faces;
    /* per face, its chords sorted along its longest axis for the sweep in match_faces */
    for (uint32_t f = 0; f < nf; ++f) {
        face_info *fi = &st->faces[f];
        if (!fi->n_samples)
            continue;
        const double *b = fi->box;
        fi->axis = b[4] - b[1] > b[3] - b[0] ? 1 : 0;
        fi->axis = b[5] - b[2] > b[3 + fi->axis] - b[fi->axis] ? 2 : fi->axis;
        bsample *sm = st->samples + fi->first_sample;
        for (uint32_t k = 0; k < fi->n_samples; ++k)
            sm[k].mid = 0.5 * (sm[k].p[fi->axis] + sm[k].q[fi->axis]);
        qsort(sm, fi->n_samples, sizeof *sm, cmp_sample_mid);
    }
    for (uint32_t k = 0; k < st->view->n_adjacency; ++k) {
        const sw_sg_adjacency_rec *a = &st->view->adjacency[k];
        if (a->face_a >= nf || a->face_b >= nf || a->face_a == a->face_b)
            continue;
        if (!match_faces(st, a->face_a, a->face_b) || !match_faces(st, a->face_b, a->face_a))
            return oom(st, "adjacency");
    }
    return SW_OK;
}

static sw_result cluster(state *st, sw_lod_supersurfaces **out)
{
    const uint32_t np = st->n_patches;
    grow g = {0};
    g.cluster_of = sw__malloc((np + 1) * sizeof *g.cluster_of);
    g.members = sw__malloc((np + 1) * sizeof *g.members);
    g.scratch_cones = sw__malloc((np + 1) * sizeof *g.scratch_cones);
    cl *c = sw__malloc((np + 1) * sizeof *c);
    sw_result res = SW_OK;
    if (!g.cluster_of || !g.members || !g.scratch_cones || !c)
        res = oom(st, "clusters");
    uint32_t n_cl = 0;
    if (res == SW_OK) {
        for (uint32_t p = 0; p < np; ++p)
            g.cluster_of[p] = UINT32_MAX;
        for (uint32_t seed = 0; seed < np && res == SW_OK; ++seed) {
            if (g.cluster_of[seed] != UINT32_MAX)
                continue;
            cl *k = &c[n_cl];
            const uint32_t n = grow_cluster(st, &g, n_cl, seed, &k->cone);
            if (n == 0) {
                res = oom(st, "frontier");
                break;
            }
            k->count = n;
            k->parent = k->tail = n_cl;
            k->next = UINT32_MAX;
            k->flags = k->cone.half_angle >= M_PI ? SW_LOD_SS_FULL_CONE : 0;
            box_empty(k->box);
            for (uint32_t m = 0; m < n; ++m)
                box_add_box(k->box, st->box[g.members[m]]);
            ++n_cl;
        }
    }
    members_csr mem = {NULL, NULL};
    if (res == SW_OK) {
        mem.first = sw__calloc((size_t)n_cl + 2, sizeof *mem.first);
        mem.patches = sw__malloc((np + 1) * sizeof *mem.patches);
        if (!mem.first || !mem.patches)
            res = oom(st, "cluster members");
    }
    if (res == SW_OK) {
        for (uint32_t p = 0; p < np; ++p)
            ++mem.first[g.cluster_of[p] + 1];
        for (uint32_t k = 0; k < n_cl; ++k)
            mem.first[k + 1] += mem.first[k];
        /* g.members is free now: use it as the fill cursor */
        memcpy(g.members, mem.first, (size_t)n_cl * sizeof *g.members);
        for (uint32_t p = 0; p < np; ++p)
            mem.patches[g.members[g.cluster_of[p]]++] = p;
        while (merge_pass(st, c, n_cl, g.cluster_of, &mem) > 0) {
        }
        res = make_output(st, c, n_cl, g.cluster_of, out);
    }
    sw__free(mem.first);
    sw__free(mem.patches);
    sw__free(g.cluster_of);
    sw__free(g.members);
    sw__free(g.scratch_cones);
    sw__free(g.frontier.items);
    sw__free(c);
    return res;
}

sw_result sw_lod_supersurfaces_build(const sw_sg_scene *scene, const sw_lod_ss_desc *desc,
                                     sw_lod_supersurfaces **out, sw_status *status)
{
    *out = NULL;
    state st = {0};
    st.scene = scene;
    st.status = status;
    if (desc)
        st.desc = *desc;
    sw_lod_ss_desc_defaults(&st.desc);
    if (!(st.desc.alpha_deg < 180.0) || !(st.desc.merge_alpha_deg >= st.desc.alpha_deg) ||
        !(st.desc.merge_alpha_deg < 180.0) || !isfinite(st.desc.tiny_rel))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "super-surfaces: alpha %g, merge alpha %g, tiny %g (need 0 < alpha <= "
                        "merge alpha < 180)",
                        st.desc.alpha_deg, st.desc.merge_alpha_deg, st.desc.tiny_rel);
    st.view = sw_sg_scene_view_ptr(scene);
    st.alpha = st.desc.alpha_deg * M_PI / 180.0;
    st.merge_alpha = st.desc.merge_alpha_deg * M_PI / 180.0;
    st.faces = sw__calloc((size_t)st.view->n_faces + 1, sizeof *st.faces);
    sw_result res = st.faces ? SW_OK : oom(&st, "faces");
    if (res == SW_OK)
        res = collect_patches(&st);
    if (res == SW_OK)
        res = cross_face_pairs(&st);
    if (res == SW_OK)
        res = build_adjacency(&st);
    if (res == SW_OK)
        res = cluster(&st, out);
    sw__free(st.faces);
    sw__free(st.patch);
    sw__free(st.cone);
    sw__free(st.box);
    sw__free(st.samples);
    sw__free(st.pairs);
    sw__free(st.adj_first);
    sw__free(st.adj);
    if (res != SW_OK) {
        sw_lod_supersurfaces_free(*out);
        *out = NULL;
        return res;
    }
    sw__status_ok(status);
    return SW_OK;
}

void sw_lod_supersurfaces_free(sw_lod_supersurfaces *ss)
{
    if (!ss)
        return;
    sw__free(ss->patches);
    sw__free(ss->patch_cones);
    sw__free(ss->cluster_of);
    sw__free(ss->clusters);
    sw__free(ss->adjacency);
    sw__free(ss);
}

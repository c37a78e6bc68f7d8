/* SPDX-License-Identifier: MIT */
/* The BVH over face occurrences or caller-made items (sw_sg_bvh.h). */
#include "sw_sg_bvh.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct build {
    const sw_sg_scene *scene;
    double *face_box; /* 6 per face, local; NaN[0] until computed */
    sw_sg_bvh_item *items;
    size_t n_items, cap_items;
    int oom;
} build;

void sw_sg_bvh_face_box(const sw_sg_scene *scene, uint32_t face, double box[6])
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, face, &s);
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    const size_t n = (size_t)s.n_u * (size_t)s.n_v;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = s.cpw[4 * i + k] / s.cpw[4 * i + 3];
            box[k] = fmin(box[k], x);
            box[3 + k] = fmax(box[3 + k], x);
        }
}

int sw_sg_to_local(const double m[12], const double p[3], const double d[3], double lp[3],
                   double ld[3])
{
    const double a[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
    const double inv[9] = {
        /* cofactors, transposed: M^-1 = inv / det */
        a[4] * a[8] - a[5] * a[7], a[2] * a[7] - a[1] * a[8], a[1] * a[5] - a[2] * a[4],
        a[5] * a[6] - a[3] * a[8], a[0] * a[8] - a[2] * a[6], a[2] * a[3] - a[0] * a[5],
        a[3] * a[7] - a[4] * a[6], a[1] * a[6] - a[0] * a[7], a[0] * a[4] - a[1] * a[3]};
    const double det = a[0] * inv[0] + a[1] * inv[3] + a[2] * inv[6];
    if (!(fabs(det) > 1e-300))
        return 0;
    int finite = 1;
    if (p) {
        const double rel[3] = {p[0] - m[3], p[1] - m[7], p[2] - m[11]};
        for (int i = 0; i < 3; ++i) {
            lp[i] = (inv[3 * i] * rel[0] + inv[3 * i + 1] * rel[1] + inv[3 * i + 2] * rel[2]) / det;
            finite &= isfinite(lp[i]);
        }
    }
    if (d)
        for (int i = 0; i < 3; ++i) {
            ld[i] = (inv[3 * i] * d[0] + inv[3 * i + 1] * d[1] + inv[3 * i + 2] * d[2]) / det;
            finite &= isfinite(ld[i]);
        }
    return finite;
}

void sw_sg_box_transform(const double m[12], const double b[6], double out[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = INFINITY;
        out[3 + k] = -INFINITY;
    }
    for (int c = 0; c < 8; ++c) {
        const double p[3] = {b[(c & 1) ? 3 : 0], b[(c & 2) ? 4 : 1], b[(c & 4) ? 5 : 2]};
        for (int r = 0; r < 3; ++r) {
            double x = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
            out[r] = fmin(out[r], x);
            out[3 + r] = fmax(out[3 + r], x);
        }
    }
}

static int visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    build *b = ctx;
    if (b->n_items == b->cap_items) {
        size_t cap = b->cap_items ? 2 * b->cap_items : 256;
        sw_sg_bvh_item *p = cap <= INT32_MAX ? sw__realloc(b->items, cap * sizeof *p) : NULL;
        if (!p) {
            b->oom = 1;
            return 1;
        }
        b->items = p;
        b->cap_items = cap;
    }
    double *lb = b->face_box + 6 * (size_t)face;
    if (isnan(lb[0]))
        sw_sg_bvh_face_box(b->scene, face, lb);
    sw_sg_bvh_item *it = &b->items[b->n_items++];
    memcpy(it->world, world, sizeof it->world);
    sw_sg_box_transform(world, lb, it->box);
    static const float k_none[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
    memcpy(it->color, color ? color : k_none, sizeof it->color);
    it->face = face;
    return 0;
}

static void box_union(double out[6], const double b[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = fmin(out[k], b[k]);
        out[3 + k] = fmax(out[3 + k], b[3 + k]);
    }
}

static double centre(const sw_sg_bvh_item *it, int axis)
{
    return 0.5 * (it->box[axis] + it->box[3 + axis]);
}

static void swap_items(sw_sg_bvh_item *a, sw_sg_bvh_item *b)
{
    sw_sg_bvh_item t = *a;
    *a = *b;
    *b = t;
}

/* Quickselect (Lomuto partition, middle pivot): afterwards the item at mid has its sorted place
 * along axis among [lo, hi), smaller centres before it and larger after. */
static void select_median(sw_sg_bvh_item *items, uint32_t lo, uint32_t hi, uint32_t mid, int axis)
{
    int64_t l = lo, h = (int64_t)hi - 1;
    while (l < h) {
        swap_items(&items[l + (h - l) / 2], &items[h]);
        const double pivot = centre(&items[h], axis);
        int64_t store = l;
        for (int64_t i = l; i < h; ++i)
            if (centre(&items[i], axis) < pivot)
                swap_items(&items[i], &items[store++]);
        swap_items(&items[store], &items[h]);
        if (store == (int64_t)mid)
            return;
        if ((int64_t)mid < store)
            h = store - 1;
        else
            l = store + 1;
    }
}

/* Builds the subtree of items [lo, hi); returns its node index (nodes preallocated: 2n - 1 at
 * most, so pointers into them stay valid). Recursion depth is O(log n): median splits. */
static uint32_t build_node(sw_sg_bvh *t, uint32_t lo, uint32_t hi)
{
    const uint32_t id = t->n_nodes++;
    sw_sg_bvh_node *n = &t->nodes[id];
    double cb[6];
    for (int k = 0; k < 3; ++k) {
        n->box[k] = cb[k] = INFINITY;
        n->box[3 + k] = cb[3 + k] = -INFINITY;
    }
    for (uint32_t i = lo; i < hi; ++i) {
        box_union(n->box, t->items[i].box);
        for (int k = 0; k < 3; ++k) {
            cb[k] = fmin(cb[k], centre(&t->items[i], k));
            cb[3 + k] = fmax(cb[3 + k], centre(&t->items[i], k));
        }
    }
    n->child[0] = n->child[1] = -1;
    n->first = lo;
    n->count = hi - lo;
    if (hi - lo <= SW_SG_BVH_LEAF)
        return id;
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (cb[3 + k] - cb[k] > cb[3 + axis] - cb[axis])
            axis = k;
    const uint32_t mid = lo + (hi - lo) / 2;
    if (cb[3 + axis] > cb[axis]) /* all centres equal: any split is as good */
        select_median(t->items, lo, hi, mid, axis);
    const int32_t a = (int32_t)build_node(t, lo, mid);
    const int32_t b = (int32_t)build_node(t, mid, hi);
    n->child[0] = a;
    n->child[1] = b;
    return id;
}

/* Takes `items` (n of them, malloc'ed; freed on failure) and builds the hierarchy over them. */
static sw_result finish(sw_sg_bvh_item *items, size_t n, sw_sg_bvh **out, sw_status *status)
{
    sw_sg_bvh *t = sw__calloc(1, sizeof *t);
    if (t) {
        t->items = items;
        t->n_items = (uint32_t)n;
        t->nodes = sw__malloc((n ? 2 * n : 1) * sizeof *t->nodes);
    }
    if (!t || !t->nodes) {
        if (!t)
            sw__free(items);
        sw_sg_bvh_free(t);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: out of memory");
    }
    if (n)
        build_node(t, 0, t->n_items);
    *out = t;
    return SW_OK;
}

sw_result sw_sg_bvh_build(const sw_sg_scene *scene, sw_sg_bvh **out, sw_status *status)
{
    *out = NULL;
    const uint32_t n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    build b = {scene, sw__malloc((n_faces ? n_faces : 1) * 6 * sizeof(double)), NULL, 0, 0, 0};
    if (!b.face_box)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: out of memory");
    for (size_t i = 0; i < 6 * (size_t)n_faces; ++i)
        b.face_box[i] = NAN;
    sw_result r = sw_sg_scene_traverse(scene, visit, &b);
    sw__free(b.face_box);
    if (r != SW_OK || b.oom) {
        sw__free(b.items);
        return sw__fail(status, b.cap_items >= INT32_MAX / 2 ? SW_ERR_LIMIT : SW_ERR_OUT_OF_MEMORY,
                        "BVH: %zu occurrences: out of memory", b.n_items);
    }
    return finish(b.items, b.n_items, out, status);
}

sw_result sw_sg_bvh_build_items(sw_sg_bvh_item *items, uint32_t n, sw_sg_bvh **out,
                                sw_status *status)
{
    *out = NULL;
    if (n > INT32_MAX) {
        sw__free(items);
        return sw__fail(status, SW_ERR_LIMIT, "BVH: %u items (at most 2^31 - 1)", n);
    }
    return finish(items, n, out, status);
}

sw_result sw_sg_bvh_build_boxes(const double *boxes, uint32_t n, sw_sg_bvh **out, sw_status *status)
{
    *out = NULL;
    if (n > INT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "BVH: %u boxes (at most 2^31 - 1)", n);
    sw_sg_bvh_item *items = sw__malloc((n ? n : 1) * sizeof *items);
    if (!items)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: %u boxes: out of memory", n);
    static const double k_identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    for (uint32_t i = 0; i < n; ++i) {
        memcpy(items[i].world, k_identity, sizeof k_identity);
        memcpy(items[i].box, boxes + 6 * (size_t)i, sizeof items[i].box);
        for (int k = 0; k < 4; ++k)
            items[i].color[k] = -1.0f;
        items[i].face = i;
    }
    return sw_sg_bvh_build_items(items, n, out, status);
}

void sw_sg_bvh_free(sw_sg_bvh *bvh)
{
    if (!bvh)
        return;
    sw__free(bvh->items);
    sw__free(bvh->nodes);
    sw__free(bvh);
}

size_t sw_sg_bvh_memory(const sw_sg_bvh *bvh)
{
    return bvh ? sizeof *bvh + bvh->n_items * sizeof *bvh->items +
                     2 * (size_t)bvh->n_items * sizeof *bvh->nodes
               : 0;
}

/* ---- culling ------------------------------------------------------------------------------- */
/* Kumar §4.4 (a hierarchy of bounding volumes whose visible leaves are all output, also when the
 * decision is made at an internal node) and §5's visibility thread (nodes totally, partially or not
 * visible; a totally visible node is queued whole, a partially visible one traversed). The paper
 * names neither the volume nor the test: axis-aligned boxes here, each plane tested at the box's
 * corners farthest along and against its normal — exact per plane, conservative for the frustum
 * (a box near its edges can be outside it without being outside any one plane). */

sw_sg_cull_class sw_sg_planes_classify(const double (*planes)[4], int32_t n_planes,
                                       const double box[6])
{
    sw_sg_cull_class c = SW_SG_CULL_INSIDE;
    for (int32_t p = 0; p < n_planes; ++p) {
        const double *pl = planes[p];
        double far = pl[3], near = pl[3]; /* the corners farthest along and against the normal */
        for (int k = 0; k < 3; ++k) {
            far += pl[k] * (pl[k] >= 0.0 ? box[3 + k] : box[k]);
            near += pl[k] * (pl[k] >= 0.0 ? box[k] : box[3 + k]);
        }
        if (far < 0.0)
            return SW_SG_CULL_OUTSIDE;
        if (near < 0.0)
            c = SW_SG_CULL_PARTLY;
    }
    return c;
}

sw_sg_cull_class sw_sg_frustum_classify(const sw_sg_frustum *fr, const double world_box[6])
{
    double b[6];
    for (int k = 0; k < 3; ++k) {
        b[k] = world_box[k] - fr->origin[k];
        b[3 + k] = world_box[3 + k] - fr->origin[k];
    }
    return sw_sg_planes_classify((const double(*)[4])fr->planes, fr->n_planes, b);
}

typedef struct cull {
    const sw_sg_bvh *bvh;
    const sw_sg_frustum *fr;
    sw_sg_bvh_cull_fn fn;
    void *ctx;
    sw_sg_bvh_cull_stats st;
} cull;

/* Reports items [first, first + count) untested, as inside (stop = the callback's value). */
static int report_all(cull *c, uint32_t first, uint32_t count)
{
    for (uint32_t i = first; i < first + count; ++i) {
        c->st.items_visible++;
        c->st.items_inside++;
        int stop = c->fn(c->ctx, i, SW_SG_CULL_INSIDE);
        if (stop)
            return stop;
    }
    return 0;
}

/* Reports the items of [first, first + count) that are not outside, each tested. */
static int report_tested(cull *c, uint32_t first, uint32_t count)
{
    for (uint32_t i = first; i < first + count; ++i) {
        c->st.items_tested++;
        const sw_sg_cull_class k = sw_sg_frustum_classify(c->fr, c->bvh->items[i].box);
        if (k == SW_SG_CULL_OUTSIDE)
            continue;
        c->st.items_visible++;
        c->st.items_inside += k == SW_SG_CULL_INSIDE;
        int stop = c->fn(c->ctx, i, k);
        if (stop)
            return stop;
    }
    return 0;
}

/* Depth-first, first child first, so that items come in increasing order. A median-split tree
 * over < 2^31 items is at most 31 levels deep; a deeper one (not built here) would have its
 * overflowing subtrees' items tested one by one, which is slower but reports the same set. */
enum { CULL_STACK = 64 };

int sw_sg_bvh_cull(const sw_sg_bvh *bvh, const sw_sg_frustum *fr, sw_sg_bvh_cull_fn fn, void *ctx,
                   sw_sg_bvh_cull_stats *stats)
{
    cull c = {bvh, fr, fn, ctx, {0}};
    uint32_t stack[CULL_STACK], n = bvh->n_nodes ? 1 : 0;
    stack[0] = 0;
    int stop = 0;
    while (n > 0 && !stop) {
        const sw_sg_bvh_node *node = &bvh->nodes[stack[--n]];
        c.st.nodes_visited++;
        const sw_sg_cull_class k = sw_sg_frustum_classify(fr, node->box);
        if (k == SW_SG_CULL_OUTSIDE) {
            c.st.nodes_outside++;
        } else if (k == SW_SG_CULL_INSIDE) {
            c.st.nodes_inside++;
            stop = report_all(&c, node->first, node->count);
        } else {
            c.st.nodes_partly++;
            if (node->child[0] >= 0 && n + 2 <= CULL_STACK) {
                stack[n++] = (uint32_t)node->child[1];
                stack[n++] = (uint32_t)node->child[0];
            } else {
                stop = report_tested(&c, node->first, node->count);
            }
        }
    }
    if (stats)
        *stats = c.st;
    return stop;
}

/* SPDX-License-Identifier: MIT */
/* The BVH over face occurrences or caller-made items (sw_sg_bvh.h). */
#include "sw_sg_bvh.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Items and places being collected (sw_sg_bvh_build's traversal, sw_sg_bvh_build_items). */
typedef struct build {
    const sw_sg_scene *scene;
    double *face_box; /* 6 per face, local; NaN[0] until computed */
    sw_sg_bvh_item *items;
    size_t n_items, cap_items;
    sw_sg_bvh_place *places;
    size_t n_places, cap_places;
    double box[6]; /* the union of the items' boxes, in double (empty to begin with) */
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

double sw_sg_stretch_bound(const double m[12])
{
    double col = 0.0, row = 0.0;
    for (int i = 0; i < 3; ++i) {
        double c = 0.0, r = 0.0;
        for (int j = 0; j < 3; ++j) {
            c += fabs(m[4 * j + i]);
            r += fabs(m[4 * i + j]);
        }
        col = fmax(col, c);
        row = fmax(row, r);
    }
    return sqrt(col * row);
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

static void box_union(double out[6], const double b[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = fmin(out[k], b[k]);
        out[3 + k] = fmax(out[3 + k], b[3 + k]);
    }
}

static void box_empty(double b[6])
{
    for (int k = 0; k < 3; ++k) {
        b[k] = INFINITY;
        b[3 + k] = -INFINITY;
    }
}

/* The float offset from origin o rounded down (up: dir = +1) so that o + (double)f <= x (>= x)
 * as sw_sg_bvh_box_at computes it: a stored box bounds the double one whatever the two roundings
 * (to float, and of the addition back) do. At most a few steps: each rounding is within an ulp. */
static float offset_outward(double x, double o, int dir)
{
    float f = (float)(x - o);
    if (dir < 0)
        while (o + (double)f > x)
            f = nextafterf(f, -INFINITY);
    else
        while (o + (double)f < x)
            f = nextafterf(f, INFINITY);
    return f;
}

static void box_store(const double o[3], const double box[6], float out[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = offset_outward(box[k], o[k], -1);
        out[3 + k] = offset_outward(box[3 + k], o[k], 1);
    }
}

/* The place of an item with this transform and colour: the last one when they match it (the
 * occurrences of one node come together), else a new one at the centre of `box`. */
static int place_of(build *b, const double world[12], const float color[4], const double box[6],
                    uint32_t *out)
{
    static const float k_none[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
    const float *c = color ? color : k_none;
    if (b->n_places) {
        const sw_sg_bvh_place *last = &b->places[b->n_places - 1];
        if (!memcmp(last->world, world, sizeof last->world) &&
            !memcmp(last->color, c, sizeof last->color)) {
            *out = (uint32_t)(b->n_places - 1);
            return 1;
        }
    }
    if (b->n_places >= INT32_MAX ||
        !sw__grow((void **)&b->places, &b->cap_places, b->n_places + 1, sizeof *b->places))
        return 0;
    sw_sg_bvh_place *p = &b->places[b->n_places];
    memcpy(p->world, world, sizeof p->world);
    memcpy(p->color, c, sizeof p->color);
    for (int k = 0; k < 3; ++k) {
        const double mid = 0.5 * box[k] + 0.5 * box[3 + k];
        p->origin[k] = isfinite(mid) ? mid : 0.0;
    }
    *out = (uint32_t)b->n_places++;
    return 1;
}

/* Appends one item: its place, its box stored relative to the place's origin. */
static int add_item(build *b, uint32_t face, const double world[12], const float color[4],
                    const double box[6])
{
    uint32_t place;
    if (b->n_items >= INT32_MAX || !place_of(b, world, color, box, &place) ||
        !sw__grow((void **)&b->items, &b->cap_items, b->n_items + 1, sizeof *b->items)) {
        b->oom = 1;
        return 0;
    }
    sw_sg_bvh_item *it = &b->items[b->n_items++];
    box_store(b->places[place].origin, box, it->box);
    box_union(b->box, box);
    it->face = face;
    it->place = place;
    return 1;
}

/* Per face, its control-net box once computed (NaN until then): NULL when out of memory. */
static double *face_boxes_new(const sw_sg_scene *scene)
{
    const uint32_t n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    double *fb = sw__malloc((n_faces ? n_faces : 1) * 6 * sizeof(double));
    for (size_t i = 0; fb && i < 6 * (size_t)n_faces; ++i)
        fb[i] = NAN;
    return fb;
}

/* An occurrence's world box: its face's box (computed on first use) through world. */
static void occurrence_box(const sw_sg_scene *scene, double *face_boxes, uint32_t face,
                           const double world[12], double out[6])
{
    double *lb = face_boxes + 6 * (size_t)face;
    if (isnan(lb[0]))
        sw_sg_bvh_face_box(scene, face, lb);
    sw_sg_box_transform(world, lb, out);
}

static int visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    build *b = ctx;
    double box[6];
    occurrence_box(b->scene, b->face_box, face, world, box);
    return !add_item(b, face, world, color, box);
}

static double centre(const sw_sg_bvh *t, const sw_sg_bvh_item *it, int axis)
{
    const double o = t->places[it->place].origin[axis];
    return o + 0.5 * ((double)it->box[axis] + (double)it->box[3 + axis]);
}

static void swap_items(sw_sg_bvh_item *a, sw_sg_bvh_item *b)
{
    sw_sg_bvh_item t = *a;
    *a = *b;
    *b = t;
}

/* Quickselect (Lomuto partition, middle pivot): afterwards the item at mid has its sorted place
 * along axis among [lo, hi), smaller centres before it and larger after. */
static void select_median(sw_sg_bvh *t, uint32_t lo, uint32_t hi, uint32_t mid, int axis)
{
    sw_sg_bvh_item *items = t->items;
    int64_t l = lo, h = (int64_t)hi - 1;
    while (l < h) {
        swap_items(&items[l + (h - l) / 2], &items[h]);
        const double pivot = centre(t, &items[h], axis);
        int64_t store = l;
        for (int64_t i = l; i < h; ++i)
            if (centre(t, &items[i], axis) < pivot)
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
 * most, so pointers into them stay valid). The first child is built right after its parent.
 * Recursion depth is O(log n): median splits. */
static uint32_t build_node(sw_sg_bvh *t, uint32_t lo, uint32_t hi)
{
    const uint32_t id = t->n_nodes++;
    sw_sg_bvh_node *n = &t->nodes[id];
    double box[6], cb[6];
    box_empty(box);
    box_empty(cb);
    for (uint32_t i = lo; i < hi; ++i) {
        double ib[6];
        sw_sg_bvh_item_box(t, i, ib);
        box_union(box, ib);
        for (int k = 0; k < 3; ++k) {
            const double c = centre(t, &t->items[i], k);
            cb[k] = fmin(cb[k], c);
            cb[3 + k] = fmax(cb[3 + k], c);
        }
    }
    box_store(t->origin, box, n->box);
    n->second = -1;
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
        select_median(t, lo, hi, mid, axis);
    build_node(t, lo, mid);
    const int32_t second = (int32_t)build_node(t, mid, hi);
    t->nodes[id].second = second;
    return id;
}

static void shrink_to_fit(void **p, size_t n, size_t elem)
{
    void *fit = sw__realloc(*p, (n ? n : 1) * elem);
    if (fit)
        *p = fit;
}

/* Takes b's items and places and builds the hierarchy over them (b's arrays freed on failure). */
static sw_result finish(build *b, sw_sg_bvh **out, sw_status *status)
{
    const size_t n = b->n_items;
    sw_sg_bvh *t = sw__calloc(1, sizeof *t);
    if (t) {
        t->items = b->items;
        t->n_items = (uint32_t)n;
        t->places = b->places;
        t->n_places = (uint32_t)b->n_places;
        t->nodes = sw__malloc((n ? 2 * n : 1) * sizeof *t->nodes);
    }
    if (!t || !t->nodes) {
        if (!t) {
            sw__free(b->items);
            sw__free(b->places);
        }
        sw_sg_bvh_free(t);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: out of memory");
    }
    memcpy(t->box, b->box, sizeof t->box);
    if (n) {
        for (int k = 0; k < 3; ++k) {
            const double mid = 0.5 * t->box[k] + 0.5 * t->box[3 + k];
            t->origin[k] = isfinite(mid) ? mid : 0.0;
        }
        build_node(t, 0, t->n_items);
        /* the 2n nodes reserved are about n / 2 used (leaves of up to SW_SG_BVH_LEAF items), and
         * the growing arrays up to twice their use: kept at their size */
        shrink_to_fit((void **)&t->nodes, t->n_nodes, sizeof *t->nodes);
        shrink_to_fit((void **)&t->items, t->n_items, sizeof *t->items);
        shrink_to_fit((void **)&t->places, t->n_places, sizeof *t->places);
    }
    *out = t;
    return SW_OK;
}

sw_result sw_sg_bvh_build(const sw_sg_scene *scene, sw_sg_bvh **out, sw_status *status)
{
    *out = NULL;
    build b = {.scene = scene, .face_box = face_boxes_new(scene)};
    box_empty(b.box);
    if (!b.face_box)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: out of memory");
    sw_result r = sw_sg_scene_traverse(scene, visit, &b);
    sw__free(b.face_box);
    if (r != SW_OK || b.oom) {
        sw__free(b.items);
        sw__free(b.places);
        return sw__fail(status, b.n_items >= INT32_MAX ? SW_ERR_LIMIT : SW_ERR_OUT_OF_MEMORY,
                        "BVH: %zu occurrences: %s", b.n_items,
                        b.n_items >= INT32_MAX ? "more than 2^31 - 1" : "out of memory");
    }
    return finish(&b, out, status);
}

typedef struct box_walk {
    const sw_sg_scene *scene;
    double *face_box; /* as build's */
    uint64_t n;
    double box[6];
} box_walk;

static int visit_box(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)color;
    box_walk *w = ctx;
    double box[6];
    occurrence_box(w->scene, w->face_box, face, world, box);
    box_union(w->box, box);
    w->n++;
    return 0;
}

sw_result sw_sg_occurrences_box(const sw_sg_scene *scene, uint64_t *n, double box[6],
                                sw_status *status)
{
    box_walk w = {scene, face_boxes_new(scene), 0, {0}};
    if (!w.face_box)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "occurrence box: out of memory");
    box_empty(w.box);
    sw_result r = sw_sg_scene_traverse(scene, visit_box, &w);
    sw__free(w.face_box);
    if (r != SW_OK)
        return sw__fail(status, r, "occurrence box: out of memory");
    *n = w.n;
    memcpy(box, w.box, sizeof w.box);
    return SW_OK;
}

sw_result sw_sg_bvh_build_items(const sw_sg_bvh_input *items, uint32_t n, sw_sg_bvh **out,
                                sw_status *status)
{
    *out = NULL;
    if (n > INT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "BVH: %u items (at most 2^31 - 1)", n);
    build b = {0};
    box_empty(b.box);
    for (uint32_t i = 0; i < n && !b.oom; ++i)
        add_item(&b, items[i].face, items[i].world, items[i].color, items[i].box);
    if (b.oom) {
        sw__free(b.items);
        sw__free(b.places);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: %u items: out of memory", n);
    }
    return finish(&b, out, status);
}

sw_result sw_sg_bvh_build_boxes(const double *boxes, uint32_t n, sw_sg_bvh **out, sw_status *status)
{
    *out = NULL;
    if (n > INT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "BVH: %u boxes (at most 2^31 - 1)", n);
    static const double k_identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    build b = {0};
    box_empty(b.box);
    for (uint32_t i = 0; i < n && !b.oom; ++i)
        add_item(&b, i, k_identity, NULL, boxes + 6 * (size_t)i);
    if (b.oom) {
        sw__free(b.items);
        sw__free(b.places);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "BVH: %u boxes: out of memory", n);
    }
    return finish(&b, out, status);
}

void sw_sg_bvh_free(sw_sg_bvh *bvh)
{
    if (!bvh)
        return;
    sw__free(bvh->items);
    sw__free(bvh->nodes);
    sw__free(bvh->places);
    sw__free(bvh);
}

size_t sw_sg_bvh_memory(const sw_sg_bvh *bvh)
{
    return bvh ? sizeof *bvh + (size_t)bvh->n_items * sizeof *bvh->items +
                     (size_t)bvh->n_nodes * sizeof *bvh->nodes +
                     (size_t)bvh->n_places * sizeof *bvh->places
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
        double box[6];
        sw_sg_bvh_item_box(c->bvh, i, box);
        const sw_sg_cull_class k = sw_sg_frustum_classify(c->fr, box);
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
        const uint32_t id = stack[--n];
        const sw_sg_bvh_node *node = &bvh->nodes[id];
        c.st.nodes_visited++;
        double box[6];
        sw_sg_bvh_node_box(bvh, id, box);
        const sw_sg_cull_class k = sw_sg_frustum_classify(fr, box);
        if (k == SW_SG_CULL_OUTSIDE) {
            c.st.nodes_outside++;
        } else if (k == SW_SG_CULL_INSIDE) {
            c.st.nodes_inside++;
            stop = report_all(&c, node->first, node->count);
        } else {
            c.st.nodes_partly++;
            if (node->second >= 0 && n + 2 <= CULL_STACK) {
                stack[n++] = (uint32_t)node->second;
                stack[n++] = id + 1;
            } else {
                stop = report_tested(&c, node->first, node->count);
            }
        }
    }
    if (stats)
        *stats = c.st;
    return stop;
}

/* SPDX-License-Identifier: MIT */
/* tests/bvh: view-frustum culling by the BVH (scenegraph/sw_sg_bvh.h, sw_sg_bvh_cull; Kumar et al.
 * 1997 §4.4) against brute force, no GL. Hierarchies:
 *  - terrain.brep's face BVH: the file is one B-spline face (100,776 poles), so its BVH over faces
 *    is one leaf holding one item; checked, and printed as such;
 *  - the same face at a finer granularity: a BVH over its Bézier patches' control-net boxes
 *    (sw_sg_bvh_build_boxes);
 *  - grids of >= 10,000 terrain instances made by sw_sg_generate_grid (the library behind
 *    `splinewalk generate grid`), 3D and 2D: a BVH over instance occurrences;
 *  - with static LODs (lod/static/sw_lod_static_set.h), the static set's BVH whose leaves are
 *    super-surface (unit) instances, on terrain.brep, on a grid of 10,000 terrain instances and on
 *    a grid of 400 CrankArms (25 units each: 10,000 unit instances). First the instances
 *    themselves: every face occurrence of the scene's traversal in exactly one instance, of its
 *    face's unit and transform, no (unit, transform) twice, each leaf's box the unit's box
 *    through the transform (checked against a traversal of our own).
 *  - storage: items stored as float offsets read back as bounds of their double boxes, tight to
 *    float rounding, far from the origin too (stored_boxes).
 * For random cameras of six classes (inside the model, outside looking at it, outside looking
 * away, looking along the grid's rows from its side, seeing a corner of it, a narrow field of
 * view) with and without a far plane:
 *  - the visible set is exactly the set of items whose own box a brute-force test finds not
 *    outside the frustum (every item, every plane, all eight corners: independent of the
 *    nearest/farthest-corner code under test), and the class reported with each item (wholly or
 *    partly inside) is the brute-force class of its own box;
 *  - the traversal's counts are exactly what a brute-force classification of every node implies:
 *    a node is visited iff all its ancestors are partly visible internal nodes, so
 *    visited = 1 + 2 x (partly visible internal nodes visited), and the items tested one by one
 *    are those of the partly visible leaves visited (a traversal that opened inside subtrees, or
 *    stopped at partly visible ones, breaks these);
 *  - visited <= 2 x frontier - 1 + 2 x wasted exactly, and visited <= 16 (visible + log2 n): see
 *    bound_holds() for why the second is a guard and not a theorem.
 * Usage: test_bvh_cull TERRAIN.brep CRANKARM.brep
 */
#include <splinewalk/sw_lod_build.h>
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"
#include "sw_sg_generate.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

enum { CAMERAS_PER_CLASS = 40, N_CLASSES = 6 };
static const char *const k_class_name[N_CLASSES] = {"inside",        "outside, at it",
                                                    "outside, away", "along the rows",
                                                    "a corner",      "narrow (0.5-3 deg)"};

/* ---- random numbers and vectors -------------------------------------------------------------- */
static uint64_t g_rng = 0x9e3779b97f4a7c15ull;

static double uniform(double lo, double hi)
{
    g_rng ^= g_rng >> 12;
    g_rng ^= g_rng << 25;
    g_rng ^= g_rng >> 27;
    const uint64_t x = g_rng * 0x2545f4914f6cdd1dull;
    return lo + (hi - lo) * (double)(x >> 11) * 0x1.0p-53;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize3(double v[3])
{
    const double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; ++k)
        v[k] /= n;
}

static void random_unit(double v[3])
{
    do {
        for (int k = 0; k < 3; ++k)
            v[k] = uniform(-1.0, 1.0);
    } while (dot3(v, v) > 1.0 || dot3(v, v) < 1e-4);
    normalize3(v);
}

/* ---- cameras --------------------------------------------------------------------------------- */
typedef struct camera {
    double eye[3], fwd[3], up[3];
    double fovy_deg, aspect, near_plane, far_plane; /* far 0: none (five planes) */
} camera;

/* The perspective frustum in eye-relative coordinates, planes as gpu/camera.c builds them (side
 * planes through the eye, the near plane) plus an optional far plane. */
static void make_frustum(const camera *c, sw_sg_frustum *fr)
{
    double right[3], up[3], fwd[3];
    memcpy(fwd, c->fwd, sizeof fwd);
    normalize3(fwd);
    cross3(fwd, c->up, right);
    normalize3(right);
    cross3(right, fwd, up);
    const double tan_y = tan(c->fovy_deg * M_PI / 360.0), tan_x = tan_y * c->aspect;
    const double fx = 1.0 / tan_x, fy = 1.0 / tan_y;
    memset(fr, 0, sizeof *fr);
    memcpy(fr->origin, c->eye, sizeof fr->origin);
    for (int k = 0; k < 3; ++k) {
        fr->planes[0][k] = fwd[k] + fx * right[k];
        fr->planes[1][k] = fwd[k] - fx * right[k];
        fr->planes[2][k] = fwd[k] + fy * up[k];
        fr->planes[3][k] = fwd[k] - fy * up[k];
        fr->planes[4][k] = fwd[k];
        fr->planes[5][k] = -fwd[k];
    }
    fr->planes[4][3] = -c->near_plane;
    fr->planes[5][3] = c->far_plane;
    fr->n_planes = c->far_plane > 0.0 ? 6 : 5;
}

static void random_up(camera *c)
{
    double f[3];
    memcpy(f, c->fwd, sizeof f);
    normalize3(f);
    do
        random_unit(c->up);
    while (fabs(dot3(c->up, f)) > 0.95);
}

static void point_in(const double b[6], double p[3])
{
    for (int k = 0; k < 3; ++k)
        p[k] = uniform(b[k], b[3 + k]);
}

static void look_at(camera *c, const double target[3])
{
    for (int k = 0; k < 3; ++k)
        c->fwd[k] = target[k] - c->eye[k];
}

/* A camera of class `cls` for a model with box b. */
static camera make_camera(int cls, const double b[6])
{
    double centre[3], ext[3], dir[3], target[3];
    for (int k = 0; k < 3; ++k) {
        centre[k] = 0.5 * (b[k] + b[3 + k]);
        ext[k] = b[3 + k] - b[k];
    }
    const double diag = sqrt(dot3(ext, ext));
    camera c;
    memset(&c, 0, sizeof c);
    c.fovy_deg = uniform(15.0, 100.0);
    c.aspect = uniform(0.5, 2.4);
    random_unit(dir);
    const double away = uniform(0.75, 2.5) * diag;
    for (int k = 0; k < 3; ++k)
        c.eye[k] = centre[k] + away * dir[k];
    switch (cls) {
    case 0: /* inside, any direction */
        point_in(b, c.eye);
        random_unit(c.fwd);
        break;
    case 1: /* outside, looking at a point of the model */
        point_in(b, target);
        look_at(&c, target);
        break;
    case 2: /* outside, looking away from it (within 45 degrees of straight away) */
        for (int k = 0; k < 3; ++k)
            c.fwd[k] = dir[k] + uniform(-0.7, 0.7);
        break;
    case 3: { /* just outside one side of the box, looking across it along an axis */
        const int a = (int)uniform(0.0, 3.0) % 3, side = uniform(0.0, 1.0) < 0.5;
        point_in(b, c.eye);
        c.eye[a] = side ? b[3 + a] + 0.02 * ext[a] : b[a] - 0.02 * ext[a];
        for (int k = 0; k < 3; ++k)
            c.fwd[k] = uniform(-0.05, 0.05);
        c.fwd[a] = side ? -1.0 : 1.0;
        break;
    }
    case 4: /* outside, looking at a corner: part of the model in view */
        for (int k = 0; k < 3; ++k)
            target[k] = (uniform(0.0, 1.0) < 0.5 ? b[k] : b[3 + k]) + uniform(-0.1, 0.1) * ext[k];
        look_at(&c, target);
        break;
    default: /* narrow: a few degrees, from inside or outside, at a point of the model */
        if (uniform(0.0, 1.0) < 0.5)
            point_in(b, c.eye);
        point_in(b, target);
        look_at(&c, target);
        c.fovy_deg = uniform(0.5, 3.0);
        break;
    }
    random_up(&c);
    c.near_plane = 1e-3 * diag;
    c.far_plane = uniform(0.0, 1.0) < 0.5 ? 0.0 : uniform(0.1, 1.5) * diag;
    return c;
}

/* ---- brute force ----------------------------------------------------------------------------- */
/* Every corner against every plane, in the same coordinates and accumulation order as the code
 * under test (origin-relative box, d + n.x summed over x, y, z): outside when some plane has all
 * eight corners behind it, inside when every plane has all eight in front. */
static sw_sg_cull_class brute_class(const sw_sg_frustum *fr, const double world[6])
{
    double b[6];
    for (int k = 0; k < 3; ++k) {
        b[k] = world[k] - fr->origin[k];
        b[3 + k] = world[3 + k] - fr->origin[k];
    }
    int all_in = 1;
    for (int p = 0; p < fr->n_planes; ++p) {
        int behind = 0;
        for (int c = 0; c < 8; ++c) {
            double s = fr->planes[p][3];
            for (int k = 0; k < 3; ++k)
                s += fr->planes[p][k] * b[((c >> k) & 1) ? 3 + k : k];
            behind += s < 0.0;
        }
        if (behind == 8)
            return SW_SG_CULL_OUTSIDE;
        all_in = all_in && behind == 0;
    }
    return all_in ? SW_SG_CULL_INSIDE : SW_SG_CULL_PARTLY;
}

/* 1 when a stored box bounds the exact one (computed in double) and is no looser than float's
 * rounding (2 ulps) of offsets from a point within `spread` of `origin` allows, plus the double
 * sum back. */
static int box_stored_well(const double exact[6], const double stored[6], const double origin[3],
                           double spread)
{
    for (int k = 0; k < 6; ++k) {
        const double slack = fabs(stored[k] - exact[k]),
                     allowed = 2.5e-7 * (fabs(exact[k] - origin[k % 3]) + spread) +
                               4.5e-16 * fabs(exact[k]);
        if ((k < 3 ? stored[k] > exact[k] : stored[k] < exact[k]) || slack > allowed)
            return 0;
    }
    return 1;
}

/* Items stored as float offsets (sw_sg_bvh.h): boxes far from the origin and much smaller than
 * their distance to it, in places of one item and places shared by many, must read back as
 * bounds of the double boxes, tight to float rounding of their own size, and the nodes' boxes
 * must bound their items'. Storing offsets rounded to nearest (not outward) fails the first;
 * offsets from the scene's centre instead of each place's origin fail the second. */
static void stored_boxes(void)
{
    enum { N = 3000 };
    sw_sg_bvh_input *in = malloc(N * sizeof *in);
    double(*centre)[3] = malloc(N * sizeof *centre); /* the run's point: every box within 1.01 */
    for (uint32_t i = 0; i < N; ++i) {
        memset(&in[i], 0, sizeof in[i]);
        /* runs of 10 items share a transform and colour: one place */
        const uint32_t run = i / 10;
        const double far = run % 3 == 0   ? 1e6
                           : run % 3 == 1 ? -3e4
                                          : 7.0,
                     size = uniform(1e-4, 1e-2), shift = far * (double)(run % 7 + 1);
        in[i].world[0] = in[i].world[5] = in[i].world[10] = 1.0;
        in[i].world[3] = shift;
        for (int k = 0; k < 3; ++k) {
            const double c = shift + uniform(-1.0, 1.0);
            in[i].box[k] = c - size * uniform(0.1, 1.0);
            in[i].box[3 + k] = c + size * uniform(0.1, 1.0);
        }
        in[i].color[3] = -1.0f;
        in[i].face = i;
        for (int k = 0; k < 3; ++k)
            centre[i][k] = shift;
    }
    sw_sg_bvh *t = NULL;
    sw_status st = {0};
    if (sw_sg_bvh_build_items(in, N, &t, &st) != SW_OK) {
        CHECK(0, "stored boxes: %s", st.message);
        free(in);
        free(centre);
        return;
    }
    uint32_t loose = 0, unbounded = 0;
    for (uint32_t i = 0; i < t->n_items; ++i) {
        double b[6];
        sw_sg_bvh_item_box(t, i, b);
        /* a place's origin is within 2.02 of its run's point */
        loose += !box_stored_well(in[t->items[i].face].box, b, centre[t->items[i].face], 2.02);
    }
    for (uint32_t n = 0; n < t->n_nodes; ++n) {
        double nb[6], ib[6];
        sw_sg_bvh_node_box(t, n, nb);
        for (uint32_t i = t->nodes[n].first; i < t->nodes[n].first + t->nodes[n].count; ++i) {
            sw_sg_bvh_item_box(t, i, ib);
            for (int k = 0; k < 3; ++k)
                unbounded += ib[k] < nb[k] || ib[3 + k] > nb[3 + k];
        }
    }
    CHECK(t->n_places == N / 10 && loose == 0 && unbounded == 0,
          "stored boxes: %u places for %u runs, %u item boxes loose or not bounding, %u node "
          "sides not bounding their items",
          t->n_places, N / 10, loose, unbounded);
    printf("stored boxes: %u items, %u places, %u nodes, %zu bytes (%.1f per item)\n", t->n_items,
           t->n_places, t->n_nodes, sw_sg_bvh_memory(t),
           (double)sw_sg_bvh_memory(t) / (double)t->n_items);
    sw_sg_bvh_free(t);
    free(in);
    free(centre);
}

typedef struct shape {
    uint32_t n_items, n_nodes, depth, n_leaves;
    uint32_t *parent; /* per node; parent index < child index (nodes in preorder) */
} shape;

static shape tree_shape(const sw_sg_bvh *t)
{
    shape s = {t->n_items, t->n_nodes, 0, 0, calloc(t->n_nodes ? t->n_nodes : 1, sizeof(uint32_t))};
    uint32_t *depth = calloc(t->n_nodes ? t->n_nodes : 1, sizeof *depth);
    for (uint32_t i = 0; i < t->n_nodes; ++i) {
        s.depth = depth[i] > s.depth ? depth[i] : s.depth;
        if (sw_sg_bvh_child(t, i, 0) < 0) {
            s.n_leaves++;
            continue;
        }
        for (int c = 0; c < 2; ++c) {
            const int32_t child = sw_sg_bvh_child(t, i, c);
            CHECK((uint32_t)child > i && (uint32_t)child < t->n_nodes, "node %u: child %d", i,
                  child);
            s.parent[child] = i;
            depth[child] = depth[i] + 1;
        }
    }
    free(depth);
    return s;
}

/* ---- one camera ------------------------------------------------------------------------------ */
typedef struct sink {
    unsigned char *seen;
    unsigned char *cls; /* the class reported with each item */
    uint32_t last;
    int64_t n, out_of_order;
} sink;

static int take(void *ctx, uint32_t item, sw_sg_cull_class cls)
{
    sink *s = ctx;
    s->cls[item] = (unsigned char)cls;
    s->out_of_order += s->n > 0 && item <= s->last;
    s->seen[item] = 1;
    s->last = item;
    s->n++;
    return 0;
}

typedef struct result {
    uint64_t visible, inside, visited,
        wasted;        /* wasted: visited nodes with no visible item below */
    uint64_t frontier; /* visited nodes inside, or partly visible leaves with a
                          visible item: where the traversal stops on the set */
} result;

typedef struct work {
    unsigned char *seen, *brute, *cls, *reach;
    uint32_t *prefix; /* visible items before index i, by brute force */
} work;

/* The visible set: traversal against brute force, exact. */
static void check_items(const sw_sg_bvh *t, const sw_sg_frustum *fr, const char *what, work *w,
                        const sink *s, const sw_sg_bvh_cull_stats *st)
{
    uint32_t missing = 0, extra = 0, vis = 0;
    double box[6];
    for (uint32_t i = 0; i < t->n_items; ++i) {
        sw_sg_bvh_item_box(t, i, box);
        w->brute[i] = brute_class(fr, box) != SW_SG_CULL_OUTSIDE;
        w->prefix[i] = vis;
        vis += w->brute[i];
        missing += w->brute[i] && !w->seen[i];
        extra += !w->brute[i] && w->seen[i];
    }
    w->prefix[t->n_items] = vis;
    CHECK(missing == 0 && extra == 0 && s->n == vis && st->items_visible == vis,
          "%s: visible set: %u missing, %u extra (%lld reported, %u by brute force)", what, missing,
          extra, (long long)s->n, vis);
    CHECK(s->out_of_order == 0, "%s: %lld items out of increasing order", what,
          (long long)s->out_of_order);
    uint32_t wrong_class = 0;
    for (uint32_t i = 0; i < t->n_items; ++i) {
        sw_sg_bvh_item_box(t, i, box);
        wrong_class += w->seen[i] && s->cls[i] != (unsigned char)brute_class(fr, box);
    }
    CHECK(wrong_class == 0, "%s: %u items reported with another class than their box's", what,
          wrong_class);
    uint64_t inside = 0;
    for (uint32_t i = 0; i < t->n_items; ++i)
        inside += w->seen[i] && s->cls[i] == SW_SG_CULL_INSIDE;
    CHECK(st->items_inside == inside, "%s: %llu items counted inside, %llu reported so", what,
          (unsigned long long)st->items_inside, (unsigned long long)inside);
}

/* The traversal's counts from a brute-force classification of every node. */
static void check_nodes(const sw_sg_bvh *t, const shape *sh, const sw_sg_frustum *fr,
                        const char *what, work *w, const sw_sg_bvh_cull_stats *st, result *r)
{
    uint64_t by[3] = {0, 0, 0}, tested = 0, partly_internal = 0;
    for (uint32_t i = 0; i < t->n_nodes; ++i) {
        const sw_sg_bvh_node *n = &t->nodes[i];
        const uint32_t p = sh->parent[i];
        double box[6];
        sw_sg_bvh_node_box(t, i, box);
        w->cls[i] = (unsigned char)brute_class(fr, box);
        w->reach[i] = i == 0 || (w->reach[p] && w->cls[p] == SW_SG_CULL_PARTLY);
        if (!w->reach[i])
            continue;
        by[w->cls[i]]++;
        const int leaf = n->second < 0;
        const uint32_t below = w->prefix[n->first + n->count] - w->prefix[n->first];
        r->wasted += below == 0;
        r->frontier += below > 0 &&
                       (w->cls[i] == SW_SG_CULL_INSIDE || (leaf && w->cls[i] == SW_SG_CULL_PARTLY));
        if (w->cls[i] == SW_SG_CULL_PARTLY) {
            tested += leaf ? n->count : 0;
            partly_internal += !leaf;
        }
    }
    const uint64_t visited = by[0] + by[1] + by[2];
    CHECK(st->nodes_visited == visited && st->nodes_outside == by[0] && st->nodes_partly == by[1] &&
              st->nodes_inside == by[2],
          "%s: visited %llu (out %llu, partly %llu, in %llu); brute force %llu (%llu, %llu, "
          "%llu)",
          what, (unsigned long long)st->nodes_visited, (unsigned long long)st->nodes_outside,
          (unsigned long long)st->nodes_partly, (unsigned long long)st->nodes_inside,
          (unsigned long long)visited, (unsigned long long)by[0], (unsigned long long)by[1],
          (unsigned long long)by[2]);
    CHECK(t->n_nodes == 0 || visited == 1 + 2 * partly_internal,
          "%s: visited %llu != 1 + 2 x %llu partly visible internal nodes", what,
          (unsigned long long)visited, (unsigned long long)partly_internal);
    CHECK(st->items_tested == tested, "%s: %llu items tested, the partly visible leaves hold %llu",
          what, (unsigned long long)st->items_tested, (unsigned long long)tested);
    r->visited = st->nodes_visited;
    r->visible = st->items_visible;
    r->inside = st->items_inside;
}

/* The output-sensitive bound. The visited nodes with a visible item below form a tree whose leaves
 * are the frontier F (inside nodes, and partly visible leaves with a visible item: |F| <= V, the
 * visible items); it has at most |F| - 1 nodes with two such children, and each of its other
 * internal nodes has a child with no visible item below, which the traversal visits too (W, the
 * wasted visits). So, exactly, visited <= 2|F| - 1 + 2W (visited = W when nothing is visible),
 * asserted; with the identities of
 * check_nodes (a node is visited iff its parent is a visited partly visible internal node) this
 * says the traversal visits the fewest nodes any top-down traversal of this tree with this box
 * test can. O(visible + log n) then needs W to be O(V + log n), which is no theorem for a BVH: a
 * node whose box spans the gap between two instances meets a frustum that misses both, and a
 * narrow frustum threading a grid passes such gaps along its whole length, so W grows with that
 * length, not with V (and a box beside an edge of the frustum can be outside it without being
 * outside any one plane). What is asserted for it is a guard, not a theorem: visited <= 16 x
 * (V + log2 n) per camera; the measured maximum of the ratio is printed per camera class (the
 * narrow cameras in the 3D grid come closest, about 9). A median-split BVH of this quality keeps
 * it; a degenerate one (unsorted splits) would not. */
enum { GUARD = 16 };

static int bound_holds(const result *r, double log2n)
{
    const int exact = r->frontier > 0 ? r->visited <= 2 * r->frontier - 1 + 2 * r->wasted
                                      : r->visited == r->wasted;
    return exact && (double)r->visited <= GUARD * ((double)r->visible + log2n);
}

/* ---- per hierarchy --------------------------------------------------------------------------- */
typedef struct class_sum {
    int cameras;
    uint64_t visible_min, visible_max, visited_min, visited_max, wasted_max, inside_sum;
    double visible_sum, visited_sum, ratio_max; /* ratio: visited / (visible + log2 n) */
} class_sum;

static void add_sum(class_sum *c, const result *r, double log2n)
{
    if (c->cameras == 0) {
        c->visible_min = c->visited_min = UINT64_MAX;
    }
    c->cameras++;
    c->visible_min = r->visible < c->visible_min ? r->visible : c->visible_min;
    c->visible_max = r->visible > c->visible_max ? r->visible : c->visible_max;
    c->visited_min = r->visited < c->visited_min ? r->visited : c->visited_min;
    c->visited_max = r->visited > c->visited_max ? r->visited : c->visited_max;
    c->wasted_max = r->wasted > c->wasted_max ? r->wasted : c->wasted_max;
    c->visible_sum += (double)r->visible;
    c->inside_sum += r->inside;
    c->visited_sum += (double)r->visited;
    const double ratio = (double)r->visited / ((double)r->visible + log2n);
    c->ratio_max = ratio > c->ratio_max ? ratio : c->ratio_max;
}

static void run_bvh(const sw_sg_bvh *t, const char *name)
{
    shape sh = tree_shape(t);
    const double log2n = log2((double)(t->n_items > 1 ? t->n_items : 2));
    printf("%s: %u items, %u nodes (%u leaves), depth %u, log2(n) = %.1f\n", name, t->n_items,
           t->n_nodes, sh.n_leaves, sh.depth, log2n);
    work w = {calloc(t->n_items + 1, 1), calloc(t->n_items + 1, 1), calloc(t->n_nodes + 1, 1),
              calloc(t->n_nodes + 1, 1), calloc(t->n_items + 1, sizeof(uint32_t))};
    unsigned char *reported = calloc(t->n_items + 1, 1);
    class_sum sums[N_CLASSES];
    memset(sums, 0, sizeof sums);
    for (int cls = 0; cls < N_CLASSES; ++cls) {
        for (int k = 0; k < CAMERAS_PER_CLASS; ++k) {
            const camera cam = make_camera(cls, t->box);
            sw_sg_frustum fr;
            make_frustum(&cam, &fr);
            char what[96];
            snprintf(what, sizeof what, "%s, %s camera %d", name, k_class_name[cls], k);
            memset(w.seen, 0, t->n_items + 1);
            sink s = {w.seen, reported, 0, 0, 0};
            sw_sg_bvh_cull_stats st;
            CHECK(sw_sg_bvh_cull(t, &fr, take, &s, &st) == 0, "%s: traversal stopped", what);
            result r = {0, 0, 0, 0, 0};
            check_items(t, &fr, what, &w, &s, &st);
            check_nodes(t, &sh, &fr, what, &w, &st, &r);
            CHECK(bound_holds(&r, log2n),
                  "%s: visited %llu, frontier %llu, wasted %llu, visible %llu, depth %u", what,
                  (unsigned long long)r.visited, (unsigned long long)r.frontier,
                  (unsigned long long)r.wasted, (unsigned long long)r.visible, sh.depth);
            add_sum(&sums[cls], &r, log2n);
        }
        const class_sum *c = &sums[cls];
        printf("  %-19s %2d cameras: visible %llu..%llu (mean %.0f: %.0f wholly, %.0f partly, %.0f "
               "not), visited %llu..%llu (mean %.0f), wasted <= %llu, visited / (visible + log2 n) "
               "<= %.2f (c = %d)\n",
               k_class_name[cls], c->cameras, (unsigned long long)c->visible_min,
               (unsigned long long)c->visible_max, c->visible_sum / c->cameras,
               (double)c->inside_sum / c->cameras,
               (c->visible_sum - (double)c->inside_sum) / c->cameras,
               t->n_items - c->visible_sum / c->cameras, (unsigned long long)c->visited_min,
               (unsigned long long)c->visited_max, c->visited_sum / c->cameras,
               (unsigned long long)c->wasted_max, c->ratio_max, GUARD);
    }
    free(reported);
    free(w.seen);
    free(w.brute);
    free(w.cls);
    free(w.reach);
    free(w.prefix);
    free(sh.parent);
}

/* ---- the hierarchies ------------------------------------------------------------------------- */
static void terrain_faces(const sw_sg_scene *terrain)
{
    sw_sg_bvh *t = NULL;
    sw_status st = {0};
    if (sw_sg_bvh_build(terrain, &t, &st) != SW_OK) {
        CHECK(0, "terrain BVH: %s", st.message);
        return;
    }
    CHECK(t->n_items == 1 && t->n_nodes == 1, "terrain: %u items, %u nodes (one face expected)",
          t->n_items, t->n_nodes);
    printf(
        "terrain.brep over faces: one face, so one leaf with one item (culling is one box test)\n");
    run_bvh(t, "terrain.brep, faces");
    sw_sg_bvh_free(t);
}

/* The face's Bézier patches, each boxed by its control net (Euclidean points). */
static void terrain_patches(const sw_sg_scene *terrain)
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(terrain, 0, &s);
    sw_sg_bezier_set set;
    sw_status st = {0};
    if (sw_sg_surface_extract_bezier(&s, &set, &st) != SW_OK) {
        CHECK(0, "terrain patches: %s", st.message);
        return;
    }
    const uint32_t n = (uint32_t)set.n_u * (uint32_t)set.n_v;
    double *boxes = malloc(6 * (size_t)n * sizeof *boxes);
    for (uint32_t i = 0; i < n; ++i) {
        const sw_sg_bezier_patch *p = &set.patches[i];
        double *b = boxes + 6 * (size_t)i;
        for (int k = 0; k < 3; ++k) {
            b[k] = INFINITY;
            b[3 + k] = -INFINITY;
        }
        for (int j = 0; j < (p->deg_u + 1) * (p->deg_v + 1); ++j)
            for (int k = 0; k < 3; ++k) {
                const double x = p->cpw[4 * j + k] / p->cpw[4 * j + 3];
                b[k] = fmin(b[k], x);
                b[3 + k] = fmax(b[3 + k], x);
            }
    }
    sw_sg_bezier_set_free(&set);
    sw_sg_bvh *t = NULL;
    if (sw_sg_bvh_build_boxes(boxes, n, &t, &st) != SW_OK) {
        CHECK(0, "terrain patch BVH: %s", st.message);
    } else {
        run_bvh(t, "terrain.brep, Bézier patches");
        sw_sg_bvh_free(t);
    }
    free(boxes);
}

static void grid(const sw_sg_scene *terrain, uint32_t count, int32_t dims)
{
    sw_sg_grid_desc d = {count, dims, 0.0, NULL, NULL};
    sw_sg_grid_report rep;
    sw_sg_scene *g = NULL;
    sw_status st = {0};
    if (sw_sg_generate_grid(terrain, &d, &g, &rep, &st) != SW_OK) {
        CHECK(0, "grid of %u: %s", count, st.message);
        return;
    }
    CHECK((uint64_t)rep.nx * rep.ny * rep.nz >= count &&
              (uint64_t)rep.nx * rep.ny * (rep.nz - 1) < count && rep.occurrences == count,
          "grid of %u: %ux%ux%u, %llu occurrences", count, rep.nx, rep.ny, rep.nz,
          (unsigned long long)rep.occurrences);
    sw_sg_bvh *t = NULL;
    if (sw_sg_bvh_build(g, &t, &st) != SW_OK) {
        CHECK(0, "grid BVH: %s", st.message);
    } else {
        CHECK(t->n_items == count, "grid of %u: %u BVH items", count, t->n_items);
        char name[96];
        snprintf(name, sizeof name, "grid of %u terrain instances (%ux%ux%u)", count, rep.nx,
                 rep.ny, rep.nz);
        run_bvh(t, name);
        sw_sg_bvh_free(t);
    }
    sw_sg_scene_free(g);
}

/* ---- super-surface (unit) instances ---------------------------------------------------------- */
typedef struct occ_list {
    uint32_t *face;
    double (*world)[12];
    size_t n, cap;
} occ_list;

static int list_occurrence(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)color;
    occ_list *l = ctx;
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 1024;
        l->face = realloc(l->face, l->cap * sizeof *l->face);
        l->world = realloc(l->world, l->cap * sizeof *l->world);
    }
    l->face[l->n] = face;
    memcpy(l->world[l->n++], world, sizeof *l->world);
    return 0;
}

/* The instances partition the traversal's occurrences by (unit, transform), and each leaf box is
 * the unit's (or the lone face's) box through the transform. */
static void check_instances(const sw_sg_scene *scene, const sw_lod_static_set *set,
                            const char *name)
{
    const sw_lod_static_instances *in = sw_lod_static_set_instances(set);
    occ_list l = {NULL, NULL, 0, 0};
    sw_sg_scene_traverse(scene, list_occurrence, &l);
    CHECK(in->n_occs == l.n && in->bvh->n_items == in->n_instances,
          "%s: %u occurrences in instances, %zu traversed; %u leaves, %u instances", name,
          in->n_occs, l.n, in->bvh->n_items, in->n_instances);
    /* every traversed occurrence found once in the instance of its unit and transform */
    uint32_t *of_item = malloc((in->n_instances + 1) * sizeof *of_item);
    for (uint32_t k = 0; k < in->bvh->n_items; ++k)
        of_item[in->bvh->items[k].face] = k;
    uint64_t misplaced = 0, bad_box = 0, twice = 0;
    for (uint32_t i = 0; i < in->n_instances; ++i) {
        const sw_lod_static_instance *ins = &in->instances[i];
        sw_sg_bvh_item_view it_view;
        sw_sg_bvh_item_at(in->bvh, of_item[i], &it_view);
        const sw_sg_bvh_item_view *it = &it_view;
        for (uint32_t k = 0; k < ins->n_occ; ++k)
            misplaced +=
                sw_lod_static_set_unit_of(set, in->occs[ins->first_occ + k].face) != ins->unit;
        double box[6];
        const double *local = ins->unit != SW_LOD_STATIC_NO_UNIT
                                  ? sw_lod_static_set_unit(set, ins->unit)->box
                                  : in->face_boxes + 6 * (size_t)in->occs[ins->first_occ].face;
        sw_sg_box_transform(it->world, local, box);
        bad_box +=
            !box_stored_well(box, it->box, in->bvh->places[in->bvh->items[of_item[i]].place].origin,
                             0.0) ||
            ins->n_occ == 0 || (ins->unit == SW_LOD_STATIC_NO_UNIT && ins->n_occ != 1);
    }
    /* occurrences matched to instances by (face, transform): each exactly once */
    unsigned char *used = calloc(in->n_occs + 1, 1);
    for (size_t j = 0; j < l.n; ++j) {
        int found = 0;
        const uint32_t unit = sw_lod_static_set_unit_of(set, l.face[j]);
        for (uint32_t i = 0; i < in->n_instances && !found; ++i) {
            const sw_lod_static_instance *ins = &in->instances[i];
            if (ins->unit != unit || memcmp(sw_sg_bvh_item_world(in->bvh, of_item[i]), l.world[j],
                                            sizeof l.world[j]) != 0)
                continue;
            for (uint32_t k = 0; k < ins->n_occ && !found; ++k)
                if (in->occs[ins->first_occ + k].face == l.face[j] && !used[ins->first_occ + k])
                    found = used[ins->first_occ + k] = 1;
        }
        misplaced += !found;
    }
    for (uint32_t i = 0; i + 1 < in->n_instances && in->n_instances < 20000; ++i)
        for (uint32_t j = i + 1; j < in->n_instances; ++j)
            twice += in->instances[i].unit != SW_LOD_STATIC_NO_UNIT &&
                     in->instances[i].unit == in->instances[j].unit &&
                     memcmp(sw_sg_bvh_item_world(in->bvh, of_item[i]),
                            sw_sg_bvh_item_world(in->bvh, of_item[j]), sizeof(double[12])) == 0;
    CHECK(misplaced == 0 && bad_box == 0 && twice == 0,
          "%s: %llu occurrences misplaced, %llu bad leaf boxes, %llu (unit, transform) pairs twice",
          name, (unsigned long long)misplaced, (unsigned long long)bad_box,
          (unsigned long long)twice);
    const size_t bytes = sw_sg_bvh_memory(in->bvh) + in->n_instances * sizeof *in->instances +
                         in->n_occs * sizeof *in->occs +
                         sw_sg_scene_view_ptr(scene)->n_faces * 6 * sizeof(double);
    printf("%s: %u units, %u face occurrences in %u unit instances (%zu bytes with their BVH)\n",
           name, sw_lod_static_set_unit_count(set), in->n_occs, in->n_instances, bytes);
    free(used);
    free(of_item);
    free(l.face);
    free(l.world);
}

/* The static set of `scene` (clustering, units, instances; no LOD built) and its BVH culled. */
static void unit_instances(const sw_sg_scene *scene, const char *name, uint32_t min_instances)
{
    sw_th_pool_desc pd = {0};
    pd.worker_count = 1;
    sw_th_pool *pool = NULL;
    sw_lod_static_set *set = NULL;
    sw_status st = {0};
    if (sw_th_pool_create(&pd, &pool) != SW_OK ||
        sw_lod_static_set_create(scene, pool, NULL, &set, &st) != SW_OK) {
        CHECK(0, "%s: static set: %s", name, st.message);
        sw_th_pool_destroy(pool);
        return;
    }
    check_instances(scene, set, name);
    const sw_lod_static_instances *in = sw_lod_static_set_instances(set);
    CHECK(in->n_instances >= min_instances, "%s: %u unit instances, %u wanted", name,
          in->n_instances, min_instances);
    char what[128];
    snprintf(what, sizeof what, "%s, super-surface instances", name);
    run_bvh(in->bvh, what);
    sw_lod_static_set_destroy(set);
    sw_th_pool_destroy(pool);
}

static sw_sg_scene *grid_of(const sw_sg_scene *model, uint32_t count, int32_t dims)
{
    sw_sg_grid_desc d = {count, dims, 0.0, NULL, NULL};
    sw_sg_scene *g = NULL;
    sw_status st = {0};
    if (sw_sg_generate_grid(model, &d, &g, NULL, &st) != SW_OK)
        CHECK(0, "grid of %u: %s", count, st.message);
    return g;
}

int main(int argc, char **argv)
{
    (void)sw_lod_build_install(); /* static LODs are built by the LOD-building module */
    if (argc != 3) {
        fprintf(stderr, "usage: %s TERRAIN.brep CRANKARM.brep\n", argv[0]);
        return 2;
    }
    sw_sg_import_desc id = {argv[1], NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *terrain = NULL;
    sw_status st = {0};
    if (sw_sg_import_file(&id, &terrain, NULL, &st) != SW_OK) {
        printf("FAIL: import %s: %s\n", argv[1], st.message);
        return 1;
    }
    terrain_faces(terrain);
    terrain_patches(terrain);
    grid(terrain, 10000, 3);
    grid(terrain, 16384, 2);
    unit_instances(terrain, "terrain.brep", 1);
    sw_sg_scene *g = grid_of(terrain, 10000, 3);
    if (g)
        unit_instances(g, "grid of 10000 terrain instances", 10000);
    sw_sg_scene_free(g);
    sw_sg_import_desc cd = {argv[2], NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *crank = NULL;
    if (sw_sg_import_file(&cd, &crank, NULL, &st) != SW_OK) {
        CHECK(0, "import %s: %s", argv[2], st.message);
    } else {
        unit_instances(crank, "CrankArm.brep", 1);
        g = grid_of(crank, 400, 3);
        if (g)
            unit_instances(g, "grid of 400 CrankArms", 10000);
        sw_sg_scene_free(g);
    }
    sw_sg_scene_free(crank);
    sw_sg_scene_free(terrain);
    stored_boxes(); /* last: the cameras above keep their random sequence */
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}

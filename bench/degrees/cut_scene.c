/* bench/degrees: the scenes drawn for one frame — see cut_scene.h. */
#include "cut_scene.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const float k_color[4] = {0.8f, 0.8f, 0.8f, 1.0f};
static const double k_cubic_knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};

/* ---- the source scene ------------------------------------------------------------------------ */
static uint32_t add_cubic_loop(sw_sg_builder *b, const sw_lod_cubic_set *set)
{
    const uint64_t knots = sw_sg_builder_push_doubles(b, k_cubic_knots, 8);
    uint32_t first = SW_SG_NONE;
    for (int32_t i = 0; i < set->count; ++i) {
        sw_sg_curve_rec c = {3, 4, knots, sw_sg_builder_push_doubles(b, set->pieces[i].cpw, 12)};
        const uint32_t id = sw_sg_builder_add_curve(b, &c);
        first = i == 0 ? id : first;
    }
    sw_sg_loop_rec l = {first, (uint32_t)set->count, SW_SG_LOOP_OUTER, 0};
    return sw_sg_builder_add_loop(b, &l);
}

sw_result bd_source_scene(const sw_sg_surface *s, const sw_lod_cubic_set *loop,
                          const double uv_box[4], sw_sg_scene **out, sw_status *status)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "source scene: out of memory");
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = (uint32_t)s->deg_u;
    f.deg_v = (uint32_t)s->deg_v;
    f.n_u = (uint32_t)s->n_u;
    f.n_v = (uint32_t)s->n_v;
    f.knots_u = sw_sg_builder_push_doubles(b, s->knots_u, (size_t)(s->n_u + s->deg_u + 1));
    f.knots_v = sw_sg_builder_push_doubles(b, s->knots_v, (size_t)(s->n_v + s->deg_v + 1));
    f.cpw = sw_sg_builder_push_doubles(b, s->cpw, (size_t)s->n_u * (size_t)s->n_v * 4);
    f.kind = SW_SG_KIND_BSPLINE;
    f.flags = SW_SG_FACE_TRIMMED;
    f.first_loop = add_cubic_loop(b, loop);
    f.n_loops = 1;
    memcpy(f.uv_box, uv_box, sizeof f.uv_box);
    f.tolerance = 1e-7;
    const uint32_t face = sw_sg_builder_add_face(b, &f);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, k_color, "surface");
    return sw_sg_builder_finish(b, out, status);
}

/* ---- the cut -----------------------------------------------------------------------------------
 */
double bd_max_parametric_speed(const sw_lod_hierarchy *h)
{
    double g = 0.0;
    for (int32_t i = 0; i < h->n_nodes; ++i) {
        const sw_lod_hnode *n = &h->nodes[i];
        if (n->child[0] >= 0 || !sw_lod_hnode_cpw_ptr(n))
            continue;
        g = fmax(g, n->tex_c[0] / (n->rect[1] - n->rect[0]));
        g = fmax(g, n->tex_c[1] / (n->rect[3] - n->rect[2]));
    }
    return g;
}

typedef struct cut {
    const sw_lod_hierarchy *h;
    const bd_screen *screen;
    double tol_px;
    int32_t *nodes, n, cap, over;
} cut;

static int cut_push(cut *c, int32_t i)
{
    if (c->n == c->cap) {
        const int32_t cap = c->cap ? 2 * c->cap : 64;
        int32_t *p = realloc(c->nodes, (size_t)cap * sizeof *p);
        if (!p)
            return 0;
        c->nodes = p;
        c->cap = cap;
    }
    c->nodes[c->n++] = i;
    return 1;
}

/* Top-down (§7): a node whose error is within the tolerance at its nearest depth is drawn, else
 * its children; the bicubic and the surface both lie within `error` of the node's box, hence at
 * depth >= min_depth(box) - error. */
static int cut_visit(cut *c, int32_t i)
{
    const sw_lod_hnode *n = &c->h->nodes[i];
    const int leaf = n->child[0] < 0;
    if (sw_lod_hnode_cpw_ptr(n)) {
        const double z = bd_screen_min_depth(c->screen, n->box) - n->error;
        const double tol = bd_screen_tolerance(c->screen, z, c->tol_px);
        if (n->error <= tol || leaf) {
            c->over += n->error > tol;
            return cut_push(c, i);
        }
    } else if (leaf) {
        c->over++; /* nothing to draw it with */
        return 1;
    }
    return cut_visit(c, n->child[0]) && cut_visit(c, n->child[1]);
}

sw_result bd_select_cut(const sw_lod_hierarchy *h, const bd_screen *screen, double tol_px,
                        int32_t **nodes, int32_t *n, int32_t *over, sw_status *status)
{
    cut c = {h, screen, tol_px, NULL, 0, 0, 0};
    if (!cut_visit(&c, h->root)) {
        free(c.nodes);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cut: out of memory");
    }
    *nodes = c.nodes;
    *n = c.n;
    *over = c.over;
    return SW_OK;
}

/* ---- the loop clipped to a rectangle (Sutherland-Hodgman, one half-plane at a time) -----------
 */
typedef struct poly {
    double *uv;
    int32_t n, cap;
} poly;

static int poly_push(poly *p, double u, double v)
{
    if (p->n == p->cap) {
        const int32_t cap = p->cap ? 2 * p->cap : 256;
        double *q = realloc(p->uv, (size_t)cap * 2 * sizeof *q);
        if (!q)
            return 0;
        p->uv = q;
        p->cap = cap;
    }
    p->uv[2 * p->n] = u;
    p->uv[2 * p->n + 1] = v;
    p->n++;
    return 1;
}

/* Keeps the side sign * (uv[axis] - at) >= 0; crossing points lie exactly on the line. */
static int clip_half(const poly *in, int axis, double at, double sign, poly *out)
{
    out->n = 0;
    for (int32_t i = 0; i < in->n; ++i) {
        const double *a = in->uv + 2 * i, *b = in->uv + 2 * ((i + 1) % in->n);
        const double da = sign * (a[axis] - at), db = sign * (b[axis] - at);
        if (da >= 0.0 && !poly_push(out, a[0], a[1]))
            return 0;
        if ((da >= 0.0) != (db >= 0.0)) {
            const double t = da / (da - db);
            double p[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
            p[axis] = at;
            if (!poly_push(out, p[0], p[1]))
                return 0;
        }
    }
    return 1;
}

/* Drops repeated vertices (a crossing at a vertex emits it twice), the closing one included. */
static void poly_dedupe(poly *p)
{
    int32_t m = 0;
    for (int32_t i = 0; i < p->n; ++i) {
        const double *q = p->uv + 2 * i;
        if (m > 0 && q[0] == p->uv[2 * (m - 1)] && q[1] == p->uv[2 * (m - 1) + 1])
            continue;
        p->uv[2 * m] = q[0];
        p->uv[2 * m + 1] = q[1];
        m++;
    }
    while (m > 1 && p->uv[0] == p->uv[2 * (m - 1)] && p->uv[1] == p->uv[2 * (m - 1) + 1])
        m--;
    p->n = m;
}

static double poly_area(const poly *p)
{
    double a = 0.0;
    for (int32_t i = 0; i < p->n; ++i) {
        const double *x = p->uv + 2 * i, *y = p->uv + 2 * ((i + 1) % p->n);
        a += x[0] * y[1] - x[1] * y[0];
    }
    return 0.5 * fabs(a);
}

/* The loop clipped to rect into *a (b: scratch). Returns 0 when out of memory. */
static int clip_to_rect(const sw_sg_polyline *loop, const double rect[4], poly *a, poly *b)
{
    a->n = 0;
    for (uint32_t i = 0; i < loop->count; ++i)
        if (!poly_push(a, loop->uv[2 * i], loop->uv[2 * i + 1]))
            return 0;
    if (!clip_half(a, 0, rect[0], 1.0, b) || !clip_half(b, 0, rect[1], -1.0, a) ||
        !clip_half(a, 1, rect[2], 1.0, b) || !clip_half(b, 1, rect[3], -1.0, a))
        return 0;
    poly_dedupe(a);
    return 1;
}

/* ---- the cut scene -----------------------------------------------------------------------------
 */
/* The clipped loop as one closed degree-1 curve (first vertex repeated at the end). */
static uint32_t add_polygon_loop(sw_sg_builder *b, const poly *p, double *scratch)
{
    const int32_t n = p->n + 1;
    for (int32_t i = 0; i < n; ++i) {
        const double *q = p->uv + 2 * (i % p->n);
        scratch[3 * i] = q[0], scratch[3 * i + 1] = q[1], scratch[3 * i + 2] = 1.0;
    }
    sw_sg_curve_rec c = {1, (uint32_t)n, 0, sw_sg_builder_push_doubles(b, scratch, 3 * (size_t)n)};
    for (int32_t i = 0; i < n + 2; ++i) /* clamped, uniform */
        scratch[i] = i == 0 ? 0.0 : i == n + 1 ? 1.0 : (double)(i - 1) / (n - 1);
    c.knots = sw_sg_builder_push_doubles(b, scratch, (size_t)n + 2);
    sw_sg_loop_rec l = {sw_sg_builder_add_curve(b, &c), 1, SW_SG_LOOP_OUTER, 0};
    return sw_sg_builder_add_loop(b, &l);
}

/* One node as a bicubic face over its rectangle; p: its clipped loop, NULL when untrimmed. */
static void add_node_face(sw_sg_builder *b, const sw_lod_hnode *nd, const poly *p, double *scratch)
{
    const double *r = nd->rect;
    const double ku[8] = {r[0], r[0], r[0], r[0], r[1], r[1], r[1], r[1]};
    const double kv[8] = {r[2], r[2], r[2], r[2], r[3], r[3], r[3], r[3]};
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 3;
    f.n_u = f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, ku, 8);
    f.knots_v = sw_sg_builder_push_doubles(b, kv, 8);
    f.cpw = sw_sg_builder_push_doubles(b, nd->cpw, 64);
    f.kind = SW_SG_KIND_BEZIER;
    f.tolerance = 1e-7;
    memcpy(f.uv_box, r, sizeof f.uv_box);
    if (p) {
        f.flags = SW_SG_FACE_TRIMMED;
        f.first_loop = add_polygon_loop(b, p, scratch);
        f.n_loops = 1;
        f.uv_box[0] = f.uv_box[2] = INFINITY; /* the clipped loop's box */
        f.uv_box[1] = f.uv_box[3] = -INFINITY;
        for (int32_t i = 0; i < p->n; ++i)
            for (int k = 0; k < 2; ++k) {
                f.uv_box[2 * k] = fmin(f.uv_box[2 * k], p->uv[2 * i + k]);
                f.uv_box[2 * k + 1] = fmax(f.uv_box[2 * k + 1], p->uv[2 * i + k]);
            }
    }
    const uint32_t face = sw_sg_builder_add_face(b, &f);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, k_color, NULL);
}

/* Builds the faces into b; returns 0 when out of memory. */
static int add_cut_faces(sw_sg_builder *b, const sw_lod_hierarchy *h, const int32_t *nodes,
                         int32_t n, const sw_sg_polyline *loop, bd_cut_counts *counts)
{
    poly a = {0}, c = {0};
    double *scratch = NULL;
    int ok = 1;
    for (int32_t i = 0; i < n && ok; ++i) {
        const sw_lod_hnode *nd = &h->nodes[nodes[i]];
        if (!(ok = clip_to_rect(loop, nd->rect, &a, &c)))
            break;
        const double area = (nd->rect[1] - nd->rect[0]) * (nd->rect[3] - nd->rect[2]);
        const double in = a.n >= 3 ? poly_area(&a) / area : 0.0;
        if (!(in > 1e-12)) { /* the rectangle lies outside the loop */
            counts->outside++;
            continue;
        }
        counts->area_drawn += in * area;
        if (in >= 1.0 - 1e-9) { /* a simple loop covers the whole rectangle: no trim needed */
            counts->untrimmed++;
            add_node_face(b, nd, NULL, NULL);
            continue;
        }
        double *s = realloc(scratch, 3 * ((size_t)a.n + 3) * sizeof *s);
        if (!(ok = s != NULL))
            break;
        scratch = s;
        counts->trimmed++;
        add_node_face(b, nd, &a, scratch);
    }
    free(a.uv);
    free(c.uv);
    free(scratch);
    return ok;
}

sw_result bd_cut_scene(const sw_lod_hierarchy *h, const int32_t *nodes, int32_t n,
                       const sw_sg_polyline *loop, sw_sg_scene **out, bd_cut_counts *counts,
                       sw_status *status)
{
    memset(counts, 0, sizeof *counts);
    poly whole = {loop->uv, (int32_t)loop->count, 0};
    counts->area_loop = poly_area(&whole);
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b || !add_cut_faces(b, h, nodes, n, loop, counts)) {
        sw_sg_builder_free(b);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cut scene: out of memory");
    }
    return sw_sg_builder_finish(b, out, status);
}

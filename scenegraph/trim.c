/* SPDX-License-Identifier: MIT */
/* Trim loops: snapping their joins closed, flattening them into closed polylines and classifying
 * parameter points by even-odd parity.
 *
 * Guthe et al. 2005 §4 builds each trim texture from triangle fans over the flattened loops with
 * parity toggling; that is exact only when every loop is closed with bit-identical join vertices,
 * hence the snapping and the rule that every join vertex is the image of a curve's first control
 * point. Flattening decomposes each curve into rational Bézier segments (The NURBS Book, A5.6) and
 * subdivides them by de Casteljau until the control polygon lies within the tolerance of its chord
 * (convex hull property of rational curves with positive weights).
 *
 * Bounded at the root: a tolerance below what double arithmetic on the curve's own
 * coordinates can resolve is never met, and every piece then split down to the depth cap, 2^depth
 * pieces per segment (a scaled IGES part asked for 1.85e-17 and spun for minutes). So
 *  - the tolerance is raised to a floor of TRIM_FLOOR_ULPS ulps of the curve's largest
 *    coordinate (de Casteljau's midpoints, the division by the weight and the distance test each
 *    round relative to it, a few ulps per level, TRIM_MAX_DEPTH levels at most); curves flattened
 *    at the floor are counted in the polyline (below_floor);
 *  - the depth is capped by what the request needs: a piece of parameter length 2^-d of a
 *    Bézier segment has a control polygon no longer than 2^-d p max|P_i+1 - P_i| (W^2 for the
 *    weight ratio W of a rational one), which is within the tolerance once that is; pieces emitted
 *    at the cap (rounding, or a loose rational bound) are counted (depth_capped);
 *  - the walk stops as soon as the vertex budget is spent (SW_ERR_LIMIT), so the work is at most
 *    max_vertices x depth splits, whatever the data.
 */
#include "sw_sg_trim.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { TRIM_DIM = 3, TRIM_MAX_DEPTH = 40, TRIM_FLOOR_ULPS = 64 };

/* ---- snapping ------------------------------------------------------------------------------ */

/* Always writes `out`; returns 0 for a non-positive or non-finite weight or result. */
static int euclid(const double *h, double out[2])
{
    out[0] = h[0] / h[2];
    out[1] = h[1] / h[2];
    return h[2] > 0.0 && isfinite(h[2]) && isfinite(out[0]) && isfinite(out[1]);
}

sw_result sw_sg_trim_snap_loop(int32_t n_curves, double *const *cpw, const int32_t *n,
                               double max_gap, const char *what, sw_status *status)
{
    assert(n_curves > 0 && cpw && n);
    /* Check every join before touching any, so a failure leaves the loop unchanged. */
    for (int32_t k = 0; k < n_curves; k++) {
        int32_t next = (k + 1) % n_curves;
        assert(n[k] >= 1 && n[next] >= 1);
        double a[2], b[2];
        if (!euclid(cpw[k] + (size_t)(n[k] - 1) * TRIM_DIM, a) || !euclid(cpw[next], b))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: trim curve %d or %d has a non-positive or non-finite end point",
                            what ? what : "loop", (int)k, (int)next);
        double gap = hypot(a[0] - b[0], a[1] - b[1]);
        if (!(gap <= max_gap))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: gap of %.3g between trim curves %d and %d exceeds %.3g",
                            what ? what : "loop", gap, (int)k, (int)next, max_gap);
    }
    for (int32_t k = 0; k < n_curves; k++) {
        int32_t next = (k + 1) % n_curves;
        double *end = cpw[k] + (size_t)(n[k] - 1) * TRIM_DIM;
        double *start = cpw[next];
        double a[2], b[2];
        euclid(end, a);
        euclid(start, b);
        const double mid[2] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])};
        for (int c = 0; c < 2; c++) {
            end[c] = mid[c] * end[2];
            start[c] = mid[c] * start[2];
        }
    }
    sw__status_ok(status);
    return SW_OK;
}

/* ---- flattening ---------------------------------------------------------------------------- */

typedef struct vertex_buf {
    double *uv;
    uint32_t count, cap, max;
    int overflow, oom;
    uint32_t below_floor, depth_capped; /* the counted fallbacks (sw_sg_polyline) */
} vertex_buf;

static void emit(vertex_buf *vb, const double *h)
{
    if (vb->overflow || vb->oom)
        return;
    if (vb->count >= vb->max) {
        vb->overflow = 1;
        return;
    }
    if (vb->count == vb->cap) {
        uint32_t cap = vb->cap ? vb->cap * 2 : 64;
        if (cap > vb->max)
            cap = vb->max;
        double *uv = sw__realloc(vb->uv, (size_t)cap * 2 * sizeof(double));
        if (!uv) {
            vb->oom = 1;
            return;
        }
        vb->uv = uv;
        vb->cap = cap;
    }
    vb->uv[2 * vb->count] = h[0] / h[2];
    vb->uv[2 * vb->count + 1] = h[1] / h[2];
    vb->count++;
}

static double dist_to_segment(const double p[2], const double a[2], const double b[2])
{
    double dx = b[0] - a[0], dy = b[1] - a[1];
    double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

/* The curve lies in the convex hull of its Euclidean control points, so a control polygon within
 * tol of the chord bounds the chord's distance to the curve. */
static int bezier_flat(const double *q, int32_t p, double tol)
{
    double a[2], b[2], e[2];
    euclid(q, a);
    euclid(q + (size_t)p * TRIM_DIM, b);
    for (int32_t i = 1; i < p; i++) {
        euclid(q + (size_t)i * TRIM_DIM, e);
        if (!(dist_to_segment(e, a, b) <= tol))
            return 0;
    }
    return 1;
}

/* Emits the start vertex of every flat piece of the Bézier segment q (degree p, homogeneous),
 * splitting at t = 1/2 down to depth max_depth; q is overwritten by its left half. Stops at once
 * when the buffer is full or out of memory (the caller fails then). */
static void flatten_bezier(double *q, int32_t p, double tol, int depth, int max_depth,
                           vertex_buf *vb)
{
    if (vb->overflow || vb->oom)
        return;
    if (bezier_flat(q, p, tol)) {
        emit(vb, q);
        return;
    }
    if (depth >= max_depth) {
        vb->depth_capped++;
        emit(vb, q);
        return;
    }
    double right[(SW_SG_MAX_DEGREE + 1) * TRIM_DIM];
    /* de Casteljau: after pass r, q[0..p-r] holds level r; its last point belongs to the right
     * half. q[0] is never modified, so the first vertex stays bit-identical to the input. */
    memcpy(right + (size_t)p * TRIM_DIM, q + (size_t)p * TRIM_DIM, TRIM_DIM * sizeof(double));
    for (int32_t r = 1; r <= p; r++) {
        for (int32_t i = p; i >= r; i--)
            for (int c = 0; c < TRIM_DIM; c++)
                q[i * TRIM_DIM + c] = 0.5 * (q[(i - 1) * TRIM_DIM + c] + q[i * TRIM_DIM + c]);
        memcpy(right + (size_t)(p - r) * TRIM_DIM, q + (size_t)p * TRIM_DIM,
               TRIM_DIM * sizeof(double));
    }
    /* q now holds, at index i, the left half's point i (the diagonal of the scheme). */
    flatten_bezier(q, p, tol, depth + 1, max_depth, vb);
    flatten_bezier(right, p, tol, depth + 1, max_depth, vb);
}

/* The depth at which every piece of Bézier segment q (degree p, homogeneous, positive weights)
 * is flat within tol by the length bound of the header, plus two levels of margin; at most
 * TRIM_MAX_DEPTH (also for tol = 0, the floor of a curve at the origin). */
static int depth_needed(const double *q, int32_t p, double tol)
{
    double wmin = INFINITY, wmax = 0.0, step = 0.0, a[2], b[2];
    for (int32_t i = 0; i <= p; i++) {
        wmin = fmin(wmin, q[i * TRIM_DIM + 2]);
        wmax = fmax(wmax, q[i * TRIM_DIM + 2]);
    }
    for (int32_t i = 0; i < p; i++) {
        euclid(q + (size_t)i * TRIM_DIM, a);
        euclid(q + (size_t)(i + 1) * TRIM_DIM, b);
        step = fmax(step, hypot(b[0] - a[0], b[1] - a[1]));
    }
    const double ratio = wmax / wmin, len = p * step * ratio * ratio;
    if (!(len > tol))
        return 2;
    const double d = ceil(log2(len / tol)) + 2.0;
    return d < TRIM_MAX_DEPTH ? (int)d : TRIM_MAX_DEPTH;
}

static int is_clamped(const sw_sg_curve *c)
{
    const double *u = c->knots;
    int32_t m = c->n + c->degree; /* last knot index */
    for (int32_t i = 1; i <= c->degree; i++)
        if (u[i] != u[0] || u[m - i] != u[m])
            return 0;
    return 1;
}

/* Decomposes a clamped curve into Bézier segments (The NURBS Book A5.6) into qw, which holds
 * (n - p) * (p + 1) points; returns the number of segments. */
static int32_t decompose(const sw_sg_curve *c, double *qw)
{
    const int32_t p = c->degree, m = c->n + p;
    const double *u = c->knots, *pw = c->cpw;
    const size_t seg = (size_t)(p + 1) * TRIM_DIM;
    double alphas[SW_SG_MAX_DEGREE];
    int32_t a = p, b = p + 1, nb = 0;
    memcpy(qw, pw, seg * sizeof(double));
    while (b < m) {
        int32_t i = b;
        while (b < m && u[b + 1] == u[b])
            b++;
        int32_t mult = b - i + 1;
        if (mult < p) {
            double numer = u[b] - u[a];
            for (int32_t j = p; j > mult; j--)
                alphas[j - mult - 1] = numer / (u[a + j] - u[a]);
            int32_t r = p - mult;
            for (int32_t j = 1; j <= r; j++) {
                int32_t save = r - j, s = mult + j;
                double *q = qw + (size_t)nb * seg;
                for (int32_t k = p; k >= s; k--) {
                    double al = alphas[k - s];
                    for (int cc = 0; cc < TRIM_DIM; cc++)
                        q[k * TRIM_DIM + cc] =
                            al * q[k * TRIM_DIM + cc] + (1.0 - al) * q[(k - 1) * TRIM_DIM + cc];
                }
                if (b < m)
                    memcpy(q + seg + (size_t)save * TRIM_DIM, q + (size_t)p * TRIM_DIM,
                           TRIM_DIM * sizeof(double));
            }
        }
        nb++;
        if (b < m) {
            double *q = qw + (size_t)nb * seg;
            /* A knot of full multiplicity p + 1 starts a segment on fresh points. */
            for (int32_t k = mult > p ? 0 : p - mult; k <= p; k++)
                memcpy(q + (size_t)k * TRIM_DIM, pw + (size_t)(b - p + k) * TRIM_DIM,
                       TRIM_DIM * sizeof(double));
            a = b;
            b++;
        }
    }
    return nb;
}

static sw_result flatten_curve(const sw_sg_curve *c, uint32_t index, double tol, vertex_buf *vb,
                               sw_status *status)
{
    if (c->dim != TRIM_DIM || c->degree < 1 || c->degree > SW_SG_MAX_DEGREE ||
        c->n < c->degree + 1 || !is_clamped(c))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "trim curve %u: degree %d with %d points is not a clamped 2D curve", index,
                        (int)c->degree, (int)c->n);
    const int32_t p = c->degree;
    const size_t seg = (size_t)(p + 1) * TRIM_DIM;
    double *qw = sw__malloc((size_t)(c->n - p) * seg * sizeof(double));
    if (!qw)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim curve %u: out of memory", index);
    int32_t nb = decompose(c, qw);
    /* The floor: TRIM_FLOOR_ULPS ulps of the largest Euclidean coordinate of the curve. */
    double mag = 0.0;
    for (int32_t i = 0; i < c->n; i++)
        for (int k = 0; k < 2; k++)
            mag = fmax(mag,
                       fabs(c->cpw[(size_t)i * TRIM_DIM + k] / c->cpw[(size_t)i * TRIM_DIM + 2]));
    const double floor_tol = TRIM_FLOOR_ULPS * DBL_EPSILON * mag;
    if (!(tol >= floor_tol)) {
        tol = floor_tol;
        vb->below_floor++;
    }
    for (int32_t s = 0; s < nb && !vb->overflow && !vb->oom; s++) {
        double *q = qw + (size_t)s * seg;
        flatten_bezier(q, p, tol, 0, depth_needed(q, p, tol), vb);
    }
    sw__free(qw);
    return SW_OK;
}

sw_result sw_sg_trim_flatten_loop(const sw_sg_scene *scene, uint32_t loop, double tol,
                                  uint32_t max_vertices, sw_sg_polyline *out, sw_status *status)
{
    const sw_sg_scene_view *view = sw_sg_scene_view_ptr(scene);
    assert(out && loop < view->n_loops);
    memset(out, 0, sizeof *out);
    const sw_sg_loop_rec *lp = &view->loops[loop];
    vertex_buf vb = {NULL, 0, 0, max_vertices, 0, 0, 0, 0};
    for (uint32_t k = 0; k < lp->n_curves; k++) {
        sw_sg_curve c;
        sw_sg_scene_curve(scene, lp->first_curve + k, &c);
        sw_result r = flatten_curve(&c, lp->first_curve + k, tol, &vb, status);
        if (r != SW_OK) {
            sw__free(vb.uv);
            return r;
        }
    }
    if (vb.oom || vb.overflow) {
        sw__free(vb.uv);
        return vb.oom ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "loop %u: out of memory", loop)
                      : sw__fail(status, SW_ERR_LIMIT,
                                 "loop %u: more than %u vertices at tolerance %g", loop,
                                 max_vertices, tol);
    }
    out->uv = vb.uv;
    out->count = vb.count;
    out->below_floor = vb.below_floor;
    out->depth_capped = vb.depth_capped;
    sw__status_ok(status);
    return SW_OK;
}

void sw_sg_polyline_free(sw_sg_polyline *p)
{
    if (!p)
        return;
    sw__free(p->uv);
    memset(p, 0, sizeof *p);
}

/* ---- classification ------------------------------------------------------------------------ */

/* Crossing number of a ray towards +u; half-open in v so a vertex on the ray counts once. */
int sw_sg_trim_classify(const sw_sg_polyline *loops, uint32_t n_loops, double u, double v)
{
    int inside = 0;
    for (uint32_t l = 0; l < n_loops; l++) {
        const double *p = loops[l].uv;
        uint32_t n = loops[l].count;
        for (uint32_t i = 0, j = n ? n - 1 : 0; i < n; j = i++) {
            double ui = p[2 * i], vi = p[2 * i + 1], uj = p[2 * j], vj = p[2 * j + 1];
            if ((vi > v) != (vj > v) && u < ui + (v - vi) * (uj - ui) / (vj - vi))
                inside ^= 1;
        }
    }
    return inside;
}

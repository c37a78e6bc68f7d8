/* SPDX-License-Identifier: MIT */
/* Outlines into drawable pieces (sw_curves.h): Bézier extraction by knot insertion, the implicit
 * forms of conics and integral cubics as affine functionals k, l, m of the plane, splitting at
 * the cubic's special points, and cubic Hermite approximation of everything else with a rigorous
 * bound. Santana §3 and §3.2; Loop & Blinn 2005 §4 for cubics.
 *
 * Why affine functionals: along a Bézier curve C(t) of degree n, an affine function phi of the
 * plane is a polynomial in t whose Bernstein coefficients are phi at the control points. So if
 * polynomials k(t), l(t), m(t) with k^3 = l m (or k^2 = l m) are affine functions of C(t), F =
 * k^3 - l m vanishes on the curve, and F is a cubic (conic) in x, y: the implicit form. Any
 * triangles covering the piece's neighbourhood can then carry k, l, m (exact under linear
 * interpolation), which is what lets the band drawn for anti-aliasing extend past the hull.
 *
 * Where the paper is loose (§3.2): eq. 2, f = v - w1 u (1 - u) / ((w0 - 2 w1 + w2) u^2 +
 * 2 (w1 - w0) u + w0), substitutes the interpolated texture coordinate u for the curve parameter.
 * With p0 = (0, 0), p1 = (1/2, 1/2), p2 = (1, 0) the curve's u(t) = (w1 t (1 - t) + w2 t^2) / W(t)
 * equals t only when all weights are equal, so eq. 2 is the implicit form of the integral
 * parabola only; for a circle arc it draws a different curve. (It also says "D = 3" for a
 * quadratic.) We use the exact implicit conic in barycentric coordinates of the control triangle:
 * with b0, b1, b2 the barycentric coordinates and weights normalized to (1, w, 1),
 * C(t) has b0 = (1-t)^2 / W, b1 = 2 w t (1-t) / W, b2 = t^2 / W, hence b1^2 = 4 w^2 b0 b2 and
 * F = k^2 - l m with k = b1, l = 2 w b0, m = 2 w b2 (negative between chord and curve).
 */
#include "curves_builder.h"
#include "sw_curves.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

double sw__cb_cross2(const double a[2], const double b[2])
{
    return a[0] * b[1] - a[1] * b[0];
}

void sw__cb_add_corner(builder *b, const double pt[2])
{
    if (b->err != SW_OK)
        return;
    if (b->n_corners == b->cap_corners) {
        size_t cap = b->cap_corners ? 2 * b->cap_corners : 16;
        void *q = sw__realloc(b->corners, cap * sizeof *b->corners);
        if (!q) {
            b->err = sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
            return;
        }
        b->corners = q;
        b->cap_corners = cap;
    }
    b->corners[b->n_corners][0] = pt[0];
    b->corners[b->n_corners][1] = pt[1];
    b->n_corners++;
}

sw__curves_piece *sw__cb_new_piece(builder *b)
{
    if (b->err != SW_OK)
        return NULL;
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 64;
        void *q = sw__realloc(b->p, cap * sizeof *b->p);
        if (!q) {
            b->err = sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
            return NULL;
        }
        b->p = q;
        b->cap = cap;
    }
    sw__curves_piece *p = &b->p[b->n++];
    memset(p, 0, sizeof *p);
    p->loop = b->loop;
    p->approx = (uint32_t)b->approx;
    if (b->approx)
        b->n_approx++;
    return p;
}

/* Unit tangent at the start (dir = +1: from cp[0] to the first distinct point) or at the end. */
static void end_tangent(const double (*cp)[2], int n, int at_end, double out[2])
{
    out[0] = out[1] = 0.0;
    double scale = 0.0;
    for (int i = 0; i < n; ++i)
        scale = fmax(scale, fmax(fabs(cp[i][0] - cp[0][0]), fabs(cp[i][1] - cp[0][1])));
    for (int i = 1; i < n; ++i) {
        const double *a = at_end ? cp[n - 1 - i] : cp[0];
        const double *e = at_end ? cp[n - 1] : cp[i];
        double d[2] = {e[0] - a[0], e[1] - a[1]};
        double len = hypot(d[0], d[1]);
        if (len > 1e-12 * scale) {
            out[0] = d[0] / len;
            out[1] = d[1] / len;
            return;
        }
    }
}

double sw__curves_piece_eval(const sw__curves_piece *p, double x, double y)
{
    double v[3];
    for (int j = 0; j < 3; ++j)
        v[j] = p->klm[j][0] * x + p->klm[j][1] * y + p->klm[j][2];
    switch (p->kind) {
    case SW__CURVES_LINE:
        return v[0];
    case SW__CURVES_CONIC:
        return v[0] * v[0] - v[1] * v[2];
    case SW__CURVES_CUSP: {
        double k = fmax(v[0], 0.0);
        return v[1] + p->branch * k * sqrt(k);
    }
    default:
        return v[0] * v[0] * v[0] - v[1] * v[2];
    }
}

static void piece_grad(const sw__curves_piece *p, double x, double y, double g[2])
{
    double v[3];
    for (int j = 0; j < 3; ++j)
        v[j] = p->klm[j][0] * x + p->klm[j][1] * y + p->klm[j][2];
    if (p->kind == SW__CURVES_CUSP) {
        double rk = 1.5 * p->branch * sqrt(fmax(v[0], 0.0));
        for (int c = 0; c < 2; ++c)
            g[c] = p->klm[1][c] + rk * p->klm[0][c];
        return;
    }
    double ck = p->kind == SW__CURVES_LINE    ? 1.0
                : p->kind == SW__CURVES_CONIC ? 2.0 * v[0]
                                              : 3.0 * v[0] * v[0];
    double cl = p->kind == SW__CURVES_LINE ? 0.0 : -v[2],
           cm = p->kind == SW__CURVES_LINE ? 0.0 : -v[1];
    for (int c = 0; c < 2; ++c)
        g[c] = ck * p->klm[0][c] + cl * p->klm[1][c] + cm * p->klm[2][c];
}

/* The signs: s_chord from F at the chord's midpoint, s_in from grad F at the curve's mid point
 * against the left normal (loops are taken counter-clockwise here; create() flips s_in of
 * loops whose parity says otherwise). */
void sw__cb_orient(sw__curves_piece *p, const double mid[2], const double dmid[2])
{
    const int n = p->n_cp;
    if (p->kind == SW__CURVES_LINE) {
        p->s_chord = 1.0;
    } else {
        double cx = 0.5 * (p->cp[0][0] + p->cp[n - 1][0]),
               cy = 0.5 * (p->cp[0][1] + p->cp[n - 1][1]);
        p->s_chord = sw__curves_piece_eval(p, cx, cy) < 0.0 ? 1.0 : -1.0;
    }
    double g[2];
    piece_grad(p, mid[0], mid[1], g);
    double left[2] = {-dmid[1], dmid[0]};
    p->s_in = g[0] * left[0] + g[1] * left[1] > 0.0 ? -1.0 : 1.0;
    end_tangent(p->cp, n, 0, p->tan0);
    end_tangent(p->cp, n, 1, p->tan1);
}

void sw__cb_emit_line(builder *b, const double a[2], const double e[2])
{
    double d[2] = {e[0] - a[0], e[1] - a[1]};
    double len = hypot(d[0], d[1]);
    if (!(len > 0.0))
        return; /* a zero-length piece bounds no area */
    sw__curves_piece *p = sw__cb_new_piece(b);
    if (!p)
        return;
    p->kind = SW__CURVES_LINE;
    p->n_cp = 2;
    memcpy(p->cp[0], a, sizeof p->cp[0]);
    memcpy(p->cp[1], e, sizeof p->cp[1]);
    /* k = signed distance, negative on the left */
    p->klm[0][0] = d[1] / len;
    p->klm[0][1] = -d[0] / len;
    p->klm[0][2] = -(p->klm[0][0] * a[0] + p->klm[0][1] * a[1]);
    double mid[2] = {0.5 * (a[0] + e[0]), 0.5 * (a[1] + e[1])};
    sw__cb_orient(p, mid, d);
}

/* Rational quadratic with Euclidean points q and weights w (all > 0). */

static void conic_split(const double q[3][2], const double w[3], double t, double lq[3][2],
                        double lw[3], double rq[3][2], double rw[3])
{
    double h[3][3];
    for (int i = 0; i < 3; ++i) {
        h[i][0] = w[i] * q[i][0];
        h[i][1] = w[i] * q[i][1];
        h[i][2] = w[i];
    }
    double a[3], bb[3], c[3];
    for (int k = 0; k < 3; ++k) {
        a[k] = (1 - t) * h[0][k] + t * h[1][k];
        bb[k] = (1 - t) * h[1][k] + t * h[2][k];
        c[k] = (1 - t) * a[k] + t * bb[k];
    }
    const double *L[3] = {h[0], a, c}, *R[3] = {c, bb, h[2]};
    for (int i = 0; i < 3; ++i) {
        lw[i] = L[i][2];
        lq[i][0] = L[i][0] / L[i][2];
        lq[i][1] = L[i][1] / L[i][2];
        rw[i] = R[i][2];
        rq[i][0] = R[i][0] / R[i][2];
        rq[i][1] = R[i][1] / R[i][2];
    }
    /* the shared point bit-identical */
    memcpy(rq[0], lq[2], sizeof rq[0]);
}

double sw__cb_polygon_turn(const double (*cp)[2], int n, int *convex)
{
    double turn = 0.0, prev[2] = {0, 0};
    int have = 0, sign = 0;
    *convex = 1;
    for (int i = 1; i < n; ++i) {
        double d[2] = {cp[i][0] - cp[i - 1][0], cp[i][1] - cp[i - 1][1]};
        if (d[0] == 0.0 && d[1] == 0.0)
            continue;
        if (have) {
            double a = atan2(sw__cb_cross2(prev, d), prev[0] * d[0] + prev[1] * d[1]);
            int s = a > 1e-12 ? 1 : a < -1e-12 ? -1 : 0;
            if (s && sign && s != sign)
                *convex = 0;
            if (s)
                sign = s;
            turn += fabs(a);
        }
        prev[0] = d[0];
        prev[1] = d[1];
        have = 1;
    }
    return turn;
}

/* Largest distance of the control points from the chord's line, relative to the chord. */
double sw__cb_flatness(const double (*cp)[2], int n)
{
    double d[2] = {cp[n - 1][0] - cp[0][0], cp[n - 1][1] - cp[0][1]};
    double len = hypot(d[0], d[1]), m = 0.0;
    if (!(len > 0.0))
        return INFINITY;
    for (int i = 1; i < n - 1; ++i) {
        double e[2] = {cp[i][0] - cp[0][0], cp[i][1] - cp[0][1]};
        m = fmax(m, fabs(sw__cb_cross2(d, e)) / len);
        /* a control point beyond the chord's ends makes the piece not flat */
        double s = (d[0] * e[0] + d[1] * e[1]) / (len * len);
        if (s < -1e-12 || s > 1 + 1e-12)
            return INFINITY;
    }
    return m / len;
}

void sw__cb_emit_conic(builder *b, const double q[3][2], const double w[3], int depth)
{
    if (b->err != SW_OK)
        return;
    int convex;
    double turn = sw__cb_polygon_turn(q, 3, &convex);
    if (sw__cb_flatness(q, 3) < 1e-9) {
        sw__cb_emit_line(b, q[0], q[2]);
        return;
    }
    if ((turn > MAX_TURN || sw__cb_flatness(q, 3) == INFINITY) && depth < MAX_SPLIT_DEPTH) {
        double lq[3][2], lw[3], rq[3][2], rw[3];
        conic_split(q, w, 0.5, lq, lw, rq, rw);
        sw__cb_emit_conic(b, lq, lw, depth + 1);
        sw__cb_emit_conic(b, rq, rw, depth + 1);
        return;
    }
    sw__curves_piece *p = sw__cb_new_piece(b);
    if (!p)
        return;
    p->kind = SW__CURVES_CONIC;
    p->n_cp = 3;
    memcpy(p->cp, q, sizeof(double) * 6);
    p->w = w[1] / sqrt(w[0] * w[2]);
    /* barycentric coordinates of the control triangle as affine functionals */
    double e1[2] = {q[1][0] - q[0][0], q[1][1] - q[0][1]};
    double e2[2] = {q[2][0] - q[0][0], q[2][1] - q[0][1]};
    double det = sw__cb_cross2(e1, e2);
    /* b1 = cross(x - q0, e2) / det, b2 = cross(e1, x - q0) / det, b0 = 1 - b1 - b2 */
    double B1[3] = {e2[1] / det, -e2[0] / det, 0}, B2[3] = {-e1[1] / det, e1[0] / det, 0};
    B1[2] = -(B1[0] * q[0][0] + B1[1] * q[0][1]);
    B2[2] = -(B2[0] * q[0][0] + B2[1] * q[0][1]);
    double B0[3] = {-B1[0] - B2[0], -B1[1] - B2[1], 1.0 - B1[2] - B2[2]};
    for (int c = 0; c < 3; ++c) {
        p->klm[0][c] = B1[c];
        p->klm[1][c] = 2.0 * p->w * B0[c];
        p->klm[2][c] = 2.0 * p->w * B2[c];
    }
    /* the curve's mid point and tangent */
    double W = 0.25 * w[0] + 0.5 * w[1] + 0.25 * w[2];
    double mid[2], dmid[2];
    for (int c = 0; c < 2; ++c)
        mid[c] = (0.25 * w[0] * q[0][c] + 0.5 * w[1] * q[1][c] + 0.25 * w[2] * q[2][c]) / W;
    /* at t = 1/2 the tangent is parallel to the chord for symmetric weights; in general
     * C'(t) ~ w0 w1 (q1 - q0)(1-t)^2 + w0 w2 (q2 - q0) t (1-t)... use a difference instead */
    double lq[3][2], lw[3], rq[3][2], rw[3];
    conic_split(q, w, 0.5, lq, lw, rq, rw);
    dmid[0] = rq[1][0] - lq[1][0];
    dmid[1] = rq[1][1] - lq[1][1];
    sw__cb_orient(p, mid, dmid);
}

/* ---- approximation of rational cubics and degrees > 3 ------------------------------------------
 * A rational Bézier piece C(t) = P(t) / w(t) of degree p (P(t) = sum B^p_i w_i b_i) is replaced by
 * the cubic Hermite interpolant H(t) of its end points and end derivatives (C'(0) = p w1/w0
 * (b1 - b0), C'(1) = p w_{p-1}/w_p (b_p - b_{p-1})), a C1 join with its neighbours, so the
 * approximation adds no corner. The bound: C - H = N / w with N(t) = P(t) - w(t) H(t), a
 * polynomial of degree p + 3 whose Bernstein coefficients follow from the product rule
 * B^p_i B^3_j = [C(p,i) C(3,j) / C(p+3,i+j)] B^{p+3}_{i+j}:
 *     N_k = sum_{i+j=k} [C(p,i) C(3,j) / C(p+3,k)] w_i (b_i - H_j).
 * The Bernstein basis is a partition of unity, so |N(t)| <= max_k |N_k|, and w(t) >= min_i w_i
 * > 0; hence for every t, |C(t) - H(t)| <= max_k |N_k| / min_i w_i =: bound. That bounds the
 * Hausdorff distance of the two curves. Pieces are bisected (in homogeneous form) until the bound
 * is within the tolerance. It converges as h^4 (Hermite interpolation error). */
static double binom(int n, int k)
{
    double r = 1.0;
    for (int i = 1; i <= k; ++i)
        r = r * (n - k + i) / i;
    return r;
}

static double hermite(const double *h, int p, double H[4][2])
{
    double b[SW_SG_MAX_DEGREE + 1][2], w[SW_SG_MAX_DEGREE + 1], wmin = INFINITY;
    for (int i = 0; i <= p; ++i) {
        w[i] = h[3 * i + 2];
        b[i][0] = h[3 * i] / w[i];
        b[i][1] = h[3 * i + 1] / w[i];
        wmin = fmin(wmin, w[i]);
    }
    for (int c = 0; c < 2; ++c) {
        double d0 = p * w[1] / w[0] * (b[1][c] - b[0][c]);
        double d1 = p * w[p - 1] / w[p] * (b[p][c] - b[p - 1][c]);
        H[0][c] = b[0][c];
        H[1][c] = b[0][c] + d0 / 3.0;
        H[2][c] = b[p][c] - d1 / 3.0;
        H[3][c] = b[p][c];
    }
    double worst = 0.0;
    for (int kk = 0; kk <= p + 3; ++kk) {
        double n[2] = {0, 0};
        for (int j = 0; j <= 3; ++j) {
            int i = kk - j;
            if (i < 0 || i > p)
                continue;
            double c = binom(p, i) * binom(3, j) / binom(p + 3, kk) * w[i];
            n[0] += c * (b[i][0] - H[j][0]);
            n[1] += c * (b[i][1] - H[j][1]);
        }
        worst = fmax(worst, hypot(n[0], n[1]));
    }
    return worst / wmin;
}

static void hsplit(const double *h, int p, double *l, double *r)
{
    double tmp[(SW_SG_MAX_DEGREE + 1) * 3];
    memcpy(tmp, h, sizeof(double) * 3 * (size_t)(p + 1));
    for (int c = 0; c < 3; ++c) {
        l[c] = tmp[c];
        r[3 * p + c] = tmp[3 * p + c];
    }
    for (int lev = 1; lev <= p; ++lev) {
        for (int i = 0; i <= p - lev; ++i)
            for (int c = 0; c < 3; ++c)
                tmp[3 * i + c] = 0.5 * (tmp[3 * i + c] + tmp[3 * (i + 1) + c]);
        for (int c = 0; c < 3; ++c) {
            l[3 * lev + c] = tmp[c];
            r[3 * (p - lev) + c] = tmp[3 * (p - lev) + c];
        }
    }
}

static void emit_approx(builder *b, const double *h, int p, int depth)
{
    if (b->err != SW_OK)
        return;
    double H[4][2];
    double bound = hermite(h, p, H);
    if (bound > b->tol && depth < 40) {
        double l[(SW_SG_MAX_DEGREE + 1) * 3], r[(SW_SG_MAX_DEGREE + 1) * 3];
        hsplit(h, p, l, r);
        emit_approx(b, l, p, depth + 1);
        emit_approx(b, r, p, depth + 1);
        return;
    }
    b->bound = fmax(b->bound, bound);
    b->approx = 1;
    sw__cb_emit_cubic(b, H);
    b->approx = 0;
}

/* One rational Bézier segment (homogeneous, degree p). */
static void emit_bezier(builder *b, const double *h, int p)
{
    double w0 = h[2];
    int rational = 0;
    for (int i = 1; i <= p; ++i)
        if (fabs(h[3 * i + 2] - w0) > 1e-14 * w0)
            rational = 1;
    double q[4][2];
    if (p == 1) {
        for (int i = 0; i < 2; ++i) {
            q[i][0] = h[3 * i] / h[3 * i + 2];
            q[i][1] = h[3 * i + 1] / h[3 * i + 2];
        }
        sw__cb_emit_line(b, q[0], q[1]);
    } else if (p == 2) {
        double w[3];
        for (int i = 0; i < 3; ++i) {
            w[i] = h[3 * i + 2];
            q[i][0] = h[3 * i] / w[i];
            q[i][1] = h[3 * i + 1] / w[i];
        }
        sw__cb_emit_conic(b, (const double(*)[2])q, w, 0);
    } else if (p == 3 && !rational) {
        for (int i = 0; i < 4; ++i) {
            q[i][0] = h[3 * i] / h[3 * i + 2];
            q[i][1] = h[3 * i + 1] / h[3 * i + 2];
        }
        sw__cb_emit_cubic(b, (const double(*)[2])q);
    } else {
        emit_approx(b, h, p, 0);
    }
}

sw_result sw__curves_for_each_bezier(const sw_sg_curve *c, sw__curves_bezier_fn fn, void *ctx,
                                     sw_status *status)
{
    const int p = c->degree;
    int32_t n = c->n;
    size_t cap_n = (size_t)n + (size_t)(n + p) * (size_t)p;
    double *knots = sw__malloc(sizeof(double) * (cap_n + (size_t)p + 1));
    double *cpw = sw__malloc(sizeof(double) * 3 * cap_n);
    double *k2 = sw__malloc(sizeof(double) * (cap_n + (size_t)p + 1));
    double *c2 = sw__malloc(sizeof(double) * 3 * cap_n);
    sw_result r = SW_OK;
    if (!knots || !cpw || !k2 || !c2) {
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
        goto done;
    }
    memcpy(knots, c->knots, sizeof(double) * (size_t)(n + p + 1));
    memcpy(cpw, c->cpw, sizeof(double) * 3 * (size_t)n);
    for (int32_t i = p + 1; i < n;) {
        double t = knots[i];
        int32_t mult = 0;
        while (i + mult < n && knots[i + mult] == t)
            mult++;
        if (mult < p) {
            sw_sg_curve cur = {p, n, 3, knots, cpw};
            sw_sg_curve_insert_knot(&cur, t, p - mult, k2, c2);
            n += p - mult;
            memcpy(knots, k2, sizeof(double) * (size_t)(n + p + 1));
            memcpy(cpw, c2, sizeof(double) * 3 * (size_t)n);
        }
        i += p; /* now the knot has multiplicity p (or p + 1: a discontinuity, kept) */
        while (i < n && knots[i] == t)
            i++;
    }
    for (int32_t s = 0; s + p < n; s += p)
        fn(ctx, cpw + 3 * (size_t)s, p);
done:
    sw__free(knots);
    sw__free(cpw);
    sw__free(k2);
    sw__free(c2);
    return r;
}

static void emit_bezier_fn(void *ctx, const double *h, int32_t p)
{
    builder *b = ctx;
    if (b->err == SW_OK)
        emit_bezier(b, h, p);
}

static void emit_curve(builder *b, const sw_sg_curve *c)
{
    sw_result r = sw__curves_for_each_bezier(c, emit_bezier_fn, b, b->status);
    if (r != SW_OK && b->err == SW_OK)
        b->err = r;
}

static int is_clamped(const sw_sg_curve *c)
{
    const int p = c->degree;
    for (int i = 1; i <= p; ++i)
        if (c->knots[i] != c->knots[0] || c->knots[c->n + i - 1] != c->knots[c->n + p])
            return 0;
    return 1;
}

static void curve_end(const sw_sg_curve *c, int at_end, double out[2])
{
    const double *h = c->cpw + (at_end ? 3 * (size_t)(c->n - 1) : 0);
    out[0] = h[0] / h[2];
    out[1] = h[1] / h[2];
}

/* A point of a piece at parameter t. */
static void piece_point(const sw__curves_piece *p, double t, double out[2])
{
    double mt = 1 - t;
    for (int c = 0; c < 2; ++c) {
        if (p->kind == SW__CURVES_CONIC) {
            double W = mt * mt + 2 * p->w * mt * t + t * t;
            out[c] =
                (mt * mt * p->cp[0][c] + 2 * p->w * mt * t * p->cp[1][c] + t * t * p->cp[2][c]) / W;
        } else if (p->kind == SW__CURVES_CUBIC || p->kind == SW__CURVES_CUSP) {
            out[c] = mt * mt * mt * p->cp[0][c] + 3 * mt * mt * t * p->cp[1][c] +
                     3 * mt * t * t * p->cp[2][c] + t * t * t * p->cp[3][c];
        } else {
            out[c] = mt * p->cp[0][c] + t * p->cp[1][c];
        }
    }
}

/* Even-odd parity of points against the outline, each piece as a 32-chord polyline through its
 * points at t = j / 32 (exact at t = 1/2, where build() asks). The chords are bucketed once into
 * horizontal rows by their y range, so a point tests only the chords of its row: a chord crossing
 * the point's horizontal line has that line's y in its range, so it is in that row. */
#define PARITY_CHORDS 32

typedef struct parity_grid {
    double (*seg)[4]; /* x0, y0, x1, y1 */
    size_t n_seg;
    size_t *start; /* row r's chords: idx[start[r] .. start[r + 1]) */
    size_t *idx;
    size_t rows;
    double y0, h;
} parity_grid;

static size_t grid_row(const parity_grid *g, double y)
{
    double r = floor((y - g->y0) / g->h);
    return r < 0.0 ? 0 : r >= (double)g->rows ? g->rows - 1 : (size_t)r;
}

static int parity_grid_make(parity_grid *g, const sw__curves_piece *ps, size_t n)
{
    memset(g, 0, sizeof *g);
    g->n_seg = n * PARITY_CHORDS;
    g->seg = sw__malloc(sizeof *g->seg * (g->n_seg ? g->n_seg : 1));
    if (!g->seg)
        return 0;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double prev[2] = {ps[i].cp[0][0], ps[i].cp[0][1]};
        for (int j = 1; j <= PARITY_CHORDS; ++j) {
            double cur[2], *sg = g->seg[i * PARITY_CHORDS + (size_t)(j - 1)];
            piece_point(&ps[i], (double)j / PARITY_CHORDS, cur);
            sg[0] = prev[0];
            sg[1] = prev[1];
            sg[2] = cur[0];
            sg[3] = cur[1];
            lo = fmin(lo, fmin(prev[1], cur[1]));
            hi = fmax(hi, fmax(prev[1], cur[1]));
            prev[0] = cur[0];
            prev[1] = cur[1];
        }
    }
    g->rows = (size_t)sqrt((double)g->n_seg) + 1;
    g->y0 = lo;
    g->h = hi > lo ? (hi - lo) / (double)g->rows : 1.0;
    g->start = sw__calloc(g->rows + 1, sizeof *g->start);
    if (!g->start)
        return 0;
    for (int pass = 0; pass < 2; ++pass) { /* count, then fill */
        for (size_t k = 0; k < g->n_seg; ++k) {
            const double *sg = g->seg[k];
            size_t r0 = grid_row(g, fmin(sg[1], sg[3])), r1 = grid_row(g, fmax(sg[1], sg[3]));
            for (size_t r = r0; r <= r1; ++r) {
                if (pass == 0)
                    g->start[r + 1]++;
                else
                    g->idx[g->start[r]++] = k;
            }
        }
        if (pass == 0) {
            for (size_t r = 0; r < g->rows; ++r)
                g->start[r + 1] += g->start[r];
            g->idx = sw__malloc(sizeof *g->idx * (g->start[g->rows] ? g->start[g->rows] : 1));
            if (!g->idx)
                return 0;
        } else { /* the fill advanced each start to the next row's: shift back */
            for (size_t r = g->rows; r > 0; --r)
                g->start[r] = g->start[r - 1];
            g->start[0] = 0;
        }
    }
    return 1;
}

static void parity_grid_free(parity_grid *g)
{
    sw__free(g->seg);
    sw__free(g->start);
    sw__free(g->idx);
}

static int parity(const parity_grid *g, const double pt[2])
{
    int in = 0;
    size_t r = grid_row(g, pt[1]);
    for (size_t k = g->start[r]; k < g->start[r + 1]; ++k) {
        const double *sg = g->seg[g->idx[k]];
        if ((sg[1] > pt[1]) != (sg[3] > pt[1])) {
            double x = sg[0] + (pt[1] - sg[1]) * (sg[2] - sg[0]) / (sg[3] - sg[1]);
            if (x > pt[0])
                in ^= 1;
        }
    }
    return in;
}

static sw_result build(sw__curves_shape *s, sw_status *status)
{
    builder b = {0};
    b.tol = s->approx_tol;
    b.status = status;
    b.err = SW_OK;
    const sw_sg_curve *cur = s->src;
    for (uint32_t L = 0; L < s->n_src_loops && b.err == SW_OK; ++L) {
        b.loop = L;
        size_t first = b.n;
        for (uint32_t k = 0; k < s->src_loop_n[L] && b.err == SW_OK; ++k)
            emit_curve(&b, &cur[k]);
        /* corners: joins whose tangents differ (between curves, and cusps met inside) */
        for (size_t i = first; i < b.n && b.err == SW_OK; ++i) {
            const sw__curves_piece *pv = &b.p[i == first ? b.n - 1 : i - 1], *pc = &b.p[i];
            double c = pv->tan1[0] * pc->tan0[0] + pv->tan1[1] * pc->tan0[1];
            if (c < 1.0 - 1e-9)
                sw__cb_add_corner(&b, pc->cp[0]);
        }
        cur += s->src_loop_n[L];
    }
    if (b.err == SW_OK) {
        /* Which side is inside, by parity just left of each piece's mid point: sw__cb_orient() took
         * the left. Loop orientation alone cannot say it: a self-crossing loop (a loop cubic
         * closed by a line) has its inside on the left in one lobe and on the right in the
         * other. */
        parity_grid grid;
        if (!parity_grid_make(&grid, b.p, b.n))
            b.err = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
        for (size_t i = 0; i < b.n && b.err == SW_OK; ++i) {
            sw__curves_piece *p = &b.p[i];
            double m[2], a[2], e[2];
            piece_point(p, 0.5, m);
            piece_point(p, 0.5 - 1e-4, a);
            piece_point(p, 0.5 + 1e-4, e);
            double d[2] = {e[0] - a[0], e[1] - a[1]}, len = hypot(d[0], d[1]);
            double chord =
                hypot(p->cp[p->n_cp - 1][0] - p->cp[0][0], p->cp[p->n_cp - 1][1] - p->cp[0][1]);
            double eps = 1e-3 * chord / len;
            double q[2] = {m[0] - eps * d[1], m[1] + eps * d[0]};
            if (!parity(&grid, q))
                p->s_in = -p->s_in;
        }
        parity_grid_free(&grid);
    }
    if (b.err != SW_OK) {
        sw__free(b.p);
        sw__free(b.corners);
        return b.err;
    }
    sw__free(s->pieces);
    sw__free(s->corners);
    s->pieces = b.p;
    s->n_pieces = b.n;
    s->corners = b.corners;
    s->n_corners = b.n_corners;
    s->approx_bound = b.bound;
    s->n_approx = b.n_approx;
    return SW_OK;
}

sw_result sw__curves_shape_create(const sw__curves_loop *loops, uint32_t n_loops,
                                  double px_per_unit, sw__curves_shape **out, sw_status *status)
{
    assert(out && (loops || !n_loops) && px_per_unit > 0.0);
    *out = NULL;
    size_t n_curves = 0, n_doubles = 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t L = 0; L < n_loops; ++L) {
        if (loops[L].n_curves == 0)
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "curves: loop %u is empty", L);
        for (uint32_t k = 0; k < loops[L].n_curves; ++k) {
            const sw_sg_curve *c = &loops[L].curves[k];
            sw_result r = sw_sg_curve_validate(c, "outline curve", status);
            if (r != SW_OK)
                return r;
            if (c->dim != 3 || !is_clamped(c))
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "curves: loop %u curve %u is not a clamped 2D curve", L, k);
            n_curves++;
            n_doubles += (size_t)(c->n + c->degree + 1) + 3 * (size_t)c->n;
            for (int32_t i = 0; i < c->n; ++i)
                for (int d = 0; d < 2; ++d) {
                    double x = c->cpw[3 * i + d] / c->cpw[3 * i + 2];
                    lo[d] = fmin(lo[d], x);
                    hi[d] = fmax(hi[d], x);
                }
        }
    }
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    for (uint32_t L = 0; L < n_loops; ++L)
        for (uint32_t k = 0; k < loops[L].n_curves; ++k) {
            double e[2], s0[2];
            curve_end(&loops[L].curves[k], 1, e);
            curve_end(&loops[L].curves[(k + 1) % loops[L].n_curves], 0, s0);
            if (hypot(e[0] - s0[0], e[1] - s0[1]) > 1e-9 * size)
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "curves: loop %u is open after curve %u", L, k);
        }
    sw__curves_shape *s = sw__calloc(1, sizeof *s);
    if (!s)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    s->src_loop_n = sw__calloc(n_loops ? n_loops : 1, sizeof *s->src_loop_n);
    s->src = sw__calloc(n_curves ? n_curves : 1, sizeof *s->src);
    s->src_data = sw__calloc(n_doubles ? n_doubles : 1, sizeof *s->src_data);
    if (!s->src_loop_n || !s->src || !s->src_data) {
        sw__curves_shape_free(s);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    }
    s->n_src_loops = n_loops;
    s->n_loops = n_loops;
    double *d = s->src_data;
    size_t ci = 0;
    for (uint32_t L = 0; L < n_loops; ++L) {
        s->src_loop_n[L] = loops[L].n_curves;
        for (uint32_t k = 0; k < loops[L].n_curves; ++k) {
            const sw_sg_curve *c = &loops[L].curves[k];
            size_t nk = (size_t)(c->n + c->degree + 1), nc = 3 * (size_t)c->n;
            memcpy(d, c->knots, sizeof(double) * nk);
            memcpy(d + nk, c->cpw, sizeof(double) * nc);
            s->src[ci] = (sw_sg_curve){c->degree, c->n, 3, d, d + nk};
            ci++;
            d += nk + nc;
        }
    }
    /* snap each join to the next curve's start, bit-identically, with the curve's own weight */
    ci = 0;
    for (uint32_t L = 0; L < n_loops; ++L) {
        for (uint32_t k = 0; k < loops[L].n_curves; ++k) {
            sw_sg_curve *c = &s->src[ci + k], *nx = &s->src[ci + (k + 1) % loops[L].n_curves];
            double *e = (double *)c->cpw + 3 * (size_t)(c->n - 1);
            double st[2];
            curve_end(nx, 0, st);
            e[0] = st[0] * e[2];
            e[1] = st[1] * e[2];
        }
        ci += loops[L].n_curves;
    }
    s->box[0] = lo[0];
    s->box[1] = lo[1];
    s->box[2] = hi[0];
    s->box[3] = hi[1];
    s->approx_tol = SW__CURVES_BUILD_PX / px_per_unit;
    sw_result r = build(s, status);
    if (r != SW_OK) {
        sw__curves_shape_free(s);
        return r;
    }
    *out = s;
    return SW_OK;
}

sw_result sw__curves_shape_fit_view(sw__curves_shape *shape, double px_per_unit, int *rebuilt,
                                    sw_status *status)
{
    if (rebuilt)
        *rebuilt = 0;
    if (shape->n_approx == 0 || shape->approx_bound * px_per_unit <= SW__CURVES_REFIT_PX)
        return SW_OK;
    shape->approx_tol = SW__CURVES_BUILD_PX / px_per_unit;
    sw_result r = build(shape, status);
    if (r == SW_OK) {
        shape->rebuilds++;
        if (rebuilt)
            *rebuilt = 1;
    }
    return r;
}

void sw__curves_shape_free(sw__curves_shape *s)
{
    if (!s)
        return;
    sw__free(s->pieces);
    sw__free(s->corners);
    sw__free(s->src_loop_n);
    sw__free(s->src);
    sw__free(s->src_data);
    sw__free(s);
}

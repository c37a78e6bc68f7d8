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
#include "sw_curves.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SPLIT_DEPTH 20
#define MAX_TURN (100.0 * M_PI / 180.0) /* a piece's control polygon turns at most this much */

typedef struct builder {
    sw__curves_piece *p;
    size_t n, cap;
    double (*corners)[2];
    size_t n_corners, cap_corners;
    double tol;   /* approximation tolerance, model units */
    double bound; /* largest bound met */
    uint32_t n_approx;
    uint32_t loop;
    int approx; /* pieces emitted now come from an approximation */
    sw_result err;
    sw_status *status;
} builder;

static double cross2(const double a[2], const double b[2])
{
    return a[0] * b[1] - a[1] * b[0];
}

static void add_corner(builder *b, const double pt[2])
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

static sw__curves_piece *new_piece(builder *b)
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
static void orient(sw__curves_piece *p, const double mid[2], const double dmid[2])
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

static void emit_line(builder *b, const double a[2], const double e[2])
{
    double d[2] = {e[0] - a[0], e[1] - a[1]};
    double len = hypot(d[0], d[1]);
    if (!(len > 0.0))
        return; /* a zero-length piece bounds no area */
    sw__curves_piece *p = new_piece(b);
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
    orient(p, mid, d);
}

/* Rational quadratic with Euclidean points q and weights w (all > 0). */
static void emit_conic(builder *b, const double q[3][2], const double w[3], int depth);

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

static double polygon_turn(const double (*cp)[2], int n, int *convex)
{
    double turn = 0.0, prev[2] = {0, 0};
    int have = 0, sign = 0;
    *convex = 1;
    for (int i = 1; i < n; ++i) {
        double d[2] = {cp[i][0] - cp[i - 1][0], cp[i][1] - cp[i - 1][1]};
        if (d[0] == 0.0 && d[1] == 0.0)
            continue;
        if (have) {
            double a = atan2(cross2(prev, d), prev[0] * d[0] + prev[1] * d[1]);
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
static double flatness(const double (*cp)[2], int n)
{
    double d[2] = {cp[n - 1][0] - cp[0][0], cp[n - 1][1] - cp[0][1]};
    double len = hypot(d[0], d[1]), m = 0.0;
    if (!(len > 0.0))
        return INFINITY;
    for (int i = 1; i < n - 1; ++i) {
        double e[2] = {cp[i][0] - cp[0][0], cp[i][1] - cp[0][1]};
        m = fmax(m, fabs(cross2(d, e)) / len);
        /* a control point beyond the chord's ends makes the piece not flat */
        double s = (d[0] * e[0] + d[1] * e[1]) / (len * len);
        if (s < -1e-12 || s > 1 + 1e-12)
            return INFINITY;
    }
    return m / len;
}

static void emit_conic(builder *b, const double q[3][2], const double w[3], int depth)
{
    if (b->err != SW_OK)
        return;
    int convex;
    double turn = polygon_turn(q, 3, &convex);
    if (flatness(q, 3) < 1e-9) {
        emit_line(b, q[0], q[2]);
        return;
    }
    if ((turn > MAX_TURN || flatness(q, 3) == INFINITY) && depth < MAX_SPLIT_DEPTH) {
        double lq[3][2], lw[3], rq[3][2], rw[3];
        conic_split(q, w, 0.5, lq, lw, rq, rw);
        emit_conic(b, lq, lw, depth + 1);
        emit_conic(b, rq, rw, depth + 1);
        return;
    }
    sw__curves_piece *p = new_piece(b);
    if (!p)
        return;
    p->kind = SW__CURVES_CONIC;
    p->n_cp = 3;
    memcpy(p->cp, q, sizeof(double) * 6);
    p->w = w[1] / sqrt(w[0] * w[2]);
    /* barycentric coordinates of the control triangle as affine functionals */
    double e1[2] = {q[1][0] - q[0][0], q[1][1] - q[0][1]};
    double e2[2] = {q[2][0] - q[0][0], q[2][1] - q[0][1]};
    double det = cross2(e1, e2);
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
    orient(p, mid, dmid);
}

/* ---- integral cubics (Loop & Blinn 2005 §4) ---------------------------------------------------
 */

static void cubic_split(const double q[4][2], double t, double l[4][2], double r[4][2])
{
    double a[3][2], bb[2][2], c[2];
    for (int k = 0; k < 2; ++k) {
        for (int i = 0; i < 3; ++i)
            a[i][k] = (1 - t) * q[i][k] + t * q[i + 1][k];
        for (int i = 0; i < 2; ++i)
            bb[i][k] = (1 - t) * a[i][k] + t * a[i + 1][k];
        c[k] = (1 - t) * bb[0][k] + t * bb[1][k];
        l[0][k] = q[0][k];
        l[1][k] = a[0][k];
        l[2][k] = bb[0][k];
        l[3][k] = c[k];
        r[0][k] = c[k];
        r[1][k] = bb[1][k];
        r[2][k] = a[2][k];
        r[3][k] = q[3][k];
    }
}

/* Sub-curve on [t0, t1] with its end points taken from `e0`, `e1` (bit-identical joins). */
static void cubic_sub(const double q[4][2], double t0, double t1, double out[4][2])
{
    double l[4][2], r[4][2], tmp[4][2];
    if (t0 > 0.0) {
        cubic_split(q, t0, l, r);
        memcpy(tmp, r, sizeof tmp);
    } else {
        memcpy(tmp, q, sizeof tmp);
    }
    double s = t0 < 1.0 ? (t1 - t0) / (1.0 - t0) : 1.0;
    if (s < 1.0) {
        cubic_split(tmp, s, l, r);
        memcpy(out, l, sizeof l);
    } else {
        memcpy(out, tmp, sizeof tmp);
    }
}

typedef struct poly3 {
    double c[4]; /* power basis in t */
} poly3;

static poly3 pmul(poly3 a, poly3 b)
{
    poly3 r = {{0, 0, 0, 0}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; i + j < 4; ++j)
            r.c[i + j] += a.c[i] * b.c[j];
    return r;
}

/* Linear factor (t - root) scaled to unit norm in homogeneous form: (t - r) / sqrt(1 + r^2). */
static poly3 lin(double root)
{
    double s = 1.0 / sqrt(1.0 + root * root);
    poly3 p = {{-root * s, s, 0, 0}};
    return p;
}

static void bernstein3(poly3 p, double out[4])
{
    out[0] = p.c[0];
    out[1] = p.c[0] + p.c[1] / 3.0;
    out[2] = p.c[0] + 2.0 * p.c[1] / 3.0 + p.c[2] / 3.0;
    out[3] = p.c[0] + p.c[1] + p.c[2] + p.c[3];
}

/* Least-squares affine fit phi(q_i) = v_i over the 4 control points (local coordinates);
 * returns the largest residual. */
static double fit_affine(const double q[4][2], const double v[4], double phi[3])
{
    double A[3][3] = {{0}}, rhs[3] = {0};
    for (int i = 0; i < 4; ++i) {
        double r[3] = {q[i][0], q[i][1], 1.0};
        for (int a = 0; a < 3; ++a) {
            rhs[a] += r[a] * v[i];
            for (int c = 0; c < 3; ++c)
                A[a][c] += r[a] * r[c];
        }
    }
    /* Cramer's rule on the 3x3 normal equations */
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                 A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    for (int k = 0; k < 3; ++k) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int a = 0; a < 3; ++a)
            M[a][k] = rhs[a];
        phi[k] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                  M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                  M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) /
                 det;
    }
    double res = 0.0;
    for (int i = 0; i < 4; ++i)
        res = fmax(res, fabs(phi[0] * q[i][0] + phi[1] * q[i][1] + phi[2] - v[i]));
    return res;
}

/* Power-basis coefficients of the cubic and the crosses x12, x13, x23 of c1, c2, c3. */
static void cubic_power(const double q[4][2], double c[4][2], double *x12, double *x13, double *x23)
{
    for (int k = 0; k < 2; ++k) {
        c[0][k] = q[0][k];
        c[1][k] = 3.0 * (q[1][k] - q[0][k]);
        c[2][k] = 3.0 * (q[0][k] - 2.0 * q[1][k] + q[2][k]);
        c[3][k] = q[3][k] - q[0][k] + 3.0 * (q[1][k] - q[2][k]);
    }
    *x12 = cross2(c[1], c[2]);
    *x13 = cross2(c[1], c[3]);
    *x23 = cross2(c[2], c[3]);
}

typedef enum cubic_class { C_SERPENTINE, C_SERP_INF, C_LOOP, C_CUSP, C_QUADRATIC } cubic_class;

/* Classifies an integral cubic in local coordinates (scaled to ~1) and gives its special
 * parameters: inflections (serpentine), double point (loop), cusp. The inflection polynomial is
 * cross(C', C'') = 2 x12 + 6 x13 t + 6 x23 t^2 (the cubic term cancels); the double point solves
 * (C(s) - C(t)) / (s - t) = c1 + c2 (s + t) + c3 (s^2 + s t + t^2) = 0. */
static cubic_class cubic_classify(const double q[4][2], double roots[2], int *n_roots)
{
    double c[4][2], x12, x13, x23;
    cubic_power(q, c, &x12, &x13, &x23);
    double s1 = hypot(c[1][0], c[1][1]), s2 = hypot(c[2][0], c[2][1]), s3 = hypot(c[3][0], c[3][1]);
    double sc = fmax(s1, fmax(s2, s3));
    *n_roots = 0;
    if (s3 <= 1e-12 * sc)
        return C_QUADRATIC;
    if (fabs(x23) <= 1e-15 * sc * sc) { /* else a far root, which lin() keeps well scaled */
        /* c2 parallel to c3: one inflection at infinity besides t = -x12 / (3 x13) */
        roots[0] = -x12 / (3.0 * x13);
        *n_roots = 1;
        return C_SERP_INF;
    }
    double disc = 3.0 * x13 * x13 - 4.0 * x12 * x23;
    double dscale = 3.0 * x13 * x13 + 4.0 * fabs(x12 * x23);
    if (fabs(disc) <= 1e-11 * dscale) {
        roots[0] = -x13 / (2.0 * x23);
        *n_roots = 1;
        return C_CUSP;
    }
    if (disc > 0.0) {
        /* 6 x23 t^2 + 6 x13 t + 2 x12 = 0, stable form */
        double sq = sqrt(36.0 * x13 * x13 - 48.0 * x12 * x23);
        double qq = -0.5 * (6.0 * x13 + copysign(sq, x13));
        roots[0] = qq / (6.0 * x23);
        roots[1] = (2.0 * x12) / qq;
        *n_roots = 2;
        return C_SERPENTINE;
    }
    double sigma = -x13 / x23;
    double v[2] = {c[1][0] + c[2][0] * sigma, c[1][1] + c[2][1] * sigma};
    double pi = sigma * sigma + (v[0] * c[3][0] + v[1] * c[3][1]) / (s3 * s3);
    double d = sigma * sigma - 4.0 * pi;
    double sq = sqrt(fmax(d, 0.0));
    double qq = 0.5 * (sigma + copysign(sq, sigma)); /* stable: the far root, then pi / it */
    roots[0] = qq;
    roots[1] = qq != 0.0 ? pi / qq : 0.0;
    *n_roots = 2;
    return C_LOOP;
}

/* Real roots of d0 + d1 t + d2 t^2 + d3 t^3 (degree found from the coefficients), by bisection
 * between the critical points within the Cauchy bound. */
static int real_roots3(const double d[4], double roots[3])
{
    double mx = fmax(fmax(fabs(d[0]), fabs(d[1])), fmax(fabs(d[2]), fabs(d[3])));
    int n = 3;
    while (n > 0 && fabs(d[n]) <= 1e-14 * mx)
        n--;
    if (n == 0)
        return 0;
    if (n == 1) {
        roots[0] = -d[0] / d[1];
        return 1;
    }
    double bound = 1.0;
    for (int i = 0; i < n; ++i)
        bound = fmax(bound, 1.0 + fabs(d[i] / d[n]));
    double cuts[4] = {-bound, 0, 0, bound};
    int nc = 1;
    if (n == 2) {
        cuts[nc++] = -d[1] / (2 * d[2]);
    } else {
        double a = 3 * d[3], bb = 2 * d[2], c = d[1], disc = bb * bb - 4 * a * c;
        if (disc > 0) {
            double q = -0.5 * (bb + copysign(sqrt(disc), bb));
            double r0 = q / a, r1 = q != 0 ? c / q : r0;
            cuts[nc++] = fmin(r0, r1);
            cuts[nc++] = fmax(r0, r1);
        }
    }
    cuts[nc++] = bound;
    int k = 0;
    for (int i = 0; i + 1 < nc; ++i) {
        double lo = fmax(cuts[i], -bound), hi = fmin(cuts[i + 1], bound);
        double flo = ((d[3] * lo + d[2]) * lo + d[1]) * lo + d[0];
        double fhi = ((d[3] * hi + d[2]) * hi + d[1]) * hi + d[0];
        if (!(lo < hi) || (flo > 0) == (fhi > 0))
            continue;
        for (int it = 0; it < 200 && lo < hi; ++it) {
            double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi)
                break;
            double fm = ((d[3] * mid + d[2]) * mid + d[1]) * mid + d[0];
            if ((fm > 0) == (flo > 0))
                lo = mid;
            else
                hi = mid;
        }
        roots[k++] = 0.5 * (lo + hi);
    }
    return k;
}

/* Whether another branch of the piece's implicit cubic enters its control hull grown by a
 * quarter of its size (which holds the stencil triangles and, but for tiny pieces, the band).
 * The implicit cubic's real points are C(t) for all real t (plus at most an isolated point), so
 * this is C(t) for t outside [0, 1] crossing the grown hull's boundary more than once on either
 * side: once is the curve leaving it past its end. Loop & Blinn 2005 only split loops at their
 * double point, which is not enough: the Hermite pieces of the degree-7 test had a branch a
 * few pixels off inside their hull (a wedge of wrong parity). */
static int other_branch_near(const double q[4][2])
{
    double lo[2] = {q[0][0], q[0][1]}, hi[2] = {lo[0], lo[1]};
    for (int i = 1; i < 4; ++i)
        for (int k = 0; k < 2; ++k) {
            lo[k] = fmin(lo[k], q[i][k]);
            hi[k] = fmax(hi[k], q[i][k]);
        }
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]), g = 0.25 * size;
    /* grown hull: the control points offset by +-g (a square around each) */
    double pts[16][2], h[20][2];
    for (int i = 0; i < 4; ++i)
        for (int s = 0; s < 4; ++s) {
            pts[4 * i + s][0] = q[i][0] + ((s & 1) ? g : -g);
            pts[4 * i + s][1] = q[i][1] + ((s & 2) ? g : -g);
        }
    /* convex hull by gift wrapping (16 points) */
    int start = 0, nh = 0;
    for (int i = 1; i < 16; ++i)
        if (pts[i][0] < pts[start][0] || (pts[i][0] == pts[start][0] && pts[i][1] < pts[start][1]))
            start = i;
    int cur = start;
    do {
        memcpy(h[nh++], pts[cur], sizeof h[0]);
        int nx = (cur + 1) % 16;
        for (int i = 0; i < 16; ++i) {
            double e1[2] = {pts[nx][0] - pts[cur][0], pts[nx][1] - pts[cur][1]};
            double e2[2] = {pts[i][0] - pts[cur][0], pts[i][1] - pts[cur][1]};
            double cr = cross2(e1, e2);
            if (cr < 0 || (cr == 0 && hypot(e2[0], e2[1]) > hypot(e1[0], e1[1])))
                nx = i;
        }
        cur = nx;
    } while (cur != start && nh < 20);
    double c[4][2], x12, x13, x23;
    cubic_power(q, c, &x12, &x13, &x23);
    int after = 0, before = 0;
    for (int e = 0; e < nh; ++e) {
        const double *a = h[e], *bq = h[(e + 1) % nh];
        double n[2] = {bq[1] - a[1], a[0] - bq[0]};
        double d[4] = {n[0] * (c[0][0] - a[0]) + n[1] * (c[0][1] - a[1]),
                       n[0] * c[1][0] + n[1] * c[1][1], n[0] * c[2][0] + n[1] * c[2][1],
                       n[0] * c[3][0] + n[1] * c[3][1]};
        double r[3];
        int nr = real_roots3(d, r);
        for (int k = 0; k < nr; ++k) {
            double t = r[k];
            if (t >= 0.0 && t <= 1.0)
                continue;
            double p[2] = {((c[3][0] * t + c[2][0]) * t + c[1][0]) * t + c[0][0],
                           ((c[3][1] * t + c[2][1]) * t + c[1][1]) * t + c[0][1]};
            double ed[2] = {bq[0] - a[0], bq[1] - a[1]};
            double s =
                ((p[0] - a[0]) * ed[0] + (p[1] - a[1]) * ed[1]) / (ed[0] * ed[0] + ed[1] * ed[1]);
            if (s < 0.0 || s >= 1.0)
                continue;
            if (t > 1.0)
                after++;
            else
                before++;
        }
    }
    return after > 1 || before > 1;
}

/* The class and special parameters of the whole cubic, carried into its pieces (mapped to each
 * piece's parameter) instead of classifying each piece again: a piece ending at a cusp or next
 * to a far root is numerically near the boundary between classes, and its own classification
 * gave k, l, m off by 1e-5 of its size (1.5 px at zoom 1000). */
typedef struct cubic_info {
    cubic_class cls;
    double roots[2];
    int n_roots;
} cubic_info;

static cubic_info info_map(const cubic_info *in, double t0, double t1)
{
    cubic_info o = *in;
    for (int i = 0; i < in->n_roots; ++i)
        o.roots[i] = (in->roots[i] - t0) / (t1 - t0);
    return o;
}

static void emit_cubic_piece(builder *b, const double qm[4][2], const cubic_info *ci);

static void emit_cubic_rec(builder *b, const double q[4][2], int depth, const cubic_info *ci)
{
    if (b->err != SW_OK)
        return;
    if (flatness(q, 4) < 1e-9) {
        emit_line(b, q[0], q[3]);
        return;
    }
    int convex;
    double turn = polygon_turn(q, 4, &convex);
    double e[2] = {q[3][0] - q[0][0], q[3][1] - q[0][1]};
    int closed = hypot(e[0], e[1]) <= 1e-9 * (fabs(q[1][0] - q[0][0]) + fabs(q[1][1] - q[0][1]) +
                                              fabs(q[2][0] - q[0][0]) + fabs(q[2][1] - q[0][1]));
    if ((turn > MAX_TURN || !convex || closed || other_branch_near(q)) && depth < MAX_SPLIT_DEPTH) {
        double l[4][2], r[4][2];
        cubic_split(q, 0.5, l, r);
        cubic_info li = info_map(ci, 0.0, 0.5), ri = info_map(ci, 0.5, 1.0);
        emit_cubic_rec(b, l, depth + 1, &li);
        emit_cubic_rec(b, r, depth + 1, &ri);
        return;
    }
    emit_cubic_piece(b, q, ci);
}

/* An integral cubic in model coordinates: split at its special parameters in (0, 1), then into
 * convex pieces turning at most MAX_TURN. Cusps and self-crossings are recorded as corners. */
static void emit_cubic(builder *b, const double q[4][2])
{
    double lo[2] = {q[0][0], q[0][1]}, hi[2] = {q[0][0], q[0][1]};
    for (int i = 1; i < 4; ++i)
        for (int k = 0; k < 2; ++k) {
            lo[k] = fmin(lo[k], q[i][k]);
            hi[k] = fmax(hi[k], q[i][k]);
        }
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(size > 0.0))
        return;
    double ql[4][2];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 2; ++k)
            ql[i][k] = (q[i][k] - q[0][k]) / size;
    if (flatness(q, 4) < 1e-9) {
        emit_line(b, q[0], q[3]);
        return;
    }
    double roots[2] = {0, 0};
    int nr;
    cubic_class cls = cubic_classify(ql, roots, &nr);
    if (cls == C_QUADRATIC) { /* a degree-elevated parabola: exact as a conic */
        double cq[3][2], w[3] = {1, 1, 1};
        for (int k = 0; k < 2; ++k) {
            cq[0][k] = q[0][k];
            cq[1][k] = 0.25 * (3.0 * q[1][k] - q[0][k]) + 0.25 * (3.0 * q[2][k] - q[3][k]);
            cq[2][k] = q[3][k];
        }
        emit_conic(b, cq, w, 0);
        return;
    }
    double ts[4];
    int nt = 0;
    for (int i = 0; i < nr; ++i)
        if (roots[i] > 1e-9 && roots[i] < 1.0 - 1e-9)
            ts[nt++] = roots[i];
    if (nt == 2 && ts[0] > ts[1]) {
        double t = ts[0];
        ts[0] = ts[1];
        ts[1] = t;
    }
    if (nt == 2 && ts[1] - ts[0] < 1e-9)
        nt = 1;
    double t0 = 0.0;
    double prev_end[2] = {q[0][0], q[0][1]};
    for (int i = 0; i <= nt; ++i) {
        double t1 = i < nt ? ts[i] : 1.0;
        double s[4][2];
        cubic_sub(q, t0, t1, s);
        memcpy(s[0], prev_end, sizeof s[0]);
        if (i == nt)
            memcpy(s[3], q[3], sizeof s[3]);
        memcpy(prev_end, s[3], sizeof prev_end);
        if (i < nt && (cls == C_CUSP || cls == C_LOOP))
            add_corner(b, s[3]);
        cubic_info all = {cls, {roots[0], roots[1]}, nr};
        cubic_info ci = info_map(&all, t0, t1);
        emit_cubic_rec(b, s, 0, &ci);
        t0 = t1;
    }
    /* a loop's crossing is a corner of the outline even where it is not a split point */
    if (cls == C_LOOP && nr == 2) {
        double t = roots[0], mt = 1 - t;
        if (t > -1e-9 && t < 1 + 1e-9 && roots[1] > -1e-9 && roots[1] < 1 + 1e-9) {
            double pt[2];
            for (int k = 0; k < 2; ++k)
                pt[k] = mt * mt * mt * q[0][k] + 3 * mt * mt * t * q[1][k] +
                        3 * mt * t * t * q[2][k] + t * t * t * q[3][k];
            if (nt == 0)
                add_corner(b, pt);
        }
    }
}

/* One convex piece of an integral cubic: k, l, m as in Loop & Blinn 2005 §4 — serpentine
 * k = L M, l = L^3, m = M^3 (L, M vanish at the inflections); loop k = L M, l = L^2 M,
 * m = L M^2 (at the double point's parameters); cusp k = L^2, l = m = L^3; inflection at
 * infinity k = L, l = L^3, m = 1. Rather than their tables, the Bernstein coefficients of these
 * polynomials are fitted by affine functionals of the plane; the residual proves the class. */
static void emit_cubic_piece(builder *b, const double qm[4][2], const cubic_info *ci)
{
    double lo[2] = {qm[0][0], qm[0][1]}, hi[2] = {qm[0][0], qm[0][1]};
    for (int i = 1; i < 4; ++i)
        for (int k = 0; k < 2; ++k) {
            lo[k] = fmin(lo[k], qm[i][k]);
            hi[k] = fmax(hi[k], qm[i][k]);
        }
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    double q[4][2];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 2; ++k)
            q[i][k] = (qm[i][k] - qm[0][k]) / size;
    const double *roots = ci->roots;
    cubic_class cls = ci->cls;
    poly3 k, l, m, one = {{1, 0, 0, 0}};
    switch (cls) {
    case C_QUADRATIC: {
        double cq[3][2], w[3] = {1, 1, 1};
        for (int c = 0; c < 2; ++c) {
            cq[0][c] = qm[0][c];
            cq[1][c] = 0.25 * (3.0 * qm[1][c] - qm[0][c]) + 0.25 * (3.0 * qm[2][c] - qm[3][c]);
            cq[2][c] = qm[3][c];
        }
        emit_conic(b, cq, w, MAX_SPLIT_DEPTH);
        return;
    }
    case C_SERP_INF: {
        poly3 L = lin(roots[0]);
        k = L;
        l = pmul(L, pmul(L, L));
        m = one;
        break;
    }
    case C_CUSP: {
        poly3 L = lin(roots[0]);
        k = pmul(L, L);
        l = m = pmul(k, L);
        break;
    }
    case C_SERPENTINE: {
        poly3 L = lin(roots[0]), M = lin(roots[1]);
        k = pmul(L, M);
        l = pmul(L, pmul(L, L));
        m = pmul(M, pmul(M, M));
        break;
    }
    default: {
        poly3 L = lin(roots[0]), M = lin(roots[1]);
        k = pmul(L, M);
        l = pmul(L, k);
        m = pmul(M, k);
        break;
    }
    }
    double bk[4], bl[4], bm[4], fk[3], fl[3], fm[3];
    bernstein3(k, bk);
    bernstein3(l, bl);
    bernstein3(m, bm);
    /* normalize: k by a, l and m by a^(3/2), which keeps k^3 = l m */
    double mk = 0, ml = 0, mm = 0;
    for (int i = 0; i < 4; ++i) {
        mk = fmax(mk, fabs(bk[i]));
        ml = fmax(ml, fabs(bl[i]));
        mm = fmax(mm, fabs(bm[i]));
    }
    double a = mk > 0 ? 1.0 / mk : 1.0;
    double a32 = a * sqrt(a);
    /* l m = a^3 k^3 needs l scaled by x and m by a^3 / x: balance their sizes */
    double xl = ml > 0 && mm > 0 && cls != C_CUSP ? sqrt(a * a * a * mm / ml) : a32;
    double xm = a * a * a / xl;
    for (int i = 0; i < 4; ++i) {
        bk[i] *= a;
        bl[i] *= xl;
        bm[i] *= xm;
    }
    double res = fit_affine(q, bk, fk);
    res = fmax(res, fit_affine(q, bl, fl));
    res = fmax(res, fit_affine(q, bm, fm));
    if (!(res <= 1e-4)) {
        /* not representable (numerically degenerate): fall back to the chord polygon's conic
         * split would be wrong; report instead */
        b->err = sw__fail(b->status, SW_ERR_INVALID_GEOMETRY,
                          "curves: cubic implicitization residual %g (class %d)", res, (int)cls);
        return;
    }
    sw__curves_piece *p = new_piece(b);
    if (!p)
        return;
    p->kind = SW__CURVES_CUBIC;
    if (cls == C_CUSP) {
        /* k = L^2, l = m = L^3: F = k^3 - l^2 vanishes on both branches, L < 0 and L > 0, which
         * leave the cusp tangent to each other. A piece ending at the cusp then has the other
         * branch within a pixel all along the thin spike, where F / |grad F| measures the
         * distance to the wrong branch or to neither (cusp x1, x10: up to 170/255 off).
         * F = l + branch k^(3/2) with branch = -sign(L) on the piece vanishes on this branch
         * only (k >= 0 on the curve; beyond k = 0, past the cusp, it is l, the cusp tangent). */
        double Lmid = 0.5 - roots[0];
        p->kind = SW__CURVES_CUSP;
        p->branch = Lmid < 0.0 ? 1.0 : -1.0;
    }
    p->n_cp = 4;
    memcpy(p->cp, qm, sizeof p->cp);
    const double *f[3] = {fk, fl, fm};
    for (int j = 0; j < 3; ++j) { /* local (x - q0) / size back to model coordinates */
        p->klm[j][0] = f[j][0] / size;
        p->klm[j][1] = f[j][1] / size;
        p->klm[j][2] = f[j][2] - (f[j][0] * qm[0][0] + f[j][1] * qm[0][1]) / size;
    }
    double mid[2], dmid[2];
    for (int c = 0; c < 2; ++c) {
        mid[c] = 0.125 * (qm[0][c] + 3 * qm[1][c] + 3 * qm[2][c] + qm[3][c]);
        dmid[c] = 0.75 * (qm[2][c] + qm[3][c] - qm[0][c] - qm[1][c]);
    }
    orient(p, mid, dmid);
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
    emit_cubic(b, H);
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
        emit_line(b, q[0], q[1]);
    } else if (p == 2) {
        double w[3];
        for (int i = 0; i < 3; ++i) {
            w[i] = h[3 * i + 2];
            q[i][0] = h[3 * i] / w[i];
            q[i][1] = h[3 * i + 1] / w[i];
        }
        emit_conic(b, (const double(*)[2])q, w, 0);
    } else if (p == 3 && !rational) {
        for (int i = 0; i < 4; ++i) {
            q[i][0] = h[3 * i] / h[3 * i + 2];
            q[i][1] = h[3 * i + 1] / h[3 * i + 2];
        }
        emit_cubic(b, (const double(*)[2])q);
    } else {
        emit_approx(b, h, p, 0);
    }
}

/* Bézier extraction of a clamped curve by knot insertion (scenegraph/knot_insert.c). */
static void emit_curve(builder *b, const sw_sg_curve *c)
{
    const int p = c->degree;
    int32_t n = c->n;
    size_t cap_n = (size_t)n + (size_t)(n + p) * (size_t)p;
    double *knots = sw__malloc(sizeof(double) * (cap_n + (size_t)p + 1));
    double *cpw = sw__malloc(sizeof(double) * 3 * cap_n);
    double *k2 = sw__malloc(sizeof(double) * (cap_n + (size_t)p + 1));
    double *c2 = sw__malloc(sizeof(double) * 3 * cap_n);
    if (!knots || !cpw || !k2 || !c2) {
        b->err = sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
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
        emit_bezier(b, cpw + 3 * (size_t)s, p);
done:
    sw__free(knots);
    sw__free(cpw);
    sw__free(k2);
    sw__free(c2);
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
                add_corner(&b, pc->cp[0]);
        }
        cur += s->src_loop_n[L];
    }
    if (b.err == SW_OK) {
        /* Which side is inside, by parity just left of each piece's mid point: orient() took
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

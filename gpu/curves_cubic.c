/* SPDX-License-Identifier: MIT */
/* Integral cubics as exact curve pieces (Loop & Blinn 2005 §4; Santana §3.2 for the conics): the
 * serpentine, loop and cusp classification, the split at inflections and double points, the
 * implicit form k^3 - l m as affine functionals, and the check that no other branch of the
 * implicit cubic enters a piece's hull. Split out of curves_split.c, which builds the shapes. */
#include "curves_builder.h"
#include "sw_status_util.h"

#include <math.h>
#include <string.h>

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
    *x12 = sw__cb_cross2(c[1], c[2]);
    *x13 = sw__cb_cross2(c[1], c[3]);
    *x23 = sw__cb_cross2(c[2], c[3]);
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
            double cr = sw__cb_cross2(e1, e2);
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
    if (sw__cb_flatness(q, 4) < 1e-9) {
        sw__cb_emit_line(b, q[0], q[3]);
        return;
    }
    int convex;
    double turn = sw__cb_polygon_turn(q, 4, &convex);
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
void sw__cb_emit_cubic(builder *b, const double q[4][2])
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
    if (sw__cb_flatness(q, 4) < 1e-9) {
        sw__cb_emit_line(b, q[0], q[3]);
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
        sw__cb_emit_conic(b, cq, w, 0);
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
            sw__cb_add_corner(b, s[3]);
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
                sw__cb_add_corner(b, pt);
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
        sw__cb_emit_conic(b, cq, w, MAX_SPLIT_DEPTH);
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
    sw__curves_piece *p = sw__cb_new_piece(b);
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
    sw__cb_orient(p, mid, dmid);
}

/* SPDX-License-Identifier: MIT */
/* Sampling bounds for rational Bézier patches: the Filip et al. 1986 grid density (Guthe et al.
 * 2005 §5.2), the screen-to-object tolerance (§7) and the trim-texture resolution (§5.3).
 *
 * Derivative bounds (why they hold). Let the patch be S = H / W with the homogeneous numerator
 * H(s,t) = sum w_ij P_ij B_i^p(s) B_j^q(t) and the weight W = sum w_ij B_i^p B_j^q, all w_ij > 0.
 * Derivatives of S do not change when every P_ij is translated, so take a centre c (the control
 * net's box centre) and H_c = sum Q_ij B_i B_j with Q_ij = w_ij (P_ij - c) = W (S - c). Then:
 *  - a partial derivative of a Bernstein polynomial is a Bernstein polynomial of the forward
 *    differences, so with the partition of unity |d_s H_c| <= p max|D_s Q| =: A_s,
 *    |d_ss H_c| <= p(p-1) max|D_s^2 Q| =: A_ss, |d_st H_c| <= p q max|D_s D_t Q| =: A_st, and the
 *    same for W with B_s, B_ss, B_st (max |differences of w|);
 *  - W >= w_min = min w_ij, and |S - c| <= R = max |P_ij - c| (convex hull; weights positive);
 *  - differentiating H_c = W (S - c):
 *      S_s  = (d_s H_c - W_s (S - c)) / W
 *      S_ss = (d_ss H_c - 2 W_s S_s - W_ss (S - c)) / W
 *      S_st = (d_st H_c - W_s S_t - W_t S_s - W_st (S - c)) / W
 *    hence
 *      |S_s|  <= G_s = (A_s + B_s R) / w_min
 *      |S_ss| <= (A_ss + 2 B_s G_s + B_ss R) / w_min
 *      |S_st| <= (A_st + B_s G_t + B_t G_s + B_st R) / w_min
 *    For a polynomial patch (equal weights) the B terms vanish and the bounds are the classical
 *    p(p-1) max|D^2 P| etc.
 *
 * A second bound, used for degrees <= 7 (taking the smaller of the two, both being rigorous),
 * follows §5.1 literally but for surfaces: with N_s = H_s W - H W_s (so S_s = N_s / W^2) the
 * second derivatives are S_ss = (d_s N_s W - 2 N_s W_s) / W^3, S_st = (d_s N_t W - 2 N_t W_s) /
 * W^3, S_tt likewise; numerators and W^3 are multiplied out in Bernstein form, and |S_xy| <= max
 * |numerator coefficient| / min (W^3 coefficient) (convex hull; W^3's coefficients are positive).
 * The first derivatives likewise: |S_s| <= max |N_s coefficient| / min (W^2 coefficient).
 * Its numerators cancel exactly where the first bound's triangle inequalities cannot: a cylinder's
 * S_st = 0 gets a zero bound, so its straight direction needs one segment.
 *
 * Where the paper is loose: (a) §5.1 bounds |C''| by max|P_i| / min w_i of the rational
 * derivative's numerator and denominator in absolute coordinates; that numerator is not
 * translation-invariant, so for a patch far from the origin (CAD parts placed at 10^3 mm) the bound
 * grows with the distance to the origin. Centring at c fixes this. (b) §5.2 needs sup|S_uv| but
 * only explains how to bound the iso-curves' second derivatives; the mixed term above is ours.
 * (c) §5.3 multiplies the local-parameter derivative by (u1 - u0) again; we keep the units straight
 * (texels per parameter unit = local derivative / (patch length * eps)). (d) §7 maps ε_img to
 * object space with "the distance of the viewer to the bounding box" only; off the view axis the
 * perspective projection magnifies by up to sqrt(1 + tan_x^2 + tan_y^2) more, which we include,
 * and we use the box's depth along the view axis (<= its distance), which is the stricter choice.
 *
 * Filip's bound (Guthe §5.2): on a cell of size (ds, dt) the two triangles deviate from the patch
 * by at most (ds^2 M_ss + 2 ds dt M_st + dt^2 M_tt) / 8 <= (ds^2 (M_ss + M_st) + dt^2 (M_tt +
 * M_st)) / 8 (from 2ab <= a^2 + b^2), so each direction gets eps/2: ds <= sqrt(4 eps / (M_ss +
 * M_st)).
 */
#include "sw_lod_sampling.h"
#include "sw_hooks.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* Norm of the components of v selected by mask (bit k = component k): the bounds of a linear
 * image L(S) of the patch (a rational patch with control points L P_ij and the same weights) are
 * the bounds with the norm taken over L's components, which is how the screen-space bounds split
 * an error into its lateral and depth parts. */
static double norm_mask(const double v[3], unsigned mask)
{
    double s = 0.0;
    for (int k = 0; k < 3; ++k)
        if (mask & (1u << k))
            s += v[k] * v[k];
    return sqrt(s);
}

/* Differences of a control net, 4 doubles per point (Q_xyz, w). */
typedef struct diff_max {
    double q, w; /* max norm of the xyz part, max |w part| */
} diff_max;

static void diff_update(diff_max *m, const double d[4], unsigned mask)
{
    double qn = norm_mask(d, mask);
    if (qn > m->q)
        m->q = qn;
    if (fabs(d[3]) > m->w)
        m->w = fabs(d[3]);
}

/* Centred homogeneous point Q_ij = (w (P - c), w). */
static void centred(const double *cpw, int32_t nu, int32_t i, int32_t j, const double c[3],
                    double out[4])
{
    const double *p = cpw + ((size_t)j * (size_t)nu + (size_t)i) * 4;
    for (int k = 0; k < 3; ++k)
        out[k] = p[k] - p[3] * c[k];
    out[3] = p[3];
}

/* max over the net of the norm of a difference given by stencil offsets and coefficients, for
 * each mask (the differences are the masks' common work: one pass). */
static void net_diff(const double *cpw, int32_t nu, int32_t nv, const double c[3], int di, int dj,
                     int order_s, int order_t, const unsigned *masks, int n_masks, diff_max *m)
{
    for (int k = 0; k < n_masks; ++k)
        m[k] = (diff_max){0.0, 0.0};
    for (int32_t j = 0; j + dj < nv; ++j) {
        for (int32_t i = 0; i + di < nu; ++i) {
            double a[4], b[4], e[4], d[4];
            if (order_s == 2 || order_t == 2) { /* second difference along one direction */
                int si = order_s == 2, sj = order_t == 2;
                centred(cpw, nu, i, j, c, a);
                centred(cpw, nu, i + si, j + sj, c, b);
                centred(cpw, nu, i + 2 * si, j + 2 * sj, c, e);
                for (int k = 0; k < 4; ++k)
                    d[k] = e[k] - 2.0 * b[k] + a[k];
            } else if (order_s == 1 && order_t == 1) { /* mixed difference */
                double f[4];
                centred(cpw, nu, i, j, c, a);
                centred(cpw, nu, i + 1, j, c, b);
                centred(cpw, nu, i, j + 1, c, e);
                centred(cpw, nu, i + 1, j + 1, c, f);
                for (int k = 0; k < 4; ++k)
                    d[k] = f[k] - b[k] - e[k] + a[k];
            } else { /* first difference */
                centred(cpw, nu, i, j, c, a);
                centred(cpw, nu, i + di, j + dj, c, b);
                for (int k = 0; k < 4; ++k)
                    d[k] = b[k] - a[k];
            }
            for (int k = 0; k < n_masks; ++k)
                diff_update(&m[k], d, masks[k]);
        }
    }
}

/* The net's box centre c, its radius about c per mask and its smallest weight. */
static void net_centre_radius_wmin(const double *cpw, int32_t count, const unsigned *masks,
                                   int n_masks, double c[3], double *radius, double *wmin)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    *wmin = INFINITY;
    for (int32_t k = 0; k < count; ++k) {
        const double *p = cpw + (size_t)k * 4;
        for (int a = 0; a < 3; ++a) {
            double x = p[a] / p[3];
            lo[a] = fmin(lo[a], x);
            hi[a] = fmax(hi[a], x);
        }
        *wmin = fmin(*wmin, p[3]);
    }
    for (int a = 0; a < 3; ++a)
        c[a] = 0.5 * (lo[a] + hi[a]);
    for (int m = 0; m < n_masks; ++m)
        radius[m] = 0.0;
    for (int32_t k = 0; k < count; ++k) {
        const double *p = cpw + (size_t)k * 4;
        double d[3] = {p[0] / p[3] - c[0], p[1] / p[3] - c[1], p[2] / p[3] - c[2]};
        for (int m = 0; m < n_masks; ++m)
            radius[m] = fmax(radius[m], norm_mask(d, masks[m]));
    }
}

/* ---- the Bernstein-product bound ---------------------------------------------------------- */
enum { PRODUCT_MAX_DEGREE = 7, BMAX = 3 * PRODUCT_MAX_DEGREE };

/* A tensor-product polynomial in scaled Bernstein form: coefficient (i, j) is the Bernstein
 * coefficient times C(m, i) C(n, j), so that products are plain convolutions and derivatives need
 * no division; (m+1) x (n+1) coefficients of `dim` doubles, s fastest. */
typedef struct bpoly {
    int32_t m, n, dim;
    double *c;
} bpoly;

typedef struct arena {
    double *mem;
    size_t used, cap;
} arena;

enum { ARENA_STACK = 17 * 10 * 10 * 3 }; /* bicubic patches need no allocation */

static bpoly bp_new(arena *a, int32_t m, int32_t n, int32_t dim)
{
    bpoly p = {m, n, dim, a->mem + a->used};
    size_t need = (size_t)(m + 1) * (size_t)(n + 1) * (size_t)dim;
    a->used += need;
    memset(p.c, 0, need * sizeof *p.c);
    return p;
}

static double *bp_at(const bpoly *p, int32_t i, int32_t j)
{
    return p->c + ((size_t)j * (size_t)(p->m + 1) + (size_t)i) * (size_t)p->dim;
}

/* Partial derivative along s (dir 0) or t (dir 1); of a constant direction: zero of degree 0.
 * Scaled form: d_i = (i + 1) c_{i+1} - (deg - i) c_i. */
static bpoly bp_deriv(arena *a, const bpoly *p, int dir)
{
    int32_t deg = dir ? p->n : p->m;
    int32_t m = dir ? p->m : (deg > 0 ? deg - 1 : 0), n = dir ? (deg > 0 ? deg - 1 : 0) : p->n;
    bpoly d = bp_new(a, m, n, p->dim);
    if (deg == 0)
        return d;
    for (int32_t j = 0; j <= n; ++j)
        for (int32_t i = 0; i <= m; ++i) {
            const double *lo = bp_at(p, i, j), *hi = bp_at(p, i + !dir, j + dir);
            double *o = bp_at(&d, i, j);
            double kh = (double)((dir ? j : i) + 1), kl = (double)(deg - (dir ? j : i));
            for (int32_t k = 0; k < p->dim; ++k)
                o[k] = kh * hi[k] - kl * lo[k];
        }
    return d;
}

/* Product of a scalar polynomial `w` and a polynomial `p`, times `scale`, added to `out` (which
 * must have degree (w.m + p.m, w.n + p.n) and p's dim). */
static void bp_mul_add(const bpoly *w, const bpoly *p, double scale, bpoly *out)
{
    for (int32_t j1 = 0; j1 <= w->n; ++j1)
        for (int32_t i1 = 0; i1 <= w->m; ++i1) {
            double wc = *bp_at(w, i1, j1) * scale;
            for (int32_t j2 = 0; j2 <= p->n; ++j2) {
                const double *pc = bp_at(p, 0, j2);
                double *o = bp_at(out, i1, j1 + j2);
                size_t len = (size_t)(p->m + 1) * (size_t)p->dim;
                for (size_t k = 0; k < len; ++k)
                    o[k] += wc * pc[k];
            }
        }
}

/* x * w - y * v (x, y vector; w, v scalar), both products of the same degree. */
static bpoly bp_cross_diff(arena *a, const bpoly *x, const bpoly *w, double ky, const bpoly *y,
                           const bpoly *v)
{
    bpoly r = bp_new(a, x->m + w->m, x->n + w->n, x->dim);
    bp_mul_add(w, x, 1.0, &r);
    bp_mul_add(v, y, -ky, &r);
    return r;
}

static void binomials(int32_t n, double *b)
{
    b[0] = 1.0;
    for (int32_t k = 1; k <= n; ++k)
        b[k] = b[k - 1] * (double)(n - k + 1) / (double)k;
}

/* Per mask, the largest norm (components in the mask) of the Bernstein coefficients, in one pass
 * over them. The comparison skips a NaN norm as fmax(out, NaN) does, and out never becomes NaN,
 * so the result is fmax's. */
static void bp_max_norms(const bpoly *p, const unsigned *masks, int n_masks, double *out)
{
    double bm[BMAX + 1], bn[BMAX + 1];
    binomials(p->m, bm);
    binomials(p->n, bn);
    for (int k = 0; k < n_masks; ++k)
        out[k] = 0.0;
    for (int32_t j = 0; j <= p->n; ++j)
        for (int32_t i = 0; i <= p->m; ++i) {
            const double *c = bp_at(p, i, j), d = bm[i] * bn[j];
            for (int k = 0; k < n_masks; ++k) {
                const double x = norm_mask(c, masks[k]) / d;
                out[k] = x > out[k] ? x : out[k];
            }
        }
}

/* Smallest Bernstein coefficient of a scalar polynomial. */
static double bp_min(const bpoly *p)
{
    double bm[BMAX + 1], bn[BMAX + 1], m = INFINITY;
    binomials(p->m, bm);
    binomials(p->n, bn);
    for (int32_t j = 0; j <= p->n; ++j)
        for (int32_t i = 0; i <= p->m; ++i)
            m = fmin(m, *bp_at(p, i, j) / (bm[i] * bn[j]));
    return m;
}

/* The Bernstein-product bounds (see the top of the file), one set per mask (at most 3:
 * bounds_masked calls it with no more); 0 when out of memory or too high a degree (the caller keeps
 * the other bound then). second = 0: the first derivatives only (the second-derivative products,
 * of degree (3p, 3q), are most of the cost), d2 left infinite. */
static int product_bounds(int32_t p, int32_t q, const double *cpw, const double c[3],
                          const unsigned *masks, int n_masks, int second, sw_lod_patch_bounds *out)
{
    if (p > PRODUCT_MAX_DEGREE || q > PRODUCT_MAX_DEGREE)
        return 0;
    arena a;
    double stack_mem[ARENA_STACK];
    /* 17 polynomials, none of degree above (3p, 3q), at most 3 doubles per coefficient */
    a.cap = 17 * (size_t)(3 * p + 1) * (size_t)(3 * q + 1) * 3;
    a.used = 0;
    a.mem = a.cap <= ARENA_STACK ? stack_mem : sw__malloc(a.cap * sizeof *a.mem);
    if (!a.mem)
        return 0;
    double bp[PRODUCT_MAX_DEGREE + 1], bq[PRODUCT_MAX_DEGREE + 1];
    binomials(p, bp);
    binomials(q, bq);
    bpoly h = bp_new(&a, p, q, 3), w = bp_new(&a, p, q, 1);
    for (int32_t j = 0; j <= q; ++j)
        for (int32_t i = 0; i <= p; ++i) {
            const double *src = cpw + ((size_t)j * (size_t)(p + 1) + (size_t)i) * 4;
            double sc = bp[i] * bq[j];
            for (int k = 0; k < 3; ++k)
                bp_at(&h, i, j)[k] = (src[k] - src[3] * c[k]) * sc;
            *bp_at(&w, i, j) = src[3] * sc;
        }
    bpoly hs = bp_deriv(&a, &h, 0), ht = bp_deriv(&a, &h, 1);
    bpoly ws = bp_deriv(&a, &w, 0), wt = bp_deriv(&a, &w, 1);
    bpoly ns = bp_cross_diff(&a, &hs, &w, 1.0, &h, &ws);
    bpoly nt = bp_cross_diff(&a, &ht, &w, 1.0, &h, &wt);
    bpoly w2 = bp_new(&a, 2 * p, 2 * q, 1);
    bp_mul_add(&w, &w, 1.0, &w2);
    if (!second) {
        double m2 = bp_min(&w2), n_s[3], n_t[3];
        bp_max_norms(&ns, masks, n_masks, n_s);
        bp_max_norms(&nt, masks, n_masks, n_t);
        for (int k = 0; k < n_masks; ++k) {
            out[k].d1[0] = n_s[k] / m2;
            out[k].d1[1] = n_t[k] / m2;
            out[k].d2[0] = out[k].d2[1] = out[k].d2[2] = INFINITY;
        }
        if (a.mem != stack_mem)
            sw__free(a.mem);
        return 1;
    }
    bpoly w3 = bp_new(&a, 3 * p, 3 * q, 1);
    bp_mul_add(&w2, &w, 1.0, &w3);
    bpoly nss = bp_deriv(&a, &ns, 0), nts = bp_deriv(&a, &nt, 0), ntt = bp_deriv(&a, &nt, 1);
    bpoly kss = bp_cross_diff(&a, &nss, &w, 2.0, &ns, &ws);
    bpoly kst = bp_cross_diff(&a, &nts, &w, 2.0, &nt, &ws);
    bpoly ktt = bp_cross_diff(&a, &ntt, &w, 2.0, &nt, &wt);
    double m2 = bp_min(&w2), m3 = bp_min(&w3);
    double n_s[3], n_t[3], n_ss[3], n_st[3], n_tt[3];
    bp_max_norms(&ns, masks, n_masks, n_s);
    bp_max_norms(&nt, masks, n_masks, n_t);
    bp_max_norms(&kss, masks, n_masks, n_ss);
    bp_max_norms(&kst, masks, n_masks, n_st);
    bp_max_norms(&ktt, masks, n_masks, n_tt);
    for (int k = 0; k < n_masks; ++k) {
        out[k].d1[0] = n_s[k] / m2;
        out[k].d1[1] = n_t[k] / m2;
        out[k].d2[0] = n_ss[k] / m3;
        out[k].d2[1] = n_st[k] / m3;
        out[k].d2[2] = n_tt[k] / m3;
    }
    if (a.mem != stack_mem)
        sw__free(a.mem);
    return 1;
}

/* The difference bounds of one linear image (see the top of the file) from its net's radius r
 * about the centre, the smallest weight and the largest differences. */
static void difference_bounds(int32_t deg_u, int32_t deg_v, double r, double wmin, diff_max ds,
                              diff_max dt, diff_max dst, diff_max dss, diff_max dtt,
                              sw_lod_patch_bounds *out)
{
    const double p = deg_u, q = deg_v;

    double a_s = p * ds.q, b_s = p * ds.w, a_t = q * dt.q, b_t = q * dt.w;
    double g_s = (a_s + b_s * r) / wmin, g_t = (a_t + b_t * r) / wmin;
    double a_ss = p * (p - 1.0) * dss.q, b_ss = p * (p - 1.0) * dss.w;
    double a_tt = q * (q - 1.0) * dtt.q, b_tt = q * (q - 1.0) * dtt.w;
    double a_st = p * q * dst.q, b_st = p * q * dst.w;

    out->d1[0] = g_s;
    out->d1[1] = g_t;
    out->d2[0] = (a_ss + 2.0 * b_s * g_s + b_ss * r) / wmin;
    out->d2[1] = (a_st + b_s * g_t + b_t * g_s + b_st * r) / wmin;
    out->d2[2] = (a_tt + 2.0 * b_t * g_t + b_tt * r) / wmin;
}

/* The difference bounds for each mask; c: the centre the product bounds take. */
static void difference_bounds_masked(int32_t deg_u, int32_t deg_v, const double *cpw,
                                     const unsigned *masks, int n_masks, double c[3],
                                     sw_lod_patch_bounds *out)
{
    const int32_t nu = deg_u + 1, nv = deg_v + 1;
    double r[3], wmin;
    diff_max ds[3], dt[3], dst[3], dss[3] = {{0}}, dtt[3] = {{0}};
    net_centre_radius_wmin(cpw, nu * nv, masks, n_masks, c, r, &wmin);
    net_diff(cpw, nu, nv, c, 1, 0, 1, 0, masks, n_masks, ds);
    net_diff(cpw, nu, nv, c, 0, 1, 0, 1, masks, n_masks, dt);
    net_diff(cpw, nu, nv, c, 1, 1, 1, 1, masks, n_masks, dst);
    if (deg_u >= 2)
        net_diff(cpw, nu, nv, c, 2, 0, 2, 0, masks, n_masks, dss);
    if (deg_v >= 2)
        net_diff(cpw, nu, nv, c, 0, 2, 0, 2, masks, n_masks, dtt);
    for (int k = 0; k < n_masks; ++k)
        difference_bounds(deg_u, deg_v, r[k], wmin, ds[k], dt[k], dst[k], dss[k], dtt[k], &out[k]);
}

/* out (difference bounds) tightened by the product bounds, for each mask (at most 3); second:
 * as product_bounds. */
static void tighten_by_products(int32_t deg_u, int32_t deg_v, const double *cpw, const double c[3],
                                const unsigned *masks, int n_masks, int second,
                                sw_lod_patch_bounds *out)
{
    sw_lod_patch_bounds pb[3];
    if (n_masks <= 3 && product_bounds(deg_u, deg_v, cpw, c, masks, n_masks, second, pb)) {
        for (int m = 0; m < n_masks; ++m) {
            for (int k = 0; k < 2; ++k)
                out[m].d1[k] = fmin(out[m].d1[k], pb[m].d1[k]);
            for (int k = 0; k < 3; ++k)
                out[m].d2[k] = fmin(out[m].d2[k], pb[m].d2[k]);
        }
    }
}

/* Both bounds, the smaller kept, for each mask (at most 3). */
static void bounds_masked(int32_t deg_u, int32_t deg_v, const double *cpw, const unsigned *masks,
                          int n_masks, sw_lod_patch_bounds *out)
{
    double c[3];
    difference_bounds_masked(deg_u, deg_v, cpw, masks, n_masks, c, out);
    tighten_by_products(deg_u, deg_v, cpw, c, masks, n_masks, 1, out);
}

void sw_lod_rational_bezier_bounds(int32_t deg_u, int32_t deg_v, const double *cpw,
                                   sw_lod_patch_bounds *out)
{
    static const unsigned all = 7u;
    bounds_masked(deg_u, deg_v, cpw, &all, 1, out);
}

int32_t sw_lod_filip_segments(double m_dir, double m_mixed, double len, double eps,
                              int32_t max_segments)
{
    if (max_segments < 1)
        max_segments = 1;
    double m = m_dir + m_mixed;
    if (!(eps > 0.0) || !isfinite(m))
        return max_segments;
    double n = ceil(len * sqrt(m / (4.0 * eps)));
    if (!(n >= 1.0))
        return 1;
    return n >= (double)max_segments ? max_segments : (int32_t)n;
}

double sw_lod_filip_error(const sw_lod_patch_bounds *b, double ds, double dt)
{
    return (ds * ds * b->d2[0] + 2.0 * ds * dt * b->d2[1] + dt * dt * b->d2[2]) / 8.0;
}

double sw_lod_object_tolerance(double eps_px, double depth, double focal_px, double tan_x,
                               double tan_y)
{
    return eps_px * depth / (focal_px * sqrt(1.0 + tan_x * tan_x + tan_y * tan_y));
}

double sw_lod_trim_texels(double span, double d1, double patch_len, double eps)
{
    if (!(eps > 0.0) || !(patch_len > 0.0))
        return INFINITY;
    double t = span * d1 / (patch_len * eps);
    return t >= 1.0 ? t : 1.0;
}

/* ---- screen-space grid segments ----------------------------------------------------------------
 * Why the bound below holds. Write points in the camera frame (right, up, fwd) relative to the
 * eye, x = (x_lat, x_f). A drawn point x = T(b) of a grid triangle (barycentric b over surface
 * vertices) and the surface point y = S(s, t) at the same parameters b interpolates project to
 * f x_lat / x_f and f y_lat / y_f, and exactly
 *     pi(x) - pi(y) = (f / x_f) (e_lat - e_f p_y),   e = x - y,  p_y = y_lat / y_f,
 * so |pi(x) - pi(y)| <= (f / z_min) (|e_lat| + P |e_f|) with z_min <= x_f and P >= |p_y|. x lies
 * in the convex hull of the surface over the cell, hence of the control points of any sub-patches
 * covering the cell: z_min and P are taken over those control points (P is also capped by the
 * frustum's corner tangent plus 2 eps/f: only visible x matter, and there |p_x - p_y| <= eps/f).
 * e_lat and e_f are the grid errors of the linear images S_lat and S_f of the patch, each bounded
 * by Filip's bound with its own second-derivative bounds (the bounds above, normed over those
 * components). So a cell of size (ds, dt) is within eps_px when
 *     A ds^2 + 2 B ds dt + C dt^2 <= 8 eps_px z_min / f,   A = M_ss^lat + P M_ss^f, B, C alike.
 * This replaces the isotropic |e| sqrt(1 + tan^2) (the Jacobian's norm) by the split above, which
 * is never larger (Cauchy-Schwarz), and is much smaller where the error lies along the view.
 *
 * Sub-patches: the range [s0,s1] x [t0,t1] is cut into K x K sub-patches (for bounding only);
 * a cell of a grid with n_u >= 1 segments touches at most m_u = min(K, ceil(K / n_u) + 1)
 * consecutive sub-columns (and m_v sub-rows), so the condition above with maxima (of M, P) and
 * minima (of z) over every m_u x m_v window of sub-patches covers every cell. The whole range
 * (K = 1) is checked too; a grid passes when either analysis proves it.
 * Among the allowed segment counts the pair with the fewest cells is taken (for a single window
 * the optimum has A ds^2 = C dt^2, not the even split of eps per direction of §5.2). */
enum { SUB_MAX = 4, SMALL_NET = 64 };

typedef struct sub_info {
    double ml[3], mf[3]; /* second-derivative bounds (range parameters): lateral, depth */
    double zmin, pmax;
} sub_info;

/* The part [a, b] of a Bézier curve of degree p given by p+1 points of 4 doubles, `stride`
 * doubles apart, in place (two de Casteljau splits). */
static void curve_part(double *pts, int32_t p, size_t stride, double a, double b)
{
    if (b < 1.0)
        for (int32_t r = 1; r <= p; ++r)
            for (int32_t i = p; i >= r; --i)
                for (int k = 0; k < 4; ++k)
                    pts[i * stride + k] =
                        (1.0 - b) * pts[(i - 1) * stride + k] + b * pts[i * stride + k];
    double tau = b > 0.0 ? a / b : 0.0;
    if (tau > 0.0)
        for (int32_t r = 1; r <= p; ++r)
            for (int32_t i = 0; i <= p - r; ++i)
                for (int k = 0; k < 4; ++k)
                    pts[i * stride + k] =
                        (1.0 - tau) * pts[i * stride + k] + tau * pts[(i + 1) * stride + k];
}

/* out = the sub-patch over [s0,s1] x [t0,t1] of the net `in`. */
static void patch_part(int32_t p, int32_t q, const double *in, const double r[4], double *out)
{
    size_t n = (size_t)(p + 1) * (size_t)(q + 1) * 4;
    memcpy(out, in, n * sizeof *out);
    for (int32_t j = 0; j <= q; ++j)
        curve_part(out + (size_t)j * (size_t)(p + 1) * 4, p, 4, r[0], r[1]);
    for (int32_t i = 0; i <= p; ++i)
        curve_part(out + (size_t)i * 4, q, (size_t)(p + 1) * 4, r[2], r[3]);
}

/* z_min and P of the bound over a net's control points (view frame, homogeneous): the nearest
 * depth (not nearer than the near plane: only drawn points matter) and the largest lateral
 * tangent (capped as the derivation says; infinite when a point is not in front of the eye). */
static void depth_and_tangent(int32_t p, int32_t q, const double *net, const sw_lod_screen_view *v,
                              double *zmin, double *pmax)
{
    *zmin = INFINITY;
    *pmax = 0.0;
    size_t n = (size_t)(p + 1) * (size_t)(q + 1);
    for (size_t i = 0; i < n; ++i) {
        const double *c = net + 4 * i;
        double z = c[2] / c[3], lat = hypot(c[0], c[1]) / c[3];
        *zmin = fmin(*zmin, z);
        *pmax = z > 0.0 ? fmax(*pmax, lat / z) : INFINITY;
    }
    *pmax = fmin(*pmax, v->tan_corner + 2.0 * v->eps_px / v->focal_px);
    *zmin = fmax(*zmin, v->near_plane);
}

/* Affine parts (a plane's patches: the most common face of a CAD model) skip the bound below.
 * With equal weights, write the net as P_ij = A(i/p, j/q) + D_ij, A the affine map through the
 * corner poles P_00, P_p0, P_0q and |D_ij| <= delta. The patch is S = A + D with |D| <= delta
 * (convex hull), and a grid triangle interpolates S at its vertices: T = A + (interpolated D),
 * A being reproduced exactly. So |e| = |T - S| <= 2 delta for any grid, |e_lat| and |e_f| too,
 * and the screen error of the derivation above is at most (f / z_min) 2 delta (1 + P). When that
 * is within eps_px the coarsest allowed grid is drawn; d1 bounds |A_s| + |D_s| with
 * |D_s| <= 2 p delta (the derivative's net). Exact planes (delta at rounding level) take it at
 * any distance; others fall through to the full bound. */
static int g_affine_fast = 1;

void sw_lod_screen_affine_fast(int on)
{
    g_affine_fast = on != 0;
}

static int affine_segments(int32_t p, int32_t q, const double *net, const double range[4],
                           const sw_lod_screen_view *v, const int32_t *allowed,
                           sw_lod_screen_density *out)
{
    const size_t n = (size_t)(p + 1) * (size_t)(q + 1);
    const double w = net[3];
    for (size_t i = 1; i < n; ++i)
        if (net[4 * i + 3] != w)
            return 0;
    if (!(w > 0.0))
        return 0;
    const double *c00 = net, *cp0 = net + 4 * (size_t)p, *c0q = net + 4 * (size_t)q * (p + 1);
    double a_s[3], a_t[3], delta = 0.0;
    for (int k = 0; k < 3; ++k) {
        a_s[k] = (cp0[k] - c00[k]) / w;
        a_t[k] = (c0q[k] - c00[k]) / w;
    }
    for (int32_t j = 0; j <= q; ++j)
        for (int32_t i = 0; i <= p; ++i) {
            const double *c = net + 4 * ((size_t)j * (p + 1) + i);
            double d2 = 0.0;
            for (int k = 0; k < 3; ++k) {
                const double a = c00[k] / w + a_s[k] * i / p + a_t[k] * j / q;
                d2 += (c[k] / w - a) * (c[k] / w - a);
            }
            delta = fmax(delta, sqrt(d2));
        }
    double zmin, pmax;
    depth_and_tangent(p, q, net, v, &zmin, &pmax);
    if (!(2.0 * delta * (1.0 + pmax) * v->focal_px <= v->eps_px * zmin))
        return 0;
    out->nu = out->nv = allowed[0];
    out->eps_obj = sw_lod_object_tolerance(v->eps_px, zmin, v->focal_px, pmax, 0.0);
    out->d1[0] = (sqrt(a_s[0] * a_s[0] + a_s[1] * a_s[1] + a_s[2] * a_s[2]) + 2.0 * p * delta) /
                 (range[1] - range[0]);
    out->d1[1] = (sqrt(a_t[0] * a_t[0] + a_t[1] * a_t[1] + a_t[2] * a_t[2]) + 2.0 * q * delta) /
                 (range[3] - range[2]);
    return 1;
}

/* The lateral (mask 3), depth (mask 4) and whole (mask 7) images' bounds. */
static const unsigned k_view_masks[3] = {3u, 4u, 7u};

/* The measure's second-derivative bounds from those of the lateral and depth images (b[0],
 * b[1]) of a sub-patch 1/ku x 1/kv of the range. */
static void sub_bounds(const sw_lod_patch_bounds b[2], double ku, double kv, sub_info *o)
{
    double scale[3] = {ku * ku, ku * kv, kv * kv};
    for (int k = 0; k < 3; ++k) {
        o->ml[k] = b[0].d2[k] * scale[k];
        o->mf[k] = b[1].d2[k] * scale[k];
    }
}

static void sub_measure(int32_t p, int32_t q, const double *net, const sw_lod_screen_view *v,
                        double ku, double kv, sub_info *o)
{
    sw_lod_patch_bounds b[2];
    bounds_masked(p, q, net, k_view_masks, 2, b);
    sub_bounds(b, ku, kv, o);
    depth_and_tangent(p, q, net, v, &o->zmin, &o->pmax);
}

/* 1 when every cell of an nu x nv grid passes, from the k x k sub-patch measures. */
static int grid_passes(const sub_info *sub, int32_t k, int32_t nu, int32_t nv,
                       const sw_lod_screen_view *v)
{
    int32_t mu = k, mv = k;
    if (k > 1) {
        mu = (k + nu - 1) / nu + 1;
        mv = (k + nv - 1) / nv + 1;
        mu = mu < k ? mu : k;
        mv = mv < k ? mv : k;
    }
    double ds = 1.0 / nu, dt = 1.0 / nv;
    for (int32_t b = 0; b + mv <= k; ++b)
        for (int32_t a = 0; a + mu <= k; ++a) {
            sub_info w = sub[b * k + a];
            for (int32_t y = b; y < b + mv; ++y)
                for (int32_t x = a; x < a + mu; ++x) {
                    const sub_info *o = &sub[y * k + x];
                    for (int c = 0; c < 3; ++c) {
                        w.ml[c] = fmax(w.ml[c], o->ml[c]);
                        w.mf[c] = fmax(w.mf[c], o->mf[c]);
                    }
                    w.zmin = fmin(w.zmin, o->zmin);
                    w.pmax = fmax(w.pmax, o->pmax);
                }
            double m[3];
            for (int c = 0; c < 3; ++c)
                m[c] = w.ml[c] + w.pmax * w.mf[c];
            double lhs = m[0] * ds * ds + 2.0 * m[1] * ds * dt + m[2] * dt * dt;
            if (!(lhs <= 8.0 * v->eps_px * w.zmin / v->focal_px))
                return 0;
        }
    return 1;
}

static int pair_passes(const sub_info *whole, const sub_info *subs, int32_t k, int32_t nu,
                       int32_t nv, const sw_lod_screen_view *v)
{
    return grid_passes(whole, 1, nu, nv, v) || (k > 1 && grid_passes(subs, k, nu, nv, v));
}

/* Fewest cells among allowed pairs passing for either analysis (whole, subs). Passing is
 * monotone in nu and nv, so the smallest passing nv never grows with nu. */
static int choose_segments(const sub_info *whole, const sub_info *subs, int32_t k,
                           const sw_lod_screen_view *v, const int32_t *allowed, int32_t n_allowed,
                           int32_t out[2])
{
    double best = INFINITY;
    int32_t known = n_allowed; /* index of an nv known to pass for the current nu, or none */
    for (int32_t i = 0; i < n_allowed; ++i) {
        int32_t nu = allowed[i];
        if ((double)nu * allowed[0] >= best)
            break;
        int32_t lo = 0, hi = known; /* first passing nv in [lo, hi]; hi passes unless == n */
        while (lo < hi) {
            int32_t mid = (lo + hi) / 2;
            if (pair_passes(whole, subs, k, nu, allowed[mid], v))
                hi = mid;
            else
                lo = mid + 1;
        }
        if (lo == n_allowed)
            continue;
        known = lo;
        double cells = (double)nu * (double)allowed[lo];
        if (cells < best) {
            best = cells;
            out[0] = nu;
            out[1] = allowed[lo];
        }
    }
    return best < INFINITY;
}

static int g_coarsest_fast = 1;

void sw_lod_screen_coarsest_fast(int on)
{
    g_coarsest_fast = on != 0;
}

/* The whole range's measure and its image's bounds (all). The difference bounds come first: when
 * they already pass the coarsest allowed grid, nothing the product bounds tighten can choose
 * fewer cells, and only their first derivatives (all's d1) are taken — the second-derivative
 * products are most of the cost of a far patch's density. Returns 1 then. */
static int whole_measure(int32_t p, int32_t q, const double *net, const sw_lod_screen_view *v,
                         int32_t coarsest, sub_info *o, sw_lod_patch_bounds *all)
{
    sw_lod_patch_bounds b[3];
    double c[3];
    difference_bounds_masked(p, q, net, k_view_masks, 3, c, b);
    sub_bounds(b, 1.0, 1.0, o);
    depth_and_tangent(p, q, net, v, &o->zmin, &o->pmax);
    const int coarsest_passes = g_coarsest_fast && grid_passes(o, 1, coarsest, coarsest, v);
    if (coarsest_passes)
        tighten_by_products(p, q, net, c, k_view_masks + 2, 1, 0, b + 2);
    else
        tighten_by_products(p, q, net, c, k_view_masks, 3, 1, b);
    sub_bounds(b, 1.0, 1.0, o);
    *all = b[2];
    return coarsest_passes;
}

int sw_lod_screen_segments(int32_t deg_u, int32_t deg_v, const double *cpw, const double range[4],
                           const sw_lod_screen_view *v, const int32_t *allowed, int32_t n_allowed,
                           int32_t max_sub, sw_lod_screen_density *out)
{
    size_t n = (size_t)(deg_u + 1) * (size_t)(deg_v + 1);
    double small[3 * 4 * SMALL_NET],
        *mem = n <= SMALL_NET ? small : sw__malloc(3 * 4 * n * sizeof *mem);
    out->nu = out->nv = allowed[n_allowed - 1];
    out->eps_obj = 0.0;
    if (!mem)
        return 0;
    double *view = mem, *part = mem + 4 * n, *sub = mem + 8 * n;
    for (size_t i = 0; i < n; ++i) {
        const double *c = cpw + 4 * i;
        double *o = view + 4 * i;
        o[0] = v->right[0] * c[0] + v->right[1] * c[1] + v->right[2] * c[2];
        o[1] = v->up[0] * c[0] + v->up[1] * c[1] + v->up[2] * c[2];
        o[2] = v->fwd[0] * c[0] + v->fwd[1] * c[1] + v->fwd[2] * c[2];
        o[3] = c[3];
    }
    patch_part(deg_u, deg_v, view, range, part);
    if (g_affine_fast && deg_u > 0 && deg_v > 0 &&
        affine_segments(deg_u, deg_v, part, range, v, allowed, out)) {
        if (mem != small)
            sw__free(mem);
        return 1;
    }
    sub_info whole, subs[SUB_MAX * SUB_MAX];
    sw_lod_patch_bounds rb;
    const int coarsest = whole_measure(deg_u, deg_v, part, v, allowed[0], &whole, &rb);
    out->d1[0] = rb.d1[0] / (range[1] - range[0]);
    out->d1[1] = rb.d1[1] / (range[3] - range[2]);
    /* pmax bounds |tan| of every view direction into the part: the one tangent of the rule */
    out->eps_obj = sw_lod_object_tolerance(v->eps_px, whole.zmin, v->focal_px, whole.pmax, 0.0);
    int32_t guess[2] = {allowed[0], allowed[0]};
    int found = coarsest || choose_segments(&whole, NULL, 1, v, allowed, n_allowed, guess);
    /* Sub-patch bounds pay for themselves only on grids of many cells: a bound costs ~10 us,
     * about what drawing 50 triangles costs on llvmpipe. */
    double cells = found ? (double)guess[0] * guess[1] : INFINITY;
    int32_t k = coarsest || cells <= 32.0 ? 1 : cells <= 1024.0 ? 2 : SUB_MAX;
    k = k < max_sub ? k : (max_sub > 1 ? max_sub : 1);
    if (k > 1) {
        for (int32_t b = 0; b < k; ++b)
            for (int32_t a = 0; a < k; ++a) {
                double r[4] = {(double)a / k, (double)(a + 1) / k, (double)b / k,
                               (double)(b + 1) / k};
                patch_part(deg_u, deg_v, part, r, sub);
                sub_measure(deg_u, deg_v, sub, v, k, k, &subs[b * k + a]);
            }
        found = choose_segments(&whole, subs, k, v, allowed, n_allowed, guess);
    }
    if (found) {
        out->nu = guess[0];
        out->nv = guess[1];
    }
    if (mem != small)
        sw__free(mem);
    return found;
}

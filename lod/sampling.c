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

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* Differences of a control net, 4 doubles per point (Q_xyz, w). */
typedef struct diff_max {
    double q, w; /* max norm of the xyz part, max |w part| */
} diff_max;

static void diff_update(diff_max *m, const double d[4])
{
    double qn = norm3(d);
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

/* max over the net of the norm of a difference given by stencil offsets and coefficients. */
static diff_max net_diff(const double *cpw, int32_t nu, int32_t nv, const double c[3], int di,
                         int dj, int order_s, int order_t)
{
    diff_max m = {0.0, 0.0};
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
            diff_update(&m, d);
        }
    }
    return m;
}

static void net_centre_radius_wmin(const double *cpw, int32_t count, double c[3], double *radius,
                                   double *wmin)
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
    *radius = 0.0;
    for (int32_t k = 0; k < count; ++k) {
        const double *p = cpw + (size_t)k * 4;
        double d[3] = {p[0] / p[3] - c[0], p[1] / p[3] - c[1], p[2] / p[3] - c[2]};
        *radius = fmax(*radius, norm3(d));
    }
}

/* ---- the Bernstein-product bound ---------------------------------------------------------- */
enum { PRODUCT_MAX_DEGREE = 7, BMAX = 3 * PRODUCT_MAX_DEGREE };

/* A tensor-product polynomial in Bernstein form: (m+1) x (n+1) coefficients of `dim` doubles,
 * s fastest. */
typedef struct bpoly {
    int32_t m, n, dim;
    double *c;
} bpoly;

typedef struct arena {
    double *mem;
    size_t used, cap;
    double binom[BMAX + 1][BMAX + 1];
} arena;

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

/* Partial derivative along s (dir 0) or t (dir 1); of a constant direction: zero of degree 0. */
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
            for (int32_t k = 0; k < p->dim; ++k)
                o[k] = deg * (hi[k] - lo[k]);
        }
    return d;
}

/* Product of a scalar polynomial `w` and a polynomial `p`, times `scale`, added to `out` (which
 * must have degree (w.m + p.m, w.n + p.n) and p's dim). */
static void bp_mul_add(const arena *a, const bpoly *w, const bpoly *p, double scale, bpoly *out)
{
    const double(*b)[BMAX + 1] = a->binom;
    for (int32_t j1 = 0; j1 <= w->n; ++j1)
        for (int32_t i1 = 0; i1 <= w->m; ++i1) {
            double wc = *bp_at(w, i1, j1) * scale * b[w->m][i1] * b[w->n][j1];
            for (int32_t j2 = 0; j2 <= p->n; ++j2)
                for (int32_t i2 = 0; i2 <= p->m; ++i2) {
                    int32_t i = i1 + i2, j = j1 + j2;
                    double f = wc * b[p->m][i2] * b[p->n][j2] / (b[out->m][i] * b[out->n][j]);
                    const double *pc = bp_at(p, i2, j2);
                    double *o = bp_at(out, i, j);
                    for (int32_t k = 0; k < p->dim; ++k)
                        o[k] += f * pc[k];
                }
        }
}

/* x * w - y * v (x, y vector; w, v scalar), both products of the same degree. */
static bpoly bp_cross_diff(arena *a, const bpoly *x, const bpoly *w, double ky, const bpoly *y,
                           const bpoly *v)
{
    bpoly r = bp_new(a, x->m + w->m, x->n + w->n, x->dim);
    bp_mul_add(a, w, x, 1.0, &r);
    bp_mul_add(a, v, y, -ky, &r);
    return r;
}

static double bp_max_norm(const bpoly *p)
{
    double m = 0.0;
    size_t n = (size_t)(p->m + 1) * (size_t)(p->n + 1);
    for (size_t i = 0; i < n; ++i)
        m = fmax(m, norm3(p->c + 3 * i));
    return m;
}

static double bp_min(const bpoly *p)
{
    double m = INFINITY;
    size_t n = (size_t)(p->m + 1) * (size_t)(p->n + 1);
    for (size_t i = 0; i < n; ++i)
        m = fmin(m, p->c[i]);
    return m;
}

/* The Bernstein-product bounds (see the top of the file); 0 when out of memory or too high a
 * degree (the caller keeps the other bound then). */
static int product_bounds(int32_t p, int32_t q, const double *cpw, const double c[3],
                          sw_lod_patch_bounds *out)
{
    if (p > PRODUCT_MAX_DEGREE || q > PRODUCT_MAX_DEGREE)
        return 0;
    arena a;
    /* 17 polynomials, none of degree above (3p, 3q), at most 3 doubles per coefficient */
    a.cap = 17 * (size_t)(3 * p + 1) * (size_t)(3 * q + 1) * 3;
    a.used = 0;
    a.mem = malloc(a.cap * sizeof *a.mem);
    if (!a.mem)
        return 0;
    for (int n = 0; n <= BMAX; ++n) {
        a.binom[n][0] = 1.0;
        for (int k = 1; k <= n; ++k)
            a.binom[n][k] = a.binom[n][k - 1] * (double)(n - k + 1) / (double)k;
    }
    bpoly h = bp_new(&a, p, q, 3), w = bp_new(&a, p, q, 1);
    for (int32_t j = 0; j <= q; ++j)
        for (int32_t i = 0; i <= p; ++i) {
            const double *src = cpw + ((size_t)j * (size_t)(p + 1) + (size_t)i) * 4;
            for (int k = 0; k < 3; ++k)
                bp_at(&h, i, j)[k] = src[k] - src[3] * c[k];
            *bp_at(&w, i, j) = src[3];
        }
    bpoly hs = bp_deriv(&a, &h, 0), ht = bp_deriv(&a, &h, 1);
    bpoly ws = bp_deriv(&a, &w, 0), wt = bp_deriv(&a, &w, 1);
    bpoly ns = bp_cross_diff(&a, &hs, &w, 1.0, &h, &ws);
    bpoly nt = bp_cross_diff(&a, &ht, &w, 1.0, &h, &wt);
    bpoly w2 = bp_new(&a, 2 * p, 2 * q, 1);
    bp_mul_add(&a, &w, &w, 1.0, &w2);
    bpoly w3 = bp_new(&a, 3 * p, 3 * q, 1);
    bp_mul_add(&a, &w2, &w, 1.0, &w3);
    bpoly nss = bp_deriv(&a, &ns, 0), nts = bp_deriv(&a, &nt, 0), ntt = bp_deriv(&a, &nt, 1);
    bpoly kss = bp_cross_diff(&a, &nss, &w, 2.0, &ns, &ws);
    bpoly kst = bp_cross_diff(&a, &nts, &w, 2.0, &nt, &ws);
    bpoly ktt = bp_cross_diff(&a, &ntt, &w, 2.0, &nt, &wt);
    double m2 = bp_min(&w2), m3 = bp_min(&w3);
    out->d1[0] = bp_max_norm(&ns) / m2;
    out->d1[1] = bp_max_norm(&nt) / m2;
    out->d2[0] = bp_max_norm(&kss) / m3;
    out->d2[1] = bp_max_norm(&kst) / m3;
    out->d2[2] = bp_max_norm(&ktt) / m3;
    free(a.mem);
    return 1;
}

void sw_lod_rational_bezier_bounds(int32_t deg_u, int32_t deg_v, const double *cpw,
                                   sw_lod_patch_bounds *out)
{
    int32_t nu = deg_u + 1, nv = deg_v + 1;
    double c[3], r, wmin;
    net_centre_radius_wmin(cpw, nu * nv, c, &r, &wmin);
    double p = deg_u, q = deg_v;

    diff_max ds = net_diff(cpw, nu, nv, c, 1, 0, 1, 0);
    diff_max dt = net_diff(cpw, nu, nv, c, 0, 1, 0, 1);
    diff_max dst = net_diff(cpw, nu, nv, c, 1, 1, 1, 1);
    diff_max dss = {0.0, 0.0}, dtt = {0.0, 0.0};
    if (deg_u >= 2)
        dss = net_diff(cpw, nu, nv, c, 2, 0, 2, 0);
    if (deg_v >= 2)
        dtt = net_diff(cpw, nu, nv, c, 0, 2, 0, 2);

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

    sw_lod_patch_bounds pb;
    if (product_bounds(deg_u, deg_v, cpw, c, &pb)) {
        for (int k = 0; k < 2; ++k)
            out->d1[k] = fmin(out->d1[k], pb.d1[k]);
        for (int k = 0; k < 3; ++k)
            out->d2[k] = fmin(out->d2[k], pb.d2[k]);
    }
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

/* SPDX-License-Identifier: MIT */
/* Evaluation of rational B-spline curves and surfaces in homogeneous form (double precision).
 *
 * Derivatives are not taken from derivatives of the basis functions (The NURBS Book A2.3), whose
 * terms are ~ degree / knot-span large and cancel: in a span of width h next to spans of width 1
 * (hammer.brep, Top.brep: h = 1e-3 .. 4e-8) that loses a factor (1/h)^order of accuracy to the
 * magnitude of the poles. Instead the poles of the span are differenced first, into the control
 * points of the derivative (A3.3, A3.7: P^(k)_i = (p-k+1) (P^(k-1)_i+1 - P^(k-1)_i) /
 * (t_i+p+1 - t_i+k)), which are then contracted with the basis values of degree p-k (A2.2, all
 * degrees come from one Cox-de Boor triangle, A3.4/A3.8). Differences of neighbouring poles are
 * exact or rounded relative to themselves, and the contraction is a convex combination, so each
 * derivative is accurate relative to its own control points. Differencing happens on the poles in
 * both directions before any contraction: a v-derivative never differences u-contracted values.
 *
 * The Euclidean derivatives follow from the quotient rule (A4.4) on the homogeneous form A = w*S:
 *   S_u  = (A_u - w_u S) / w,
 *   S_uu = (A_uu - 2 w_u S_u - w_uu S) / w,  S_uv = (A_uv - w_u S_v - w_v S_u - w_uv S) / w.
 * What is left is the conditioning of the homogeneous form itself: w*P is rounded when stored,
 * and A_uv holds w_uv S at the poles' absolute magnitude (moving to a local origin would need
 * exact products, i.e. FMA, to gain anything); both stay ~1e-12 relative on the sample models.
 * Guthe et al. 2005 §4.2 evaluates the same rational form (on the GPU, per Bézier patch).
 * No heap allocation: every buffer is a stack array sized by SW_SG_MAX_DEGREE + 1.
 */
#include "sw_sg_geom.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#define SW__P1 (SW_SG_MAX_DEGREE + 1)
#define SW__ND 2       /* highest derivative order evaluated */
#define SW__MAX_DIM 16 /* sw_sg_curve_validate's bound on the homogeneous dimension */

/* One parameter's span: basis values of degrees p, p-1, p-2 and the factors that turn pole
 * differences into derivative control points. */
typedef struct span_basis {
    int32_t span, p;
    int32_t nd; /* derivative orders kept: min(requested, p); higher ones vanish */
    double n[SW__ND + 1][SW__P1]; /* n[k][r] = N_{span-p+k+r, p-k}(t), r = 0..p-k */
    double s[SW__ND][SW__P1];     /* s[k-1][i] = (p-k+1) / (t_{span+i+1} - t_{span-p+i+k}) */
} span_basis;

/* Inlined into every caller, with the degree a constant where surface_eval_h dispatches on it:
 * the loops below run over the degree, and unrolled a plane's, cylinder's or bicubic's evaluation
 * took 0.6-0.85 of the generic time (the same operations in the same order: the same bits). */
#define SW__INLINE static inline __attribute__((always_inline))

SW__INLINE void span_basis_init(span_basis *b, const double *knots, int32_t p, int32_t n, double t,
                                int32_t nd)
{
    assert(p >= 0 && p <= SW_SG_MAX_DEGREE && nd >= 0 && nd <= SW__ND);
    const int32_t span = sw_sg_knots_find_span(knots, p, n, t);
    double left[SW__P1], right[SW__P1], nb[SW__P1];
    b->span = span;
    b->p = p;
    b->nd = nd < p ? nd : p;
    nb[0] = 1.0;
    if (p <= b->nd)
        b->n[p][0] = 1.0;
    /* A2.2; the degree-j row is kept once p - j is an order we need. */
    for (int32_t j = 1; j <= p; j++) {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        double saved = 0.0;
        for (int32_t r = 0; r < j; r++) {
            /* Within a non-empty span these knot differences are never zero. */
            const double temp = nb[r] / (right[r + 1] + left[j - r]);
            nb[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        nb[j] = saved;
        if (p - j <= b->nd)
            memcpy(b->n[p - j], nb, sizeof(double) * (size_t)(j + 1));
    }
    /* The denominators hold the span itself, so they are never zero either. */
    for (int32_t k = 1; k <= b->nd; k++)
        for (int32_t i = 0; i <= p - k; i++)
            b->s[k - 1][i] = (double)(p - k + 1) / (knots[span + i + 1] - knots[span - p + i + k]);
}

/* The control points of derivative k (count - 1 points) from those of derivative k - 1 (count
 * points), `dim` doubles each: the step of A3.3. */
SW__INLINE void diff_points(const double *in, int32_t count, int32_t dim, const double *scale,
                            double *out)
{
    for (int32_t i = 0; i + 1 < count; i++)
        for (int32_t d = 0; d < dim; d++)
            out[i * dim + d] = scale[i] * (in[(i + 1) * dim + d] - in[i * dim + d]);
}

/* out[d] = sum_r basis[r] * pts[r * dim + d], r < count. */
SW__INLINE void contract(const double *basis, const double *pts, int32_t count, int32_t dim,
                         double *out)
{
    for (int32_t d = 0; d < dim; d++)
        out[d] = 0.0;
    for (int32_t r = 0; r < count; r++)
        for (int32_t d = 0; d < dim; d++)
            out[d] += basis[r] * pts[r * dim + d];
}

/* Derivatives 0..b->nd of a curve whose local control points (p + 1 of them, `dim` doubles
 * each, p = b->p) are `pts`: out[k * dim + d]. */
static void curve_ders_local(const span_basis *b, const double *pts, int32_t dim, double *out)
{
    double d1[SW__P1 * SW__MAX_DIM], d2[SW__P1 * SW__MAX_DIM];
    const int32_t p = b->p;
    contract(b->n[0], pts, p + 1, dim, out);
    if (b->nd >= 1) {
        diff_points(pts, p + 1, dim, b->s[0], d1);
        contract(b->n[1], d1, p, dim, out + dim);
    }
    if (b->nd >= 2) {
        diff_points(d1, p, dim, b->s[1], d2);
        contract(b->n[2], d2, p - 1, dim, out + 2 * dim);
    }
}

void sw_sg_curve_eval_h(const sw_sg_curve *c, double t, int32_t nd, double *out)
{
    assert(c && out && nd >= 0 && nd <= SW__ND && c->dim >= 1 && c->dim <= SW__MAX_DIM);
    span_basis b;
    span_basis_init(&b, c->knots, c->degree, c->n, t, nd);
    const double *pts = c->cpw + (size_t)(b.span - c->degree) * (size_t)c->dim;
    curve_ders_local(&b, pts, c->dim, out);
    for (int32_t k = b.nd + 1; k <= nd; k++)
        memset(out + k * c->dim, 0, sizeof(double) * (size_t)c->dim);
}

void sw_sg_curve_eval(const sw_sg_curve *c, double t, double *out)
{
    assert(c && out && c->dim >= 2 && c->dim <= SW__MAX_DIM);
    double h[SW__MAX_DIM];
    sw_sg_curve_eval_h(c, t, 0, h);
    for (int32_t d = 0; d < c->dim - 1; d++)
        out[d] = h[d] / h[c->dim - 1];
}

/* The homogeneous partials a[k][l] = d^{k+l} S^w / du^k dv^l, k + l <= nd, of a surface at the
 * spans of bu and bv. Each row of the (p+1) x (q+1) local net is differenced in v (up to the
 * order still needed) from the raw poles, then in u, then contracted in u and accumulated in v:
 * rows of v-order l arrive with a lag of l rows, so three raw rows suffice. */
typedef struct surface_acc {
    const span_basis *bu, *bv;
    int32_t nd;
    double a[SW__ND + 1][SW__ND + 1][4];
} surface_acc;

/* One row (local v index j) of the net differenced l times in v: adds its contribution to every
 * a[k][l] with k + l <= nd. */
SW__INLINE void surface_add_row(surface_acc *acc, int32_t l, int32_t j, const double *row)
{
    const span_basis *bu = acc->bu;
    const int32_t p = bu->p;
    const int32_t kmax = acc->nd - l < bu->nd ? acc->nd - l : bu->nd;
    double d1[SW__P1 * 4], d2[SW__P1 * 4], r[4];
    const double *net = row;
    for (int32_t k = 0; k <= kmax; k++) {
        if (k == 1) {
            diff_points(row, p + 1, 4, bu->s[0], d1);
            net = d1;
        } else if (k == 2) {
            diff_points(d1, p, 4, bu->s[1], d2);
            net = d2;
        }
        contract(bu->n[k], net, p + 1 - k, 4, r);
        const double nv = acc->bv->n[l][j];
        for (int32_t d = 0; d < 4; d++)
            acc->a[k][l][d] += nv * r[d];
    }
}

/* The partials of a surface of degrees (p, q); p and q are constants in the instances below. */
SW__INLINE void surface_eval_pq(const sw_sg_surface *s, double u, double v, int32_t nd, int32_t p_,
                                int32_t q_, double a[SW__ND + 1][SW__ND + 1][4])
{
    span_basis bu, bv;
    span_basis_init(&bu, s->knots_u, p_, s->n_u, u, nd);
    span_basis_init(&bv, s->knots_v, q_, s->n_v, v, nd);
    const int32_t p = bu.p, q = bv.p;
    surface_acc acc = {.bu = &bu, .bv = &bv, .nd = nd};
    double e1[2][SW__P1 * 4], e2[SW__P1 * 4];
    const double *base =
        s->cpw + ((size_t)(bv.span - q) * (size_t)s->n_u + (size_t)(bu.span - p)) * 4;
    for (int32_t j = 0; j <= q; j++) {
        const double *row = base + (size_t)j * (size_t)s->n_u * 4;
        surface_add_row(&acc, 0, j, row);
        if (bv.nd >= 1 && j >= 1) {
            /* e1[j & 1]: row j - 1 of the first v-differences */
            const double *prev = row - (size_t)s->n_u * 4;
            double *cur = e1[j & 1];
            for (int32_t i = 0; i < (p + 1) * 4; i++)
                cur[i] = bv.s[0][j - 1] * (row[i] - prev[i]);
            surface_add_row(&acc, 1, j - 1, cur);
            if (bv.nd >= 2 && j >= 2) {
                const double *old = e1[(j - 1) & 1];
                for (int32_t i = 0; i < (p + 1) * 4; i++)
                    e2[i] = bv.s[1][j - 2] * (cur[i] - old[i]);
                surface_add_row(&acc, 2, j - 2, e2);
            }
        }
    }
    memcpy(a, acc.a, sizeof(acc.a));
}

/* Every other pair of degrees. */
static void surface_eval_generic(const sw_sg_surface *s, double u, double v, int32_t nd,
                                 double a[SW__ND + 1][SW__ND + 1][4])
{
    surface_eval_pq(s, u, v, nd, s->deg_u, s->deg_v, a);
}

/* Planes (1, 1), cylinders and cones (2, 1) or (1, 2), spheres and tori (2, 2) and bicubic
 * B-splines (3, 3) take instances with constant degrees, which the compiler unrolls; the same
 * operations in the same order as the generic instance, so the results are the same bits. */
SW__INLINE void surface_eval_h(const sw_sg_surface *s, double u, double v, int32_t nd,
                               double a[SW__ND + 1][SW__ND + 1][4])
{
    assert(s && nd >= 0 && nd <= SW__ND);
    const int32_t p = s->deg_u, q = s->deg_v;
    if (p == 1 && q == 1)
        surface_eval_pq(s, u, v, nd, 1, 1, a);
    else if (p == 2 && q == 1)
        surface_eval_pq(s, u, v, nd, 2, 1, a);
    else if (p == 1 && q == 2)
        surface_eval_pq(s, u, v, nd, 1, 2, a);
    else if (p == 2 && q == 2)
        surface_eval_pq(s, u, v, nd, 2, 2, a);
    else if (p == 3 && q == 3)
        surface_eval_pq(s, u, v, nd, 3, 3, a);
    else if (p == 2) /* swept and revolved B-splines: 2 x 6..11 in the sample parts */
        surface_eval_pq(s, u, v, nd, 2, q, a);
    else
        surface_eval_generic(s, u, v, nd, a);
}

void sw_sg_surface_eval(const sw_sg_surface *s, double u, double v, double p[3])
{
    double a[SW__ND + 1][SW__ND + 1][4];
    surface_eval_h(s, u, v, 0, a);
    for (int d = 0; d < 3; d++)
        p[d] = a[0][0][d] / a[0][0][3];
}

void sw_sg_surface_eval_h1(const sw_sg_surface *s, double u, double v, double h[12])
{
    double a[SW__ND + 1][SW__ND + 1][4];
    surface_eval_h(s, u, v, 1, a);
    for (int d = 0; d < 4; d++) {
        h[d] = a[0][0][d];
        h[4 + d] = a[1][0][d];
        h[8 + d] = a[0][1][d];
    }
}

void sw_sg_h1_tangents(const double h[12], double su[3], double sv[3], double n[3])
{
    for (int k = 0; k < 3; ++k) {
        su[k] = h[4 + k] * h[3] - h[k] * h[7];
        sv[k] = h[8 + k] * h[3] - h[k] * h[11];
    }
    n[0] = su[1] * sv[2] - su[2] * sv[1];
    n[1] = su[2] * sv[0] - su[0] * sv[2];
    n[2] = su[0] * sv[1] - su[1] * sv[0];
}

/* The Greville abscissa of pole i: the mean of its degree interior knots. */
static double greville(const double *knots, int32_t degree, int32_t i)
{
    double sum = 0.0;
    for (int32_t k = 1; k <= degree; ++k)
        sum += knots[i + k];
    return sum / degree;
}

int sw_sg_surface_affine(const sw_sg_surface *s, double origin[3], double du[3], double dv[3])
{
    const int32_t nu = s->n_u, nv = s->n_v;
    const double *q = s->cpw, w = q[3];
    if (nu < 2 || nv < 2 || !(w > 0.0))
        return 0;
    const double gu0 = greville(s->knots_u, s->deg_u, 0), gv0 = greville(s->knots_v, s->deg_v, 0);
    const double su = greville(s->knots_u, s->deg_u, nu - 1) - gu0;
    const double sv = greville(s->knots_v, s->deg_v, nv - 1) - gv0;
    if (!(su > 0.0) || !(sv > 0.0))
        return 0;
    double scale = 0.0;
    for (int32_t i = 0; i < nu * nv; ++i) {
        if (fabs(q[4 * i + 3] - w) > 1e-14 * w)
            return 0;
        for (int d = 0; d < 3; ++d)
            scale = fmax(scale, fabs(q[4 * i + d] / q[4 * i + 3]));
    }
    const double *p00 = q, *pu = q + 4 * (nu - 1), *pv = q + 4 * (size_t)(nv - 1) * (size_t)nu;
    for (int d = 0; d < 3; ++d) {
        du[d] = (pu[d] - p00[d]) / (w * su);
        dv[d] = (pv[d] - p00[d]) / (w * sv);
        origin[d] = p00[d] / w - gu0 * du[d] - gv0 * dv[d];
    }
    const double tol = 1e-12 * scale;
    for (int32_t j = 0; j < nv; ++j) {
        const double gv = greville(s->knots_v, s->deg_v, j);
        for (int32_t i = 0; i < nu; ++i) {
            const double gu = greville(s->knots_u, s->deg_u, i), *p = q + 4 * ((size_t)j * nu + i);
            for (int d = 0; d < 3; ++d)
                if (fabs(p[d] / p[3] - (origin[d] + gu * du[d] + gv * dv[d])) > tol)
                    return 0;
        }
    }
    return 1;
}

void sw_sg_surface_eval_d2(const sw_sg_surface *s, double u, double v, sw_sg_surface_d2 *out)
{
    assert(out);
    double a[SW__ND + 1][SW__ND + 1][4];
    surface_eval_h(s, u, v, 2, a);
    const double w = a[0][0][3], wu = a[1][0][3], wv = a[0][1][3];
    const double wuu = a[2][0][3], wuv = a[1][1][3], wvv = a[0][2][3];
    const double iw = 1.0 / w;
    for (int d = 0; d < 3; d++) {
        const double p = a[0][0][d] * iw;
        const double su = (a[1][0][d] - wu * p) * iw;
        const double sv = (a[0][1][d] - wv * p) * iw;
        out->p[d] = p;
        out->du[d] = su;
        out->dv[d] = sv;
        out->duu[d] = (a[2][0][d] - 2.0 * wu * su - wuu * p) * iw;
        out->duv[d] = (a[1][1][d] - wu * sv - wv * su - wuv * p) * iw;
        out->dvv[d] = (a[0][2][d] - 2.0 * wv * sv - wvv * p) * iw;
    }
}

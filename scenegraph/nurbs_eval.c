/* Evaluation of rational B-spline curves and surfaces in homogeneous form (double precision).
 *
 * Points and derivatives are first computed for the homogeneous form S^w = (w*x, w*y, w*z, w)
 * (The NURBS Book A3.2/A3.6), then projected; the Euclidean derivatives follow from the quotient
 * rule (A4.4): with A = w*S,
 *   S_u  = (A_u - w_u S) / w,
 *   S_uu = (A_uu - 2 w_u S_u - w_uu S) / w,  S_uv = (A_uv - w_u S_v - w_v S_u - w_uv S) / w.
 * Guthe et al. 2005 §4.2 evaluates the same rational form (on the GPU, per Bézier patch).
 * No heap allocation: basis rows live in stack arrays sized by SW_SG_MAX_DEGREE + 1.
 */
#include "sw_sg_geom.h"

#include <assert.h>
#include <string.h>

#define SW__P1 (SW_SG_MAX_DEGREE + 1)

void sw_sg_curve_eval_h(const sw_sg_curve *c, double t, int32_t nd, double *out)
{
    assert(c && out && nd >= 0 && nd <= 2 && c->degree <= SW_SG_MAX_DEGREE);
    const int32_t p = c->degree, dim = c->dim;
    double ders[3 * SW__P1];
    const int32_t span = sw_sg_knots_find_span(c->knots, p, c->n, t);
    sw_sg_basis_ders(c->knots, p, span, t, nd, ders);

    memset(out, 0, sizeof(double) * (size_t)((nd + 1) * dim));
    for (int32_t r = 0; r <= p; r++) {
        const double *pw = c->cpw + (size_t)(span - p + r) * (size_t)dim;
        for (int32_t k = 0; k <= nd; k++) {
            const double b = ders[k * (p + 1) + r];
            for (int32_t d = 0; d < dim; d++)
                out[k * dim + d] += b * pw[d];
        }
    }
}

void sw_sg_curve_eval(const sw_sg_curve *c, double t, double *out)
{
    assert(c && out && c->dim >= 2);
    const int32_t p = c->degree, dim = c->dim;
    double n0[SW__P1];
    const int32_t span = sw_sg_knots_find_span(c->knots, p, c->n, t);
    sw_sg_basis_ders(c->knots, p, span, t, 0, n0);

    double w = 0.0;
    for (int32_t d = 0; d < dim - 1; d++)
        out[d] = 0.0;
    for (int32_t r = 0; r <= p; r++) {
        const double *pw = c->cpw + (size_t)(span - p + r) * (size_t)dim;
        for (int32_t d = 0; d < dim - 1; d++)
            out[d] += n0[r] * pw[d];
        w += n0[r] * pw[dim - 1];
    }
    for (int32_t d = 0; d < dim - 1; d++)
        out[d] /= w;
}

/* Homogeneous partial derivatives A[k][l] = d^{k+l} S^w / du^k dv^l for k, l <= nd (A3.6). */
static void surface_eval_h(const sw_sg_surface *s, double u, double v, int32_t nd,
                           double a[3][3][4])
{
    assert(s && nd >= 0 && nd <= 2);
    assert(s->deg_u <= SW_SG_MAX_DEGREE && s->deg_v <= SW_SG_MAX_DEGREE);
    const int32_t p = s->deg_u, q = s->deg_v;
    double nu[3 * SW__P1], nv[3 * SW__P1];
    const int32_t su = sw_sg_knots_find_span(s->knots_u, p, s->n_u, u);
    const int32_t sv = sw_sg_knots_find_span(s->knots_v, q, s->n_v, v);
    sw_sg_basis_ders(s->knots_u, p, su, u, nd, nu);
    sw_sg_basis_ders(s->knots_v, q, sv, v, nd, nv);

    memset(a, 0, sizeof(double) * 3 * 3 * 4);
    for (int32_t j = 0; j <= q; j++) {
        /* Row j of the net contracted with the u-basis, for each u-derivative order. */
        double row[3][4] = {{0}};
        const double *base =
            s->cpw + ((size_t)(sv - q + j) * (size_t)s->n_u + (size_t)(su - p)) * 4;
        for (int32_t i = 0; i <= p; i++) {
            const double *pw = base + (size_t)i * 4;
            for (int32_t k = 0; k <= nd; k++) {
                const double b = nu[k * (p + 1) + i];
                for (int32_t d = 0; d < 4; d++)
                    row[k][d] += b * pw[d];
            }
        }
        for (int32_t k = 0; k <= nd; k++)
            for (int32_t l = 0; k + l <= nd; l++) {
                const double b = nv[l * (q + 1) + j];
                for (int32_t d = 0; d < 4; d++)
                    a[k][l][d] += b * row[k][d];
            }
    }
}

void sw_sg_surface_eval(const sw_sg_surface *s, double u, double v, double p[3])
{
    double a[3][3][4];
    surface_eval_h(s, u, v, 0, a);
    for (int d = 0; d < 3; d++)
        p[d] = a[0][0][d] / a[0][0][3];
}

void sw_sg_surface_eval_h1(const sw_sg_surface *s, double u, double v, double h[12])
{
    double a[3][3][4];
    surface_eval_h(s, u, v, 1, a);
    for (int d = 0; d < 4; d++) {
        h[d] = a[0][0][d];
        h[4 + d] = a[1][0][d];
        h[8 + d] = a[0][1][d];
    }
}

void sw_sg_surface_eval_d2(const sw_sg_surface *s, double u, double v, sw_sg_surface_d2 *out)
{
    assert(out);
    double a[3][3][4];
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

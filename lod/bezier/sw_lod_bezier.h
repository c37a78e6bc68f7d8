/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: rational Bézier patch utilities in homogeneous form — the building blocks of
 * degree reduction (Guthe et al. 2005 §6.1), pairwise simplification (§6.2) and the rigorous error
 * bounds (error_bound.c).
 *
 * A "net" is a tensor-product Bernstein polynomial of degrees (deg_u, deg_v) with `dim` doubles per
 * coefficient, u fastest: coefficient (i, j) is at cpw[(j * (deg_u + 1) + i) * dim]. A rational
 * surface is a net with dim 4 (w*x, w*y, w*z, w); a 2D trim curve is a net with deg_v = 0 and
 * dim 3 (w*u, w*v, w); a scalar weight polynomial has dim 1. All operations are linear in the
 * coefficients, so they act on the homogeneous form exactly (de Casteljau, Farin: Curves and
 * Surfaces for CAGD, ch. 5-6 and 16).
 *
 * All functions are pure, allocate nothing and are thread-safe. Degrees are
 * 0..SW_LOD_BEZ_MAX_DEGREE (preconditions are asserts), dim is 1..SW_LOD_BEZ_MAX_DIM.
 */
#ifndef SW_LOD_BEZIER_H
#define SW_LOD_BEZIER_H

#include "sw_module_abi.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_LOD_BEZ_MAX_DEGREE 70 /* products of two nets of degree <= 31 + 3 and headroom */
#define SW_LOD_BEZ_MAX_DIM 4

/* Doubles a net of degrees (deg_u, deg_v) with `dim` doubles per coefficient occupies. */
size_t sw_lod_bez_count(int32_t deg_u, int32_t deg_v, int32_t dim);

/* Value of the net at (s, t) in [0,1]^2 (homogeneous; de Casteljau): out[dim]. */
void sw_lod_bez_eval(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, double s,
                     double t, double *out);

/* Euclidean point of a homogeneous net (dim - 1 coordinates divided by the last one). */
void sw_lod_bez_eval_euclid(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, double s,
                            double t, double *out);

/* de Casteljau subdivision along direction `dir` (0 = u, 1 = v) at parameter s in [0,1]:
 * left receives the net over [0,s], right the net over [s,1] (same degrees). left and right may
 * be NULL (not computed) and must not overlap cpw or each other. */
void sw_lod_bez_subdivide(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, int dir,
                          double s, double *left, double *right);

/* The net restricted to the sub-rectangle rect = {s0, s1, t0, t1} of [0,1]^2 (s0 <= s1, t0 <= t1),
 * reparameterized to [0,1]^2. out may equal cpw (in place); otherwise they must not overlap. */
SW_MODULE_ABI void sw_lod_bez_restrict(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw,
                                       const double rect[4], double *out);

/* Exact degree elevation to (new_u, new_v) >= (deg_u, deg_v). out must not overlap cpw. */
void sw_lod_bez_elevate(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, int32_t new_u,
                        int32_t new_v, double *out);

/* out += scale * a * b, where a is a net of degrees (au, av) with `dim` doubles per coefficient
 * and b a scalar net (dim 1) of degrees (bu, bv); out has degrees (au + bu, av + bv) and `dim`
 * doubles per coefficient (zero it first for a plain product). This is how P * w~ - P~ * w is
 * formed without leaving the Bernstein basis. out must not overlap a or b. */
void sw_lod_bez_mul_add(int32_t dim, int32_t au, int32_t av, const double *a, int32_t bu,
                        int32_t bv, const double *b, double scale, double *out);

/* Copies component `comp` of a net with `dim` doubles per coefficient into a scalar net. */
void sw_lod_bez_component(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw,
                          int32_t comp, double *out);

/* Row `n` of Pascal's triangle: row[k] = C(n, k), k = 0..n (n <= 2 * SW_LOD_BEZ_MAX_DEGREE). */
void sw_lod_binomial_row(int32_t n, double *row);

/* The weights of a Bernstein product of nets of degrees (au, av) and (bu, bv): coefficient
 * (i1, j1) of A times (i2, j2) of B goes to (i1 + i2, j1 + j2) of the product with weight
 * C(au,i1) C(av,j1) C(bu,i2) C(bv,j2) / (C(au+bu, i1+i2) C(av+bv, j1+j2)). */
typedef struct sw_lod_bez_product_weights {
    double au[SW_LOD_BEZ_MAX_DEGREE + 1], av[SW_LOD_BEZ_MAX_DEGREE + 1];
    double bu[SW_LOD_BEZ_MAX_DEGREE + 1], bv[SW_LOD_BEZ_MAX_DEGREE + 1];
    double ou[2 * SW_LOD_BEZ_MAX_DEGREE + 1], ov[2 * SW_LOD_BEZ_MAX_DEGREE + 1];
} sw_lod_bez_product_weights;

void sw_lod_bez_product_weights_init(sw_lod_bez_product_weights *w, int32_t au, int32_t av,
                                     int32_t bu, int32_t bv);

static inline double sw_lod_bez_product_weight(const sw_lod_bez_product_weights *w, int32_t i1,
                                               int32_t j1, int32_t i2, int32_t j2)
{
    return w->au[i1] * w->av[j1] * w->bu[i2] * w->bv[j2] / (w->ou[i1 + i2] * w->ov[j1 + j2]);
}

#ifdef __cplusplus
}
#endif
#endif

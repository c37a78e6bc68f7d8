/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: a rigorous bound of the distance between two rational Bézier nets over the
 * same parameter domain — an original patch P/w and its approximation P~/w~ (degree reduction,
 * Guthe et al. 2005 §6.1; pairwise simplification, §6.2; trim curves approximated by rational
 * cubics, §4.1). The paper's own error, ε_c = max distance of projected control points, is not a
 * bound; error_bound.c says why and what replaces it.
 *
 * Pure and thread-safe; allocates scratch memory per call.
 */
#ifndef SW_LOD_ERROR_H
#define SW_LOD_ERROR_H

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Zero-initialise for the defaults. */
typedef struct sw_lod_error_desc {
    double rel_tol;     /* stop refining once bound <= (1 + rel_tol) * distance found; 0 = 0.02 */
    int32_t max_pieces; /* sub-rectangles examined at most; 0 = 256, 1 = the one-piece bound */
} sw_lod_error_desc;

typedef struct sw_lod_error_result {
    double bound;   /* >= sup over [0,1]^2 of |A/wA - B/wB| (Euclidean, dim - 1 coordinates) */
    double found;   /* a distance attained at some parameter point: found <= sup <= bound */
    int32_t pieces; /* sub-rectangles examined */
} sw_lod_error_result;

/* Bounds the distance between the rational nets A (degrees pa, qa) and B (degrees pb, qb), both
 * homogeneous with `dim` doubles per coefficient (last = weight; 4 for surfaces, 3 for 2D trim
 * curves with qa = qb = 0) and both parameterized over [0,1]^2 (the caller restricts the original
 * to the approximation's rectangle first: sw_lod_bez_restrict). Precondition: every weight of both
 * nets > 0 and finite (a non-positive weight makes the bound +INF, never a wrong finite value).
 * desc may be NULL (defaults). Returns SW_OK or SW_ERR_OUT_OF_MEMORY (out untouched). */
sw_result sw_lod_error_bound(int32_t dim, int32_t pa, int32_t qa, const double *a, int32_t pb,
                             int32_t qb, const double *b, const sw_lod_error_desc *desc,
                             sw_lod_error_result *out, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

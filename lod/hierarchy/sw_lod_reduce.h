/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: G1-constrained degree reduction of rational Bézier patches of any degree to
 * rational bicubics (Guthe et al. 2005 §6.1), leaf subdivision until a rigorous error bound meets a
 * tolerance, the same for 2D trim curves to rational cubics (§4.1), and pairwise simplification of
 * two adjacent bicubics into one (§6.2, simplify.c).
 *
 * Nets are homogeneous and u fastest as in sw_lod_bezier.h; a bicubic is 64 doubles
 * (16 points of (w*x, w*y, w*z, w)). All functions are thread-safe; the ones returning sw_result
 * allocate scratch memory.
 */
#ifndef SW_LOD_REDUCE_H
#define SW_LOD_REDUCE_H

#include "sw_lod_error.h"
#include "sw_sg_geom.h"

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* How one reduction (or simplification) went. */
typedef struct sw_lod_reduce_info {
    double lambda[2][2]; /* [dir][end]: P~1 = P0 + λ[dir][0] (P1 - P0), P~2 = Pn + λ[dir][1] (..) */
    uint32_t clamped;    /* bit 2*dir+end: λ clamped (to stay > 0, or to keep weights positive) */
    uint32_t elevated;   /* bit dir: degree <= 3 in that direction, elevated exactly instead */
} sw_lod_reduce_info;

/* Reduces a rational Bézier patch of degrees (deg_u, deg_v) (1..SW_SG_MAX_DEGREE, all weights > 0)
 * to a rational bicubic, u first, then v, each with one (λ0, λ1) pair shared by all lines of that
 * direction; directions of degree <= 3 are elevated exactly. The corners are interpolated, and at
 * each corner both tangent directions are the original's (λ > 0, weights > 0). out: 64 doubles,
 * must not overlap cpw. info may be NULL. */
void sw_lod_reduce_bicubic(int32_t deg_u, int32_t deg_v, const double *cpw, double out[64],
                           sw_lod_reduce_info *info);

/* The same for a rational curve of degree deg (1..SW_SG_MAX_DEGREE) with `dim` (2..4) doubles
 * per control point: out receives 4 * dim doubles (a rational cubic). */
void sw_lod_reduce_cubic_curve(int32_t deg, int32_t dim, const double *cpw, double *out,
                               sw_lod_reduce_info *info);

/* ---- leaf subdivision ------------------------------------------------------------------------ */
/* Zero-initialise for the defaults. */
typedef struct sw_lod_reduce_desc {
    double tolerance;        /* leaf error wanted (object or parameter units); must be > 0 */
    int32_t max_depth;       /* binary splits below the input at most; 0 = 12 */
    sw_lod_error_desc error; /* how tight the bound is computed */
} sw_lod_reduce_desc;

/* One node of the subdivision tree of a patch: the bicubic over `rect` (of the input's local
 * [0,1]^2) and its rigorous error bound against the input over rect. */
typedef struct sw_lod_reduce_node {
    int32_t depth;
    int32_t parent;    /* the handle the visitor returned for the parent; -1 at the top */
    int32_t leaf;      /* 1 when not split further */
    int32_t split_dir; /* 0 = u, 1 = v when not a leaf */
    double rect[4];    /* s0, s1, t0, t1 */
    const double *cpw; /* 64 doubles, valid during the call */
    double error;
    sw_lod_reduce_info info;
} sw_lod_reduce_node;

/* Called pre-order (a parent before its two children, the half at lower parameters first);
 * returns a handle >= 0 passed as `parent` to the children, or < 0 to stop (the tree walk then
 * returns SW_ERR_OUT_OF_MEMORY). */
typedef int32_t (*sw_lod_reduce_visit_fn)(void *ctx, const sw_lod_reduce_node *node);

/* Reduces the patch; wherever the bound exceeds desc->tolerance and the depth allows, halves the
 * piece along the direction whose degree reduction loses more (largest 4th difference) and
 * recurses. Errors: SW_ERR_OUT_OF_MEMORY (scratch, or the visitor stopped). */
sw_result sw_lod_reduce_tree(int32_t deg_u, int32_t deg_v, const double *cpw,
                             const sw_lod_reduce_desc *desc, sw_lod_reduce_visit_fn visit,
                             void *ctx, sw_status *status);

typedef struct sw_lod_bicubic_leaf {
    double rect[4]; /* s0, s1, t0, t1 in the input's local domain */
    double cpw[64];
    double error; /* rigorous bound of the distance to the input over rect */
} sw_lod_bicubic_leaf;

typedef struct sw_lod_leaf_set {
    sw_lod_bicubic_leaf *leaves;
    int32_t count, cap;
    int32_t over_tolerance; /* leaves left above the tolerance at max_depth */
} sw_lod_leaf_set;

/* The leaves of sw_lod_reduce_tree: bicubics whose rectangles tile [0,1]^2. *out is
 * zero-initialised by the call and owns its memory (sw_lod_leaf_set_free) also on failure.
 * Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw_lod_reduce_leaves(int32_t deg_u, int32_t deg_v, const double *cpw,
                               const sw_lod_reduce_desc *desc, sw_lod_leaf_set *out,
                               sw_status *status);
void sw_lod_leaf_set_free(sw_lod_leaf_set *set);

/* ---- trim curves (trim_cubic.c) -------------------------------------------------------------- */
typedef struct sw_lod_cubic_piece {
    double t0, t1;  /* in the source curve's parameter */
    double cpw[12]; /* rational cubic (w*u, w*v, w) over [t0, t1] */
    double error;   /* rigorous bound of the (u, v) distance to the source over [t0, t1] */
} sw_lod_cubic_piece;

typedef struct sw_lod_cubic_set {
    sw_lod_cubic_piece *pieces;
    int32_t count, cap;
    int32_t over_tolerance;
} sw_lod_cubic_set;

/* Approximates a validated 2D rational B-spline trim curve (dim 3) by rational cubic pieces: its
 * Bézier segments (knot insertion), each reduced (or elevated) and halved until its bound is within
 * desc->tolerance (parameter units). Pieces are in curve order and join continuously. *out is
 * zero-initialised by the call; free with sw_lod_cubic_set_free. Errors: SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INVALID_ARGUMENT (dim != 3). */
sw_result sw_lod_trim_curve_to_cubics(const sw_sg_curve *c, const sw_lod_reduce_desc *desc,
                                      sw_lod_cubic_set *out, sw_status *status);
void sw_lod_cubic_set_free(sw_lod_cubic_set *set);

/* Bézier segments of a B-spline curve by knot insertion: *cpw_out (n_seg * (degree+1) * dim) and
 * *breaks_out (n_seg + 1 parameters), both malloc'ed. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw_lod_curve_bezier_segments(const sw_sg_curve *c, double **cpw_out, double **breaks_out,
                                       int32_t *n_seg, sw_status *status);

/* ---- pairwise simplification (simplify.c, §6.2) ---------------------------------------------- */
typedef struct sw_lod_simplify_result {
    double cpw[64];  /* the one bicubic N over the union of both children */
    double error[2]; /* bound of |N - child k| over child k's part of N */
    sw_lod_reduce_info info;
} sw_lod_simplify_result;

/* Approximates two adjacent bicubics by one: c_lo covers [0, s] and c_hi [s, 1] of the result along
 * direction dir (0 = u, 1 = v), where s = Δt1 / (Δt1 + Δt2) from the children's parameter lengths
 * and 0 < s < 1; they span the same range in the other direction and share the edge between them.
 * λ0, λ1 come from the same least-squares problem as §6.1 with the subdivision matrix at s in
 * place of the elevation matrix. Errors: SW_ERR_OUT_OF_MEMORY (from the bound). */
sw_result sw_lod_simplify_pair(const double c_lo[64], const double c_hi[64], int dir, double s,
                               const sw_lod_error_desc *err, sw_lod_simplify_result *out,
                               sw_status *status);

/* Largest angle (radians) between the tangents across the shared edge of two adjacent rational
 * Bézier patches, lo (degrees du_lo, dv_lo) before hi along dir, at each control-point line of the
 * edge (lines of zero length skipped). Both must have the same degree in the other direction.
 * A crease (tangent discontinuity) of the exact surface, which no single bicubic can follow. */
double sw_lod_crease_angle(int32_t du_lo, int32_t dv_lo, const double *lo, int32_t du_hi,
                           int32_t dv_hi, const double *hi, int dir);

/* ---- internal: the G1 least-squares fit shared by reduction and simplification --------------- */
/* For each of n_lines lines, fits N~0 = S, N~1 = S + λ0 d0, N~2 = E + λ1 d1, N~3 = E to the m
 * targets T_i ~ sum_j gamma[i*4+j] N~_j (one λ pair for all lines), in homogeneous space centred at
 * the targets' box centre with the weight scaled by their radius; clamps λ to
 * [0.05 * nominal, weights stay >= 10% of the end weight]. ends: per line S, d0, E, d1 (4 * dim).
 * targets: per line m * dim. out: per line 4 * dim. */
void sw__lod_g1_fit(int32_t n_lines, int32_t m, int32_t dim, const double *targets,
                    const double *gamma, const double *ends, const double nominal[2], double *out,
                    double lambda[2], uint32_t *clamped);

#ifdef __cplusplus
}
#endif
#endif

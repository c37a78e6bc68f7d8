/* SPDX-License-Identifier: MIT */
/* splinewalk lod/ sampling bounds: how densely a rational Bézier patch must be sampled so that its
 * piecewise-linear grid stays within an object-space tolerance (the Filip et al. 1986 bound as used
 * by Guthe et al. 2005 §5.2), the object-space tolerance that a screen-space error ε_img allows at
 * a given depth (§7), and the trim-texture resolution that keeps a texel below that tolerance on
 * the surface (§5.3). The derivative bounds are rigorous for any degree and any positive weights;
 * the derivation is in sampling.c.
 *
 * All functions are pure and thread-safe.
 */
#ifndef SW_LOD_SAMPLING_H
#define SW_LOD_SAMPLING_H

#include "sw_module_abi.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Upper bounds of the derivatives' norms of a rational Bézier patch over its whole local domain
 * (s, t) in [0,1]^2 (derivatives with respect to the local parameters). */
typedef struct sw_lod_patch_bounds {
    double d1[2]; /* sup |S_s|, sup |S_t| */
    double d2[3]; /* sup |S_ss|, sup |S_st|, sup |S_tt| */
} sw_lod_patch_bounds;

/* Bounds the derivatives of the rational Bézier patch of degrees (deg_u, deg_v) >= 1 whose
 * homogeneous control points (w*x, w*y, w*z, w), u fastest, are cpw[(j*(deg_u+1)+i)*4].
 * Precondition: every weight > 0 and finite (validated geometry). */
SW_MODULE_ABI void sw_lod_rational_bezier_bounds(int32_t deg_u, int32_t deg_v, const double *cpw,
                                                 sw_lod_patch_bounds *out);

/* Segments needed along one direction of a patch's local domain so that the Filip bound of that
 * direction stays within eps/2 (Guthe §5.2): ceil(len * sqrt((M_dir + M_mixed) / (4 eps))),
 * at least 1 and at most max_segments. `len` (0..1] is the part of the local domain that is
 * sampled. eps <= 0 or a non-finite bound gives max_segments. */
int32_t sw_lod_filip_segments(double m_dir, double m_mixed, double len, double eps,
                              int32_t max_segments);

/* The Filip bound itself for a cell of local size (ds, dt): what a grid achieves. */
double sw_lod_filip_error(const sw_lod_patch_bounds *b, double ds, double dt);

/* Object-space tolerance that keeps a screen-space displacement within eps_px pixels at view
 * depth `depth` (> 0, along the view axis) for a perspective camera with focal length focal_px
 * (pixels: height / (2 tan(fovy/2))) and half-angle tangents tan_x, tan_y. The projection's
 * Jacobian at depth z has norm <= focal/z * sqrt(1 + tan_x^2 + tan_y^2) inside the frustum. */
double sw_lod_object_tolerance(double eps_px, double depth, double focal_px, double tan_x,
                               double tan_y);

/* Texels along a direction of a trim texture spanning `span` parameter units so that one texel
 * step moves the surface by at most eps (§5.3): span * d1 / (patch_len * eps), where d1 bounds the
 * derivative with respect to the local parameter of a patch of parameter length patch_len.
 * Returns a value >= 1 (not capped; may be +INF when eps <= 0). */
double sw_lod_trim_texels(double span, double d1, double patch_len, double eps);

/* ---- screen-space grid density (Guthe §5.2 and §7 in one bound; derivation in sampling.c) ---- */
/* The camera as the screen-space bound needs it. Control points are given relative to the eye. */
typedef struct sw_lod_screen_view {
    double right[3], up[3], fwd[3]; /* orthonormal camera basis, fwd = viewing direction */
    double focal_px;                /* pixels per unit of tangent: height / (2 tan(fovy/2)) */
    double tan_corner;              /* sqrt(tan_x^2 + tan_y^2): the frustum's corner tangent */
    double near_plane;              /* smallest depth drawn (> 0) */
    double eps_px;                  /* ε_img */
} sw_lod_screen_view;

typedef struct sw_lod_screen_density {
    int32_t nu, nv; /* grid segments over the range */
    double eps_obj; /* object-space tolerance at the range's nearest depth (isotropic §7 form,
                       for the trim-texture resolution) */
    double d1[2];   /* bounds of |S_s|, |S_t| over the range, local patch parameters */
} sw_lod_screen_density;

/* Grid segments (nu, nv), both from `allowed` (ascending, n_allowed >= 1), over the part
 * range = [s0,s1] x [t0,t1] of the local domain of a rational Bézier patch (homogeneous control
 * points relative to the eye, as in sw_lod_rational_bezier_bounds), with the fewest cells such
 * that every point of the grid's triangles (each cell split along a diagonal) projects within
 * eps_px of the patch point at the same parameters. Rigorous: Filip's bound per screen axis with
 * derivative bounds of the range (and of up to max_sub x max_sub sub-patches of it, max_sub
 * <= 4), nearest depth and largest off-axis tangent from control points. Returns 1, or 0 when no
 * allowed pair suffices (out->nu, nv = the largest allowed) or out of memory. */
int sw_lod_screen_segments(int32_t deg_u, int32_t deg_v, const double *cpw, const double range[4],
                           const sw_lod_screen_view *v, const int32_t *allowed, int32_t n_allowed,
                           int32_t max_sub, sw_lod_screen_density *out);
/* An affine part within the view's tolerance (sampling.c says when) takes the coarsest allowed
 * grid without the bound's sub-patch analysis: on (default) or off, for the A/B of benchmarks
 * and the test that compares both. Not thread-safe: set it before frames run. */
void sw_lod_screen_affine_fast(int on);
/* A range whose difference bounds already pass the coarsest allowed grid skips the
 * second-derivative Bernstein products (sampling.c, whole_measure): the same result, cheaper. On
 * (default) or off, for the test that compares both. Not thread-safe: set it before frames run. */
void sw_lod_screen_coarsest_fast(int on);

#ifdef __cplusplus
}
#endif
#endif

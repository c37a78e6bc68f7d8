/* SPDX-License-Identifier: MIT */
/* splinewalk geometry kernel: knot vectors, rational B-spline (NURBS) curves and surfaces of any
 * degree and dimension, evaluated in homogeneous form in double precision; knot insertion and
 * extraction into rational Bézier patches.
 *
 * Algorithms: Cox-de Boor basis functions (Piegl & Tiller, The NURBS Book, A2.2); derivatives
 * from differences of the span's poles times lower-degree basis values (derivative control points,
 * A3.3/A3.7), which stay accurate where knot spans of 1e-8 sit next to spans of 1 — the basis-
 * derivative form (A2.3) loses digits there (nurbs_eval.c); rational derivatives by the quotient
 * rule on the homogeneous form (A4.4), Boehm knot insertion (A5.1) and Bézier extraction by knot
 * refinement (A5.6). Guthe et al. 2005 §3 starts the
 * GPU pipeline from exactly these rational Bézier patches.
 *
 * Conventions shared by all functions below:
 *  - Control points are stored homogeneous: (w*x, w*y, w*z, w) for surfaces (dim = 4) and
 *    (w*u, w*v, w) for trim curves (dim = 3); the last coordinate is the weight.
 *  - A surface's control net is u-fastest: point (i, j) is at cpw[(j * n_u + i) * 4].
 *  - Knot spans are half-open [t_k, t_k+1) except the last non-empty one, which is closed, so the
 *    end parameter evaluates to the last control point of a clamped knot vector.
 *  - Nothing here allocates except where a function says so; callers size arrays with *_bound().
 */
#ifndef SW_SG_GEOM_H
#define SW_SG_GEOM_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_SG_MAX_DEGREE 31 /* larger degrees are rejected as invalid geometry */

/* The range validation admits, so that no product the evaluation and the bounds form
 * overflows or underflows. The largest of them is a coordinate times the square of the net's
 * weight ratio (the rational second-derivative bounds of lod/bezier/sampling.c, error_bound.c's
 * wratio), times a transform's scale and a focal length in pixels (< 1e6), and then squared
 * (distances, segment counts): with every factor within these limits that is at most (1e30 x 1e30 x
 * 1e30 x 1e6)^2 = 1e192, finite; homogeneous products w x and 1 / w stay normal doubles (1e130,
 * 1e100). Each is far beyond real data (the universe is ~1e30 mm across; OCCT's weights lie within
 * a factor 10 of each other); a weight of 1e-300 or a coordinate or transform entry of 1e308, which
 * passed before and then refined forever, is rejected with its position. */
#define SW_SG_COORD_MAX 1e30    /* |Euclidean coordinate| and |knot| of curves and surfaces */
#define SW_SG_WEIGHT_MIN 1e-100 /* each weight in [SW_SG_WEIGHT_MIN, SW_SG_WEIGHT_MAX] */
#define SW_SG_WEIGHT_MAX 1e100
#define SW_SG_WEIGHT_RATIO_MAX 1e15 /* largest / smallest weight of one curve or surface */
#define SW_SG_XFORM_MAX 1e30        /* |entry| of a node's 3 x 4 transform */

/* A rational B-spline curve in homogeneous form; pointers are borrowed. */
typedef struct sw_sg_curve {
    int32_t degree;
    int32_t n;           /* number of control points, >= degree + 1 */
    int32_t dim;         /* homogeneous dimension (3 for trim curves: w*u, w*v, w) */
    const double *knots; /* n + degree + 1, non-decreasing */
    const double *cpw;   /* n * dim */
} sw_sg_curve;

/* A rational B-spline (tensor-product) surface in homogeneous form; pointers are borrowed. */
typedef struct sw_sg_surface {
    int32_t deg_u, deg_v;
    int32_t n_u, n_v;      /* control points in u and in v */
    const double *knots_u; /* n_u + deg_u + 1 */
    const double *knots_v; /* n_v + deg_v + 1 */
    const double *cpw;     /* n_u * n_v * 4, u fastest */
} sw_sg_surface;

/* Value and derivatives of the Euclidean (projected) surface at one (u, v). */
typedef struct sw_sg_surface_d2 {
    double p[3];
    double du[3], dv[3];
    double duu[3], duv[3], dvv[3];
} sw_sg_surface_d2;

/* ---- validation -------------------------------------------------------------------------------
 * Checks degrees (1..SW_SG_MAX_DEGREE), counts, non-decreasing finite knots with a non-empty
 * domain, no interior knot of multiplicity > degree + 1, finite control points and strictly
 * positive finite weights. Returns SW_OK or SW_ERR_INVALID_GEOMETRY with the offending index in
 * `status` (may be NULL); `what` names the object in the message (e.g. "face 12"). */
SW_MODULE_ABI sw_result sw_sg_curve_validate(const sw_sg_curve *c, const char *what,
                                             sw_status *status);
SW_MODULE_ABI sw_result sw_sg_surface_validate(const sw_sg_surface *s, const char *what,
                                               sw_status *status);

/* ---- knot vectors ---------------------------------------------------------------------------- */
/* Parameter domain [knots[degree], knots[n]]. */
void sw_sg_knots_domain(const double *knots, int32_t degree, int32_t n, double *t0, double *t1);
/* Span index k with knots[k] <= t < knots[k+1], degree <= k < n; t is clamped into the domain
 * and the last span is closed (binary search). */
int32_t sw_sg_knots_find_span(const double *knots, int32_t degree, int32_t n, double t);
/* Basis functions and their derivatives up to order `nd` (<= degree) at t in span `span`:
 * ders[k * (degree + 1) + r] = d^k N_{span-degree+r}/dt^k. `ders` holds (nd+1)*(degree+1). */
void sw_sg_basis_ders(const double *knots, int32_t degree, int32_t span, double t, int32_t nd,
                      double *ders);

/* ---- evaluation ------------------------------------------------------------------------------ */
/* Homogeneous curve point and derivatives up to order nd (<= 2): out[k*dim + c]. */
void sw_sg_curve_eval_h(const sw_sg_curve *c, double t, int32_t nd, double *out);
/* Euclidean point of a rational curve (dim-1 coordinates). */
void sw_sg_curve_eval(const sw_sg_curve *c, double t, double *out);
/* Euclidean surface point only. */
SW_MODULE_ABI void sw_sg_surface_eval(const sw_sg_surface *s, double u, double v, double p[3]);
/* Euclidean point, first and second partial derivatives (quotient rule on the homogeneous form). */
SW_MODULE_ABI void sw_sg_surface_eval_d2(const sw_sg_surface *s, double u, double v,
                                         sw_sg_surface_d2 *out);
/* Homogeneous point and first derivatives: h[0..3] = S^w, h[4..7] = dS^w/du, h[8..11] = dS^w/dv. */
void sw_sg_surface_eval_h1(const sw_sg_surface *s, double u, double v, double h[12]);
/* From such an h: w^2 S_u and w^2 S_v (the derivatives of the rational surface scaled by w^2 > 0,
 * free of the division) and their cross product, the normal S_u x S_v scaled by w^4. */
void sw_sg_h1_tangents(const double h[12], double su[3], double sv[3], double n[3]);
/* 1 when the surface is an affine map of its parameters, S(u, v) = origin + u du + v dv, to
 * within 1e-12 of its control net's magnitude (planes, as CAD files store them, at any degree):
 * equal weights and every pole on the affine function at its Greville abscissae, which a B-spline
 * reproduces exactly (linear precision). Then fills origin, du, dv; else returns 0. */
int sw_sg_surface_affine(const sw_sg_surface *s, double origin[3], double du[3], double dv[3]);

/* ---- knot insertion and Bézier extraction ---------------------------------------------------- */
/* Number of distinct interior knots of a knot vector's domain + 1 = number of Bézier segments. */
int32_t sw_sg_knots_segment_count(const double *knots, int32_t degree, int32_t n);
/* Inserts t `times` times (Boehm). Output sizes: knots n+degree+1+times, cpw (n+times)*dim.
 * Precondition: multiplicity(t) + times <= degree + 1 and t inside the domain. */
void sw_sg_curve_insert_knot(const sw_sg_curve *c, double t, int32_t times, double *knots_out,
                             double *cpw_out);

/* One rational Bézier patch of a surface, in homogeneous form, u fastest:
 * cpw[(j * (deg_u + 1) + i) * 4], over the parameter rectangle [u0,u1] x [v0,v1] of the source. */
typedef struct sw_sg_bezier_patch {
    int32_t deg_u, deg_v;
    int32_t seg_u, seg_v; /* index of the knot span in u and in v (0-based, empty spans skipped) */
    double u0, u1, v0, v1;
    double *cpw; /* (deg_u+1)*(deg_v+1)*4, owned by the extraction result */
} sw_sg_bezier_patch;

typedef struct sw_sg_bezier_set {
    int32_t n_u, n_v;            /* segments in u and v; patch (a, b) is patches[b * n_u + a] */
    sw_sg_bezier_patch *patches; /* n_u * n_v */
    double *storage;             /* all control points, one allocation */
} sw_sg_bezier_set;

/* Number of doubles of control-point storage sw_sg_surface_extract_bezier needs. */
size_t sw_sg_surface_bezier_storage_bound(const sw_sg_surface *s);
/* Extracts every Bézier patch by knot refinement (every interior knot raised to full multiplicity).
 * On success *out owns its memory (free with sw_sg_bezier_set_free). Returns SW_OK or
 * SW_ERR_OUT_OF_MEMORY; the surface must have passed sw_sg_surface_validate. */
sw_result sw_sg_surface_extract_bezier(const sw_sg_surface *s, sw_sg_bezier_set *out,
                                       sw_status *status);
/* Same, restricted to the patches whose parameter rectangle meets [u0,u1] x [v0,v1] (the trim
 * region's box): patches entirely outside are never produced. */
sw_result sw_sg_surface_extract_bezier_in(const sw_sg_surface *s, double u0, double u1, double v0,
                                          double v1, sw_sg_bezier_set *out, sw_status *status);
SW_MODULE_ABI void sw_sg_bezier_set_free(sw_sg_bezier_set *set);

/* Evaluates a rational Bézier patch (Euclidean) at local parameters (s, t) in [0,1]^2. */
void sw_sg_bezier_patch_eval(const sw_sg_bezier_patch *p, double s, double t, double out[3]);

/* The uniform bicubic B-spline on a regular 4x4 control net (non-rational), local (s,t) in
 * [0,1]^2 — the patch type OpenSubdiv evaluates for regular Catmull-Clark faces. cp: 16*3, u
 * fastest. Also converts such a net to its Bézier form (16*3). */
void sw_sg_uniform_bicubic_eval(const double cp[48], double s, double t, double out[3]);
void sw_sg_uniform_bicubic_to_bezier(const double cp[48], double bez[48]);

#ifdef __cplusplus
}
#endif
#endif

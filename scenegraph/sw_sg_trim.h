/* SPDX-License-Identifier: MIT */
/* Trim loops: closing them bit-identically, flattening them into polylines, and classifying
 * parameter points by even-odd parity (the same rule the GPU's fan parity implements, Guthe et al.
 * 2005 §4).
 */
#ifndef SW_SG_TRIM_H
#define SW_SG_TRIM_H

#include "sw_module_abi.h"

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Snaps a loop of curves closed in place: the end control point of each curve and the start of the
 * next (the last's end and the first's start) are set to one shared Euclidean point (their
 * midpoint), stored with each curve's own weight. Gaps larger than `max_gap` (parameter units) are
 * reported as SW_ERR_INVALID_GEOMETRY, `what` naming the face. cpw[k] points at curve k's
 * homogeneous control points (n[k] * 3 doubles), mutable. */
SW_MODULE_ABI sw_result sw_sg_trim_snap_loop(int32_t n_curves, double *const *cpw, const int32_t *n,
                                             double max_gap, const char *what, sw_status *status);

/* A loop flattened to a closed polyline in (u, v): vertex 0 is the loop's first join point; the
 * closing vertex is not repeated. Every join point is the Euclidean image of the curve's first
 * control point, so adjacent curves share bit-identical vertices. */
typedef struct sw_sg_polyline {
    double *uv; /* 2 * count */
    uint32_t count;
    /* Counted fallbacks of sw_sg_trim_flatten_loop (0 elsewhere), where a chord may be farther
     * than the requested tol from its curve: */
    uint32_t below_floor;  /* curves whose tol was raised to the rounding floor of their data */
    uint32_t depth_capped; /* pieces emitted unflat at the depth cap */
} sw_sg_polyline;

/* Flattens loop `loop` so that every chord is within `tol` (parameter units) of the curve, using a
 * bound from the control polygon (a subdivided segment is emitted when its control points lie
 * within tol of its chord). Allocates out->uv (free with sw_sg_polyline_free).
 * Bounded whatever tol and the data (trim.c's header): tol is raised to a floor of 64 ulps of each
 * curve's largest coordinate (64 DBL_EPSILON max |u|, |v| of its control points) and subdivision
 * stops at the depth its control polygon's length needs (at most 40); out->below_floor and
 * out->depth_capped count where that happened (0: every chord within tol). The work is at most
 * about max_vertices x 40 subdivisions.
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (more than `max_vertices`), SW_ERR_INVALID_GEOMETRY
 * (a curve that is not a clamped 2D curve: its first vertex would not be its first control point).
 */
SW_MODULE_ABI sw_result sw_sg_trim_flatten_loop(const sw_sg_scene *scene, uint32_t loop, double tol,
                                                uint32_t max_vertices, sw_sg_polyline *out,
                                                sw_status *status);
SW_MODULE_ABI void sw_sg_polyline_free(sw_sg_polyline *p);

/* Even-odd classification of (u, v) against a set of closed polylines: 1 inside, 0 outside. */
int sw_sg_trim_classify(const sw_sg_polyline *loops, uint32_t n_loops, double u, double v);

#ifdef __cplusplus
}
#endif
#endif

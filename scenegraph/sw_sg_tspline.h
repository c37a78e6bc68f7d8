/* SPDX-License-Identifier: MIT */
/* splinewalk T-splines: bicubic rational T-spline surfaces (point-based splines whose blending
 * functions come from a T-mesh), their direct evaluation, Krishnamurthy & Yasui's region
 * decomposition with binary-search lookup, and extraction into rational bicubic Bézier patches
 * that feed the same pipeline as NURBS faces (Guthe et al. 2005 §3).
 *
 * Sources:
 *  - Sederberg, Zheng, Bakenov, Nasri 2003, "T-splines and T-NURCCs", §2-§3: every control point
 *    P_i (weight w_i) carries local knot vectors s_i[0..4], t_i[0..4], inferred from the T-mesh by
 *    casting rays from the point's anchor (tspline_io.c); S(u,v) = sum w_i P_i B_i / sum w_i B_i,
 *    B_i(u,v) = N[s_i](u) N[t_i](v), N the cubic B-spline on five knots.
 *  - Sederberg et al. 2004, "T-spline simplification and local refinement": a blending function
 *    is refined by inserting knots into its local knot vectors; inserting the edges of a region
 *    to full multiplicity (Boehm) gives its Bernstein coefficients there (tspline_bezier.c).
 *  - Krishnamurthy & Yasui, "Efficient rendering of NURBS and T-spline surfaces", T-splines
 *    evaluation: the domain is split into rectangular regions, each with the list of control
 *    points that influence it; a parameter finds its region by binary search.
 *
 * Conventions: control points are homogeneous (w*x, w*y, w*z, w) as in sw_sg_geom.h; knot spans
 * are half-open except at the domain's upper ends, which are closed (the left limit is taken).
 * A finished T-spline is immutable and may be read from any thread.
 */
#ifndef SW_SG_TSPLINE_H
#define SW_SG_TSPLINE_H

#include "sw_sg_geom.h"
#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_SG_TSPLINE_MAX_POINTS (1u << 20)
/* Cells of the grid of distinct knot values inside the domain (regions are unions of cells). */
#define SW_SG_TSPLINE_MAX_CELLS (1u << 22)
/* Sum over control points of the cells their supports cover (work and memory of the regions). */
#define SW_SG_TSPLINE_MAX_SUPPORT_CELLS (1u << 25)

/* A T-spline given point by point (pointers borrowed for the call only). */
typedef struct sw_sg_tspline_desc {
    uint32_t n_points;     /* 1 .. SW_SG_TSPLINE_MAX_POINTS */
    const double *cpw;     /* n_points * 4, homogeneous, weights > 0 */
    const double *knots_u; /* n_points * 5: local knot vector in u, non-decreasing, [0] < [4] */
    const double *knots_v; /* n_points * 5 */
    double domain[4];      /* u0, u1, v0, v1 with u0 < u1, v0 < v1 */
} sw_sg_tspline_desc;

typedef struct sw_sg_tspline sw_sg_tspline; /* opaque, immutable once created */

/* One region of Krishnamurthy's decomposition: every blending function is one polynomial on it;
 * points [first, first + count) of the region point list influence it. */
typedef struct sw_sg_tspline_region {
    double u0, u1, v0, v1;
    uint32_t first, count;
} sw_sg_tspline_region;

/* Read-only view (borrowed; valid until sw_sg_tspline_free). */
typedef struct sw_sg_tspline_view {
    uint32_t n_points;
    const double *cpw, *knots_u, *knots_v; /* as in the desc, owned copies */
    double domain[4];
    uint32_t n_bu, n_bv; /* sorted distinct region boundaries inside the domain, ends included */
    const double *bu, *bv;
    const uint32_t *cell_region; /* (n_bu - 1) * (n_bv - 1), u fastest: region of each cell */
    uint32_t n_regions;
    const sw_sg_tspline_region *regions;
    const uint32_t *region_points;
} sw_sg_tspline_view;

/* Validates the desc (finite values, weights > 0, knot vectors non-decreasing with a non-empty
 * support, a non-empty finite domain) and builds the region decomposition. `what` names the
 * T-spline in messages (NULL: "T-spline"). Errors: SW_ERR_INVALID_GEOMETRY (bad values, or a
 * region of the domain that no blending function covers), SW_ERR_LIMIT (more points, cells or
 * support cells than the SW_SG_TSPLINE_MAX_* limits), SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_tspline_create(const sw_sg_tspline_desc *desc, const char *what,
                               sw_sg_tspline **out, sw_status *status);
void sw_sg_tspline_free(sw_sg_tspline *ts); /* NULL allowed */
const sw_sg_tspline_view *sw_sg_tspline_view_ptr(const sw_sg_tspline *ts);

/* The cubic B-spline on the five knots k[0..4] at t; `closed_right` takes the left limit (used at
 * the upper end of the domain). Zero outside [k0, k4]. */
double sw_sg_tspline_basis(const double k[5], double t, int closed_right);
/* Non-rational blending function B_i(u, v) of point i (< n_points), with the domain's convention
 * at its upper ends. */
double sw_sg_tspline_blend(const sw_sg_tspline *ts, uint32_t i, double u, double v);

/* Direct evaluation: the sum over every control point (O(n), the reference). (u, v) is clamped
 * into the domain. */
void sw_sg_tspline_eval_direct(const sw_sg_tspline *ts, double u, double v, double p[3]);
/* Region of (u, v) by binary search over the sorted boundaries; (u, v) is clamped. */
uint32_t sw_sg_tspline_find_region(const sw_sg_tspline *ts, double u, double v);
/* Evaluation through the region's point list (Krishnamurthy & Yasui). */
void sw_sg_tspline_eval(const sw_sg_tspline *ts, double u, double v, double p[3]);

/* ---- Bézier extraction (tspline_bezier.c) ---------------------------------------------------- */
/* One rational bicubic Bézier patch per region; patches[r].u0..v1 is region r's rectangle in the
 * T-spline's parameters; seg_u / seg_v hold the index of its first cell in u and v. */
typedef struct sw_sg_tspline_bezier {
    uint32_t n_patches;
    sw_sg_bezier_patch *patches;
    double *storage; /* all control points, one allocation */
} sw_sg_tspline_bezier;

/* Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_INVALID_GEOMETRY (a patch weight <= 0: the blending
 * functions vanish somewhere in a region). On failure *out is zeroed. */
sw_result sw_sg_tspline_extract_bezier(const sw_sg_tspline *ts, sw_sg_tspline_bezier *out,
                                       sw_status *status);
void sw_sg_tspline_bezier_free(sw_sg_tspline_bezier *bz); /* NULL allowed */

/* Adds the T-spline as a group node `name` (may be NULL) under `parent` with transform `xform`
 * (NULL = identity) and colour (NULL = inherit), holding one SURFACE node per Bézier patch. Each
 * patch becomes a face of degree 3x3 with 4x4 control points and clamped knot vectors
 * [u0 u0 u0 u0 u1 u1 u1 u1] (the region's own parameters, so face (u, v) = T-spline (u, v)), kind
 * SW_SG_KIND_BEZIER, untrimmed; patches sharing an edge are recorded as adjacent. *node_out (may
 * be NULL) receives the group. Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_INVALID_GEOMETRY. */
sw_result sw_sg_tspline_add_to_builder(sw_sg_builder *b, const sw_sg_tspline *ts, uint32_t parent,
                                       const double xform[12], const float color[4],
                                       const char *name, uint32_t *node_out, sw_status *status);

/* ---- the .tsm text format (tspline_io.c, docs/tspline-format.md) ----------------------------- */
typedef struct sw_sg_tsm_doc sw_sg_tsm_doc; /* a parsed, not yet validated file */

/* Step 1, syntax: tokens, counts, finite numbers, integer fields, size limits. `name` (the path,
 * NULL: "<memory>") prefixes every message as "name:line: ...". Errors: SW_ERR_FORMAT (garbage,
 * a wrong count of fields or records, a non-finite number, a count beyond the format's limits),
 * SW_ERR_TRUNCATED (the text ends before `end`), SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_tsm_parse(const char *text, size_t len, const char *name, sw_sg_tsm_doc **out,
                          sw_status *status);
/* Step 2, meaning: knots non-decreasing, weights > 0, edges and anchors inside the index grid,
 * anchors on T-mesh vertices, local knot vectors by ray casting (Sederberg 2003 §3), then
 * sw_sg_tspline_create. Errors: SW_ERR_INVALID_GEOMETRY (with name:line), SW_ERR_LIMIT,
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_tsm_validate(const sw_sg_tsm_doc *doc, sw_sg_tspline **out, sw_status *status);
void sw_sg_tsm_doc_free(sw_sg_tsm_doc *doc); /* NULL allowed */

/* Parse + validate text in memory, or a file (SW_ERR_NOT_FOUND, SW_ERR_IO besides the above). */
sw_result sw_sg_tspline_load_mem(const char *text, size_t len, const char *name,
                                 sw_sg_tspline **out, sw_status *status);
sw_result sw_sg_tspline_load(const char *path, sw_sg_tspline **out, sw_status *status);

/* Loads a .tsm file and adds it under `parent` of a builder (sw_sg_tspline_add_to_builder, named
 * after the file). */
sw_result sw_sg_tspline_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                                    const char *path, sw_status *status);
/* Loads a .tsm file into a new scene (the CLI's `import` of .tsm files). */
sw_result sw_sg_tspline_import_file(const char *path, sw_sg_scene **out, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

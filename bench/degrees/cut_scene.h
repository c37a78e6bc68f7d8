/* bench/degrees: scenes the GPU frame path (sw_gpu_render_scene) draws for one frame of the
 * animated surface.
 *
 * - The source scene: the degree-d surface as one face, trimmed by the rational cubic
 *   approximation of its trim loop (Guthe et al. 2005 §4.1), one clamped cubic Bézier curve per
 *   piece. The frame path draws it as it is (degree > 3: CPU grids) — the "direct" comparison —
 *   and flattens its loop for the cut scene.
 * - The cut scene: the hierarchy's nodes selected for the view (§7: the coarsest representable
 *   node whose error is within the approximation's share of ε_img at its nearest depth), each a
 *   bicubic face over its rectangle (knots u0^4 u1^4, v0^4 v1^4, so the face's parameters are the
 *   surface's), trimmed by the flattened loop clipped to that rectangle: a node outside the loop is
 *   left out, one inside it is untrimmed. Clipping per face keeps each face's trim loop and fat
 *   borders (§7.1) within its own domain; the clipped loop runs along the rectangle's edges where
 *   the region continues into a neighbour, so the fat borders also close the cracks between
 *   neighbouring bicubics.
 */
#ifndef BD_CUT_SCENE_H
#define BD_CUT_SCENE_H

#include "animated.h"
#include "sw_lod_hierarchy.h"
#include "sw_lod_reduce.h"
#include "sw_sg_scene.h"
#include "sw_sg_trim.h"

/* uv_box: the trim region's box (contains the loop). Errors: the builder's. */
sw_result bd_source_scene(const sw_sg_surface *s, const sw_lod_cubic_set *loop,
                          const double uv_box[4], sw_sg_scene **out, sw_status *status);

/* Largest |S_u|, |S_v| over the hierarchy's representable leaves, from their derivative constants
 * (tex_c over the leaf's local [0,1]^2, divided by its extent): a trim-curve error of e in (u, v)
 * moves the surface point by at most this times e. */
double bd_max_parametric_speed(const sw_lod_hierarchy *h);

/* The view's cut: node indices into *nodes (malloc'ed, caller frees), *n of them; *over counts
 * leaves drawn although above their tolerance. tol_px: the surface approximation's share of
 * ε_img. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result bd_select_cut(const sw_lod_hierarchy *h, const bd_screen *screen, double tol_px,
                        int32_t **nodes, int32_t *n, int32_t *over, sw_status *status);

typedef struct bd_cut_counts {
    int32_t trimmed, untrimmed, outside; /* faces made, and cut nodes left out */
    double area_drawn, area_loop; /* (u, v) area of the faces' trimmed regions, and of the loop's:
                                     equal when the cut tiles the loop and the clipping is right */
} bd_cut_counts;

/* The cut scene of nodes[0..n) trimmed by the closed polyline `loop`. Errors: SW_ERR_OUT_OF_MEMORY,
 * the builder's. */
sw_result bd_cut_scene(const sw_lod_hierarchy *h, const int32_t *nodes, int32_t n,
                       const sw_sg_polyline *loop, sw_sg_scene **out, bd_cut_counts *counts,
                       sw_status *status);

#endif

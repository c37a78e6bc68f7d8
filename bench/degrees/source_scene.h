/* SPDX-License-Identifier: MIT */
/* bench/degrees: the scene the GPU frame path (sw_gpu_render_scene) draws for one frame of the
 * animated surface — the degree-d surface as one face, trimmed by the rational cubic
 * approximation of its trim loop (Guthe et al. 2005 §4.1), one clamped cubic Bézier curve per
 * piece — and the bound that turns the trim approximation's share of ε_img into a (u, v)
 * tolerance. The frame draws the face through its bicubic hierarchy (desc.hierarchies) or, for
 * comparison, as it is.
 */
#ifndef BD_SOURCE_SCENE_H
#define BD_SOURCE_SCENE_H

#include "sw_lod_reduce.h"
#include "sw_sg_scene.h"

/* uv_box: the trim region's box (contains the loop). Errors: the builder's. */
sw_result bd_source_scene(const sw_sg_surface *s, const sw_lod_cubic_set *loop,
                          const double uv_box[4], sw_sg_scene **out, sw_status *status);

/* An upper bound of the surface's parametric speed over uv_box: a move of the parameters by
 * (du, dv) moves the surface point by at most the result times |(du, dv)| (Cauchy-Schwarz over
 * sup |S_u|, sup |S_v| of the Bézier patches meeting the box, lod/bezier/sampling.c's rigorous
 * bounds). Returns 0 when out of memory. */
double bd_parametric_speed(const sw_sg_surface *s, const double uv_box[4]);

#endif

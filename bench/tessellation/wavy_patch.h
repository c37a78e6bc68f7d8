/* SPDX-License-Identifier: MIT */
/* bench/tessellation: the benchmark's patch (one wavy rational bicubic Bézier patch over
 * [-1,1]^2, weights 0.5-2) and its camera fitted to a screen width, shared by bench_tessellation
 * and bench_bound_chain. */
#ifndef BT_WAVY_PATCH_H
#define BT_WAVY_PATCH_H

#include "sw_gpu.h"
#include "sw_sg_geom.h"
#include "sw_sg_scene.h"

extern const double bt_wavy_knots[8]; /* clamped cubic, [0,1] */

/* Homogeneous control points, u fastest, world space. */
void bt_wavy_cpw(double cpw[64]);
sw_sg_surface bt_wavy_surface(const double cpw[64]);
/* A scene of the untrimmed patch (one face, one node). */
sw_result bt_wavy_scene(const double cpw[64], sw_sg_scene **out, sw_status *status);
/* The benchmark's camera looking at the origin from `dist` (fovy 40 degrees). */
sw_gpu_camera bt_wavy_camera_at(double dist);
/* Camera distance at which the patch is `px` pixels across in a width x height frame; *got is
 * the width reached. */
double bt_wavy_fit_distance(const double cpw[64], double px, int32_t width, int32_t height,
                            double *got);

#endif

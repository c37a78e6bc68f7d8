/* SPDX-License-Identifier: MIT */
/* bench/degrees: the benchmark's input (Guthe et al. 2005 §9, Fig. 10) — a 10 x 10 rational
 * B-spline surface of degree d x d whose control points and weights move with a sine, trimmed by
 * one closed degree-d loop of 10 control points — its fixed camera, and the object-space
 * tolerance that keeps a displacement within a number of pixels at that camera.
 */
#ifndef BD_ANIMATED_H
#define BD_ANIMATED_H

#include "sw_gpu.h"
#include "sw_sg_geom.h"

enum { BD_N = 10, BD_MAX_DEGREE = 7 };

/* Clamped uniform knots of BD_N control points: BD_N + d + 1 values. */
void bd_clamped_knots(int d, double *knots);

/* Frame f of an animation of `period` frames: BD_N x BD_N homogeneous control points, u fastest.
 * The sheet spans x, y in [0, 9], z in [-2, 2]. */
void bd_animate(int f, int period, double *cpw);

/* The trim loop of degree d: a periodic (uniform, unclamped) curve of BD_N + d control points
 * (the first d repeated) around a wobbly circle in the domain's centre; box = its control points'
 * (u0, u1, v0, v1), which contains the curve. knots: BD_N + 2d + 1, cpw: 3 (BD_N + d). */
typedef struct bd_trim_loop {
    double knots[BD_N + 2 * BD_MAX_DEGREE + 1];
    double cpw[3 * (BD_N + BD_MAX_DEGREE)];
    double box[4];
    sw_sg_curve curve; /* points into knots, cpw */
} bd_trim_loop;
void bd_trim_loop_init(int d, bd_trim_loop *loop);

/* The fixed camera: an oblique view of the sheet's centre. */
sw_gpu_camera bd_camera(void);

/* Object-space tolerance per pixel. A point P at view depth z_P, image in the frame, moved by d to
 * Q at depth z_Q moves on screen by f_px |d_z (x_P, y_P) / z_P - (d_x, d_y)| / z_Q
 * <= f_px sqrt(1 + T^2) |d| / z_Q pixels (Cauchy-Schwarz), T the tangent of the frame corner's
 * angle off the view axis and f_px the focal length in pixels. */
typedef struct bd_screen {
    double eye[3], fwd[3];
    double k; /* f_px sqrt(1 + T^2): pixels per object unit at depth 1, at most */
} bd_screen;
void bd_screen_init(bd_screen *s, const sw_gpu_camera *cam, int32_t width, int32_t height);
/* Smallest view depth over the corners of box (min xyz, max xyz). */
double bd_screen_min_depth(const bd_screen *s, const double box[6]);
/* Object distance that moves a point at depth >= z by at most px pixels (0 when z <= 0). */
static inline double bd_screen_tolerance(const bd_screen *s, double z, double px)
{
    return z > 0.0 ? px * z / s->k : 0.0;
}

#endif

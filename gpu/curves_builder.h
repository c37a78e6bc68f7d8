/* SPDX-License-Identifier: MIT */
/* gpu/ private: the piece builder the outline splitting shares between curves_split.c (lines,
 * conics, Hermite approximation, the shape) and curves_cubic.c (integral cubics, Loop & Blinn
 * 2005 §4). Never installed. */
#ifndef SW_GPU_CURVES_BUILDER_H
#define SW_GPU_CURVES_BUILDER_H

#include "sw_curves.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define MAX_SPLIT_DEPTH 20
#define MAX_TURN (100.0 * M_PI / 180.0) /* a piece's control polygon turns at most this much */

typedef struct builder {
    sw__curves_piece *p;
    size_t n, cap;
    double (*corners)[2];
    size_t n_corners, cap_corners;
    double tol;   /* approximation tolerance, model units */
    double bound; /* largest bound met */
    uint32_t n_approx;
    uint32_t loop;
    int approx; /* pieces emitted now come from an approximation */
    sw_result err;
    sw_status *status;
} builder;

/* curves_split.c */
double sw__cb_cross2(const double a[2], const double b[2]);
/* Records a corner of the outline (b->corners; out of memory sets b->err). */
void sw__cb_add_corner(builder *b, const double pt[2]);
/* A new piece at the end of b->p (NULL when out of memory: b->err set). */
sw__curves_piece *sw__cb_new_piece(builder *b);
/* The piece's signs: from F at the chord's midpoint and grad F at the curve's midpoint mid
 * (tangent dmid) against the left normal (loops counter-clockwise). */
void sw__cb_orient(sw__curves_piece *p, const double mid[2], const double dmid[2]);
void sw__cb_emit_line(builder *b, const double a[2], const double e[2]);
/* A rational quadratic (weights w) as exact conic pieces. */
void sw__cb_emit_conic(builder *b, const double q[3][2], const double w[3], int depth);
/* Total absolute turning angle of a control polygon; *convex: it never turns both ways. */
double sw__cb_polygon_turn(const double (*cp)[2], int n, int *convex);
/* Largest distance of the control points from the chord's line, relative to the chord. */
double sw__cb_flatness(const double (*cp)[2], int n);

/* curves_cubic.c: an integral cubic Bézier as exact Loop-Blinn pieces, split at its special
 * points. */
void sw__cb_emit_cubic(builder *b, const double q[4][2]);

#endif

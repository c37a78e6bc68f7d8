/* SPDX-License-Identifier: MIT */
/* The sources of the sample T-splines in samples/tsplines/ (written by make_tspline_samples.c),
 * shared with the tests that check the samples against them.
 *
 * local_refinement.tsm: the rational bicubic NURBS below with one knot (LR_NEW_KNOT) inserted into
 * its first row of control points only (Sederberg et al. 2003 §6 / 2004 §3: a single control point
 * inserted, the row refined by Boehm's algorithm, a T-junction where the new vertical edge ends).
 */
#ifndef TSPLINE_SAMPLES_H
#define TSPLINE_SAMPLES_H

#include "sw_sg_geom.h"

#include <math.h>

enum { LR_NU = 6, LR_NV = 5 };
#define LR_NEW_KNOT 0.7

static const double lr_knots_u[LR_NU + 4] = {0, 0, 0, 0, 0.3, 1.1, 2, 2, 2, 2};
static const double lr_knots_v[LR_NV + 4] = {0, 0, 0, 0, 0.6, 1.5, 1.5, 1.5, 1.5};

/* Homogeneous control net of the source NURBS, u fastest (deterministic, rational). */
static inline void lr_source_cpw(double cpw[LR_NU * LR_NV * 4])
{
    for (int j = 0; j < LR_NV; j++) {
        for (int i = 0; i < LR_NU; i++) {
            double *p = cpw + (j * LR_NU + i) * 4;
            const double x = 0.4 * i + 0.05 * sin(1.7 * j), y = 0.35 * j + 0.04 * cos(2.3 * i);
            const double z = 0.3 * sin(1.3 * i + 0.4) * cos(0.9 * j) + 0.1 * (i == 2 && j == 0);
            const double w = 1.0 + 0.6 * sin(0.9 * i + 1.4 * j + 0.3) * (j < 3 ? 1.0 : 0.5);
            p[0] = x * w, p[1] = y * w, p[2] = z * w, p[3] = w;
        }
    }
}

static inline sw_sg_surface lr_source_surface(const double *cpw)
{
    sw_sg_surface s = {3, 3, LR_NU, LR_NV, lr_knots_u, lr_knots_v, cpw};
    return s;
}

#endif

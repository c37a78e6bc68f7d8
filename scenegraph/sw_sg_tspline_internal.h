/* SPDX-License-Identifier: MIT */
/* Internal helpers shared by the T-spline files (tspline.c, tspline_bezier.c); never installed. */
#ifndef SW_SG_TSPLINE_INTERNAL_H
#define SW_SG_TSPLINE_INTERNAL_H

/* Bernstein coefficients on [a, b] of the cubic B-spline on the local knots k[0..4].
 * Precondition: k0 <= a < b <= k4 and no knot of k strictly inside (a, b). */
void sw__tspline_bernstein(const double k[5], double a, double b, double out[4]);

#endif

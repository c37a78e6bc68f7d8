/* SPDX-License-Identifier: MIT */
/* The uniform bicubic B-spline patch of a regular 4x4 control net: the patch OpenSubdiv evaluates
 * for regular Catmull-Clark faces, and the form Guthe et al. 2005 §6 approximates patches with
 * (bi-cubic hierarchy). Evaluated with the uniform cubic basis, converted to Bézier form with the
 * classical change of basis b0 = (P0+4P1+P2)/6, b1 = (2P1+P2)/3, b2 = (P1+2P2)/3,
 * b3 = (P1+4P2+P3)/6 applied in u, then in v.
 */
#include "sw_sg_geom.h"

#include <string.h>

/* Uniform cubic B-spline basis at local t in [0,1]. */
static void uniform_cubic_basis(double t, double b[4])
{
    const double s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    b[0] = s * s * s / 6.0;
    b[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
    b[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
    b[3] = t3 / 6.0;
}

void sw_sg_uniform_bicubic_eval(const double cp[48], double s, double t, double out[3])
{
    double bu[4], bv[4];
    uniform_cubic_basis(s, bu);
    uniform_cubic_basis(t, bv);
    out[0] = out[1] = out[2] = 0.0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            const double w = bu[i] * bv[j];
            for (int c = 0; c < 3; c++)
                out[c] += w * cp[(j * 4 + i) * 3 + c];
        }
}

/* B-spline to Bézier change of basis on 4 points of 3 doubles with the given stride. */
static void cubic_to_bezier(const double *in, int stride, double *out)
{
    for (int c = 0; c < 3; c++) {
        const double p0 = in[c], p1 = in[stride + c], p2 = in[2 * stride + c];
        const double p3 = in[3 * stride + c];
        out[c] = (p0 + 4.0 * p1 + p2) / 6.0;
        out[stride + c] = (2.0 * p1 + p2) / 3.0;
        out[2 * stride + c] = (p1 + 2.0 * p2) / 3.0;
        out[3 * stride + c] = (p1 + 4.0 * p2 + p3) / 6.0;
    }
}

void sw_sg_uniform_bicubic_to_bezier(const double cp[48], double bez[48])
{
    double tmp[48];
    for (int j = 0; j < 4; j++)
        cubic_to_bezier(cp + j * 12, 3, tmp + j * 12);
    for (int i = 0; i < 4; i++)
        cubic_to_bezier(tmp + i * 3, 12, bez + i * 3);
}

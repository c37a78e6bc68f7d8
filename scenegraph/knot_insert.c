/* SPDX-License-Identifier: MIT */
/* Boehm knot insertion into a rational B-spline curve in homogeneous form (The NURBS Book A5.1).
 *
 * Inserting a knot changes the basis, not the curve; it is the primitive behind Bézier extraction
 * (Guthe et al. 2005 §3 renders the rational Bézier patches obtained by raising every interior
 * knot to full multiplicity). The affected control points are recomputed one coordinate at a time
 * so any homogeneous dimension works with a fixed stack array of SW_SG_MAX_DEGREE + 1 doubles.
 */
#include "sw_sg_geom.h"

#include <assert.h>
#include <string.h>

/* Largest k with knots[k] <= t among knots[0..m-1], t inside [knots[0], knots[m-1]). */
static int32_t last_index_le(const double *knots, int32_t m, double t)
{
    int32_t lo = 0, hi = m; /* knots[lo] <= t < knots[hi] (hi == m: past the end) */
    while (hi - lo > 1) {
        int32_t mid = lo + (hi - lo) / 2;
        if (t < knots[mid])
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

void sw_sg_curve_insert_knot(const sw_sg_curve *c, double t, int32_t times, double *knots_out,
                             double *cpw_out)
{
    assert(c && knots_out && cpw_out && times >= 0 && c->degree <= SW_SG_MAX_DEGREE);
    const int32_t p = c->degree, n = c->n, dim = c->dim, m = n + p + 1;
    const double *up = c->knots;
    const size_t sd = (size_t)dim;
    if (times == 0) {
        memcpy(knots_out, up, sizeof(double) * (size_t)m);
        memcpy(cpw_out, c->cpw, sizeof(double) * (size_t)n * sd);
        return;
    }
    const int32_t k = last_index_le(up, m, t);
    int32_t s = 0;
    for (int32_t i = k; i >= 0 && up[i] == t; i--)
        s++;
    assert(s + times <= p + 1 && k < m - 1 && up[k + 1] > t);

    /* New knot vector. */
    for (int32_t i = 0; i <= k; i++)
        knots_out[i] = up[i];
    for (int32_t i = 1; i <= times; i++)
        knots_out[k + i] = t;
    for (int32_t i = k + 1; i < m; i++)
        knots_out[i + times] = up[i];

    /* Unchanged control points at both ends. */
    for (int32_t i = 0; i <= k - p; i++)
        memcpy(cpw_out + (size_t)i * sd, c->cpw + (size_t)i * sd, sizeof(double) * sd);
    for (int32_t i = k - s; i < n; i++)
        memcpy(cpw_out + (size_t)(i + times) * sd, c->cpw + (size_t)i * sd, sizeof(double) * sd);

    double rw[SW_SG_MAX_DEGREE + 1];
    for (int32_t d = 0; d < dim; d++) {
        for (int32_t i = 0; i <= p - s; i++)
            rw[i] = c->cpw[(size_t)(k - p + i) * sd + (size_t)d];
        int32_t l = k - p;
        for (int32_t j = 1; j <= times; j++) {
            l = k - p + j;
            for (int32_t i = 0; i <= p - j - s; i++) {
                const double alpha = (t - up[l + i]) / (up[i + k + 1] - up[l + i]);
                rw[i] = alpha * rw[i + 1] + (1.0 - alpha) * rw[i];
            }
            cpw_out[(size_t)l * sd + (size_t)d] = rw[0];
            /* Raising the multiplicity from degree to degree + 1 only duplicates a point. */
            const int32_t last = p - j - s >= 0 ? p - j - s : 0;
            cpw_out[(size_t)(k + times - j - s) * sd + (size_t)d] = rw[last];
        }
        for (int32_t i = l + 1; i < k - s; i++)
            cpw_out[(size_t)i * sd + (size_t)d] = rw[i - l];
    }
}

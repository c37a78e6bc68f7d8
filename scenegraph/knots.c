/* SPDX-License-Identifier: MIT */
/* Knot vectors: parameter domain, span search and B-spline basis functions with derivatives.
 *
 * Span search is The NURBS Book's A2.1 (binary search, last non-empty span closed); the basis
 * functions and their derivatives are A2.2/A2.3 (Cox-de Boor triangle, then derivatives from its
 * lower half). Everything lives in fixed stack arrays sized by SW_SG_MAX_DEGREE + 1, so evaluation
 * never allocates. Guthe et al. 2005 §3 and §4.2 start from surfaces evaluated this way.
 * The derivative rows are ~ (degree / knot span)^k large and cancel when contracted with poles, so
 * in short spans they lose accuracy to the poles' magnitude: nurbs_eval.c differences the poles
 * instead and keeps only the Cox-de Boor triangle; this function serves callers that need N^(k).
 */
#include "sw_sg_geom.h"

#include <assert.h>

#define SW__P1 (SW_SG_MAX_DEGREE + 1)

void sw_sg_knots_domain(const double *knots, int32_t degree, int32_t n, double *t0, double *t1)
{
    assert(knots && degree >= 0 && n > degree);
    if (t0)
        *t0 = knots[degree];
    if (t1)
        *t1 = knots[n];
}

int32_t sw_sg_knots_find_span(const double *knots, int32_t degree, int32_t n, double t)
{
    assert(knots && degree >= 0 && n > degree);
    const double t0 = knots[degree], t1 = knots[n];
    /* `!(t > t0)` also sends NaN to the start of the domain. */
    if (!(t > t0))
        t = t0;
    if (t >= t1) {
        /* The last non-empty span is closed at its right end. */
        int32_t k = n - 1;
        while (k > degree && !(knots[k] < knots[k + 1]))
            k--;
        return k;
    }
    /* Invariant knots[lo] <= t < knots[hi]: the result has knots[k] <= t < knots[k+1], hence a
     * non-empty span even where knots repeat. */
    int32_t lo = degree, hi = n;
    while (hi - lo > 1) {
        int32_t mid = lo + (hi - lo) / 2;
        if (t < knots[mid])
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

void sw_sg_basis_ders(const double *knots, int32_t degree, int32_t span, double t, int32_t nd,
                      double *ders)
{
    assert(knots && ders && degree >= 0 && degree <= SW_SG_MAX_DEGREE && nd >= 0);
    const int32_t p = degree;
    double ndu[SW__P1][SW__P1]; /* upper triangle: basis values; lower: knot differences */
    double left[SW__P1], right[SW__P1];
    double a[2][SW__P1];

    ndu[0][0] = 1.0;
    for (int32_t j = 1; j <= p; j++) {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        double saved = 0.0;
        for (int32_t r = 0; r < j; r++) {
            /* Within a non-empty span these knot differences are never zero. */
            ndu[j][r] = right[r + 1] + left[j - r];
            double temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for (int32_t j = 0; j <= p; j++)
        ders[j] = ndu[j][p];

    /* Derivatives above the degree vanish; the caller may still ask for them. */
    const int32_t n_eff = nd < p ? nd : p;
    for (int32_t k = n_eff + 1; k <= nd; k++)
        for (int32_t j = 0; j <= p; j++)
            ders[k * (p + 1) + j] = 0.0;

    for (int32_t r = 0; r <= p; r++) {
        int32_t s1 = 0, s2 = 1;
        a[0][0] = 1.0;
        for (int32_t k = 1; k <= n_eff; k++) {
            double d = 0.0;
            const int32_t rk = r - k, pk = p - k;
            if (r >= k) {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            const int32_t j1 = rk >= -1 ? 1 : -rk;
            const int32_t j2 = (r - 1 <= pk) ? k - 1 : p - r;
            for (int32_t j = j1; j <= j2; j++) {
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
                d += a[s2][j] * ndu[rk + j][pk];
            }
            if (r <= pk) {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k * (p + 1) + r] = d;
            int32_t tmp = s1;
            s1 = s2;
            s2 = tmp;
        }
    }
    /* Scale the k-th row by p! / (p-k)!. */
    double f = p;
    for (int32_t k = 1; k <= n_eff; k++) {
        for (int32_t j = 0; j <= p; j++)
            ders[k * (p + 1) + j] *= f;
        f *= (double)(p - k);
    }
}

int32_t sw_sg_knots_segment_count(const double *knots, int32_t degree, int32_t n)
{
    assert(knots && degree >= 0 && n > degree);
    int32_t count = 0;
    for (int32_t k = degree; k < n; k++)
        if (knots[k] < knots[k + 1])
            count++;
    return count;
}

/* SPDX-License-Identifier: MIT */
/* Validation of NURBS curves and surfaces before anything evaluates them.
 *
 * Imported geometry is untrusted (CONVENTIONS.md, "files are hostile"): every later step
 * (span search, basis functions, Bézier extraction for Guthe et al. 2005 §3) relies on what is
 * checked here — degrees in 1..SW_SG_MAX_DEGREE, consistent counts, finite non-decreasing knots
 * with a non-empty domain, no knot repeated more than degree + 1 times, finite control points and
 * strictly positive finite weights. Failures name the object and the offending index.
 * Beyond finiteness, values must lie in the range of sw_sg_geom.h (SW_SG_COORD_MAX and the weight
 * limits), where the products of evaluation and bounds cannot overflow (the rule is stated there).
 */
#include "sw_sg_geom.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

/* Counts above this would overflow size computations long before any real model needs them. */
#define SW__MAX_COUNT (1 << 28)

static sw_result check_knots(const double *knots, int32_t degree, int32_t n, const char *what,
                             const char *dir, sw_status *status)
{
    if (degree < 1 || degree > SW_SG_MAX_DEGREE)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: %sdegree %d outside 1..%d", what, dir,
                        (int)degree, SW_SG_MAX_DEGREE);
    if (n < degree + 1 || n > SW__MAX_COUNT)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: %d %scontrol points for degree %d (need %d..%d)", what, (int)n, dir,
                        (int)degree, (int)degree + 1, SW__MAX_COUNT);
    if (!knots)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no %sknot vector", what, dir);
    const int32_t m = n + degree + 1;
    int32_t run = 1;
    for (int32_t k = 0; k < m; k++) {
        if (!isfinite(knots[k]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: %sknot %d is not finite", what,
                            dir, (int)k);
        if (!(fabs(knots[k]) <= SW_SG_COORD_MAX))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: %sknot %d is %g, beyond %g (products would overflow)", what, dir,
                            (int)k, knots[k], SW_SG_COORD_MAX);
        if (k == 0)
            continue;
        if (knots[k] < knots[k - 1])
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: %sknots decrease at index %d (%.17g < %.17g)", what, dir, (int)k,
                            knots[k], knots[k - 1]);
        run = knots[k] == knots[k - 1] ? run + 1 : 1;
        if (run > degree + 1)
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: %sknot %d has multiplicity %d > degree + 1 = %d", what, dir,
                            (int)k, (int)run, (int)degree + 1);
    }
    if (!(knots[degree] < knots[n]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: empty %sparameter domain [knot %d, knot %d] = [%.17g, %.17g]", what,
                        dir, (int)degree, (int)n, knots[degree], knots[n]);
    return SW_OK;
}

/* What is wrong with one homogeneous control point; formatting is left to the failure path so
 * large nets are checked quickly. */
enum { PT_OK, PT_WEIGHT, PT_WEIGHT_RANGE, PT_COORD, PT_COORD_RANGE };

static int bad_point(const double *pw, int32_t dim, int32_t *coord)
{
    const double w = pw[dim - 1];
    if (!(isfinite(w) && w > 0.0))
        return PT_WEIGHT;
    if (!(w >= SW_SG_WEIGHT_MIN && w <= SW_SG_WEIGHT_MAX))
        return PT_WEIGHT_RANGE;
    for (int32_t d = 0; d < dim - 1; d++) {
        *coord = d;
        if (!isfinite(pw[d]))
            return PT_COORD;
        if (!(fabs(pw[d] / w) <= SW_SG_COORD_MAX))
            return PT_COORD_RANGE;
    }
    return PT_OK;
}

static sw_result fail_point(const double *pw, int32_t dim, int kind, int32_t coord,
                            const char *what, const char *index, sw_status *status)
{
    const double w = pw[dim - 1];
    switch (kind) {
    case PT_WEIGHT:
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: weight of control point %s is %g (must be finite and > 0)", what,
                        index, w);
    case PT_WEIGHT_RANGE:
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: weight of control point %s is %g, outside [%g, %g] (products would "
                        "overflow)",
                        what, index, w, SW_SG_WEIGHT_MIN, SW_SG_WEIGHT_MAX);
    case PT_COORD:
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: control point %s coordinate %d is not finite", what, index,
                        (int)coord);
    default:
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: control point %s coordinate %d is %g, beyond %g (products would "
                        "overflow)",
                        what, index, (int)coord, pw[coord] / w, SW_SG_COORD_MAX);
    }
}

/* The smallest and largest weight of a net of sound points, with their indices. */
typedef struct weight_span {
    double lo, hi;
    size_t at_lo, at_hi;
} weight_span;

static void span_add(weight_span *s, double w, size_t i)
{
    if (w < s->lo)
        s->lo = w, s->at_lo = i;
    if (w > s->hi)
        s->hi = w, s->at_hi = i;
}

static int span_ok(const weight_span *s)
{
    return s->hi <= SW_SG_WEIGHT_RATIO_MAX * s->lo;
}

static sw_result fail_span(const weight_span *s, const char *what, const char *lo, const char *hi,
                           sw_status *status)
{
    return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                    "%s: weights %g (control point %s) and %g (control point %s) differ by a "
                    "factor %g > %g (products would overflow)",
                    what, s->lo, lo, s->hi, hi, s->hi / s->lo, SW_SG_WEIGHT_RATIO_MAX);
}

sw_result sw_sg_curve_validate(const sw_sg_curve *c, const char *what, sw_status *status)
{
    if (!what)
        what = "curve";
    if (!c)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no curve", what);
    if (c->dim < 2 || c->dim > 16)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: homogeneous dimension %d", what,
                        (int)c->dim);
    sw_result r = check_knots(c->knots, c->degree, c->n, what, "", status);
    if (r != SW_OK)
        return r;
    if (!c->cpw)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no control points", what);
    weight_span span = {INFINITY, 0.0, 0, 0};
    for (int32_t i = 0; i < c->n; i++) {
        const double *pw = c->cpw + (size_t)i * (size_t)c->dim;
        int32_t coord = 0;
        const int kind = bad_point(pw, c->dim, &coord);
        if (kind != PT_OK) {
            char index[32];
            snprintf(index, sizeof index, "%d", (int)i);
            return fail_point(pw, c->dim, kind, coord, what, index, status);
        }
        span_add(&span, pw[c->dim - 1], (size_t)i);
    }
    if (!span_ok(&span)) {
        char lo[32], hi[32];
        snprintf(lo, sizeof lo, "%zu", span.at_lo);
        snprintf(hi, sizeof hi, "%zu", span.at_hi);
        return fail_span(&span, what, lo, hi, status);
    }
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_sg_surface_validate(const sw_sg_surface *s, const char *what, sw_status *status)
{
    if (!what)
        what = "surface";
    if (!s)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no surface", what);
    sw_result r = check_knots(s->knots_u, s->deg_u, s->n_u, what, "u ", status);
    if (r == SW_OK)
        r = check_knots(s->knots_v, s->deg_v, s->n_v, what, "v ", status);
    if (r != SW_OK)
        return r;
    if ((int64_t)s->n_u * s->n_v > SW__MAX_COUNT)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: %d x %d control points (max %d)",
                        what, (int)s->n_u, (int)s->n_v, SW__MAX_COUNT);
    if (!s->cpw)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no control points", what);
    weight_span span = {INFINITY, 0.0, 0, 0};
    for (int32_t j = 0; j < s->n_v; j++)
        for (int32_t i = 0; i < s->n_u; i++) {
            const size_t at = (size_t)j * (size_t)s->n_u + (size_t)i;
            const double *pw = s->cpw + at * 4;
            int32_t coord = 0;
            const int kind = bad_point(pw, 4, &coord);
            if (kind != PT_OK) {
                char index[64];
                snprintf(index, sizeof index, "(%d, %d) [index %d]", (int)i, (int)j,
                         (int)(j * s->n_u + i));
                return fail_point(pw, 4, kind, coord, what, index, status);
            }
            span_add(&span, pw[3], at);
        }
    if (!span_ok(&span)) {
        char lo[64], hi[64];
        snprintf(lo, sizeof lo, "(%d, %d)", (int)(span.at_lo % (size_t)s->n_u),
                 (int)(span.at_lo / (size_t)s->n_u));
        snprintf(hi, sizeof hi, "(%d, %d)", (int)(span.at_hi % (size_t)s->n_u),
                 (int)(span.at_hi / (size_t)s->n_u));
        return fail_span(&span, what, lo, hi, status);
    }
    sw__status_ok(status);
    return SW_OK;
}

/* SPDX-License-Identifier: MIT */
/* Validation of NURBS curves and surfaces before anything evaluates them.
 *
 * Imported geometry is untrusted (CONVENTIONS.md, "files are hostile"): every later step
 * (span search, basis functions, Bézier extraction for Guthe et al. 2005 §3) relies on what is
 * checked here — degrees in 1..SW_SG_MAX_DEGREE, consistent counts, finite non-decreasing knots
 * with a non-empty domain, no knot repeated more than degree + 1 times, finite control points and
 * strictly positive finite weights. Failures name the object and the offending index.
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

/* Returns -1 for a sound homogeneous control point, else the offending coordinate (dim - 1 being
 * the weight); formatting is left to the failure path so large nets are checked quickly. */
static int32_t bad_coordinate(const double *pw, int32_t dim)
{
    if (!(isfinite(pw[dim - 1]) && pw[dim - 1] > 0.0))
        return dim - 1;
    for (int32_t d = 0; d < dim - 1; d++)
        if (!isfinite(pw[d]))
            return d;
    return -1;
}

static sw_result fail_point(const double *pw, int32_t dim, int32_t coord, const char *what,
                            const char *index, sw_status *status)
{
    if (coord == dim - 1)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: weight of control point %s is %g (must be finite and > 0)", what,
                        index, pw[dim - 1]);
    return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                    "%s: control point %s coordinate %d is not finite", what, index, (int)coord);
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
    for (int32_t i = 0; i < c->n; i++) {
        const double *pw = c->cpw + (size_t)i * (size_t)c->dim;
        const int32_t coord = bad_coordinate(pw, c->dim);
        if (coord >= 0) {
            char index[32];
            snprintf(index, sizeof index, "%d", (int)i);
            return fail_point(pw, c->dim, coord, what, index, status);
        }
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
    for (int32_t j = 0; j < s->n_v; j++)
        for (int32_t i = 0; i < s->n_u; i++) {
            const double *pw = s->cpw + ((size_t)j * (size_t)s->n_u + (size_t)i) * 4;
            const int32_t coord = bad_coordinate(pw, 4);
            if (coord >= 0) {
                char index[64];
                snprintf(index, sizeof index, "(%d, %d) [index %d]", (int)i, (int)j,
                         (int)(j * s->n_u + i));
                return fail_point(pw, 4, coord, what, index, status);
            }
        }
    sw__status_ok(status);
    return SW_OK;
}

/* SPDX-License-Identifier: MIT */
/* The pseudo-Gauss map of a rational Bézier patch in Bézier form and the normal cone of its
 * control rays (Kumar et al. 1997 §3, eq. 1); the derivation of the degrees is in
 * sw_lod_supersurface.h.
 *
 * Kumar bounds a patch's normals by the "span" of its control rays (the largest angle between two
 * of them) and a super-surface's by the span of the union. We keep a cone (axis, half-angle)
 * instead: it is what back-patch culling tests (§4.4), two cones merge in O(1) while a cluster
 * grows, and a span s is always enclosed by a cone of half-angle <= s (and needs >= s / 2).
 *
 * Where the paper is loose: "we ignore any hull points that lie on the origin" — in floating point
 * the rays at a pole are not zero but rounding noise with arbitrary directions. We drop rays below
 * their rounding bound (SW_LOD_GAUSS_ROUNDING_ULPS) and pay for it (and for the rounding of the
 * rays we keep) with a widening that makes the cone rigorous wherever |N| is above
 * SW_LOD_GAUSS_VALID_REL of the largest ray: there N = N_kept + R with N_kept inside the cone of
 * the kept rays and |R| <= E (E = the largest dropped ray + the rounding bound, Bernstein weights
 * summing to 1), so the angle between N and N_kept is at most asin(E / |N|).
 */
#include "sw_lod_bezier.h"
#include "sw_lod_supersurface.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <string.h>

void sw_lod_pseudo_normal_degrees(int32_t deg_u, int32_t deg_v, int32_t *nu, int32_t *nv)
{
    *nu = 3 * deg_u - 1;
    *nv = 3 * deg_v - 1;
}

/* Scratch layout: the derivative nets, the weight nets, one cross-product net and the norm nets
 * of the magnitude bound, then (for the cone) the net, its magnitudes and the kept directions. */
typedef struct layout {
    size_t du, dv, w, wu, wv, cross, np, npu, npv, prod, net, mag, dirs, total;
} layout;

static layout layout_of(int32_t m, int32_t n)
{
    const size_t m1 = (size_t)m + 1, n1 = (size_t)n + 1, nc = (size_t)(3 * m) * (size_t)(3 * n);
    layout l;
    size_t at = 0;
    l.du = at, at += (size_t)m * n1 * 4;
    l.dv = at, at += m1 * (size_t)n * 4;
    l.w = at, at += m1 * n1;
    l.wu = at, at += (size_t)m * n1;
    l.wv = at, at += m1 * (size_t)n;
    l.cross = at, at += (2 * m1) * (2 * n1) * 3;
    l.np = at, at += m1 * n1;
    l.npu = at, at += (size_t)m * n1;
    l.npv = at, at += m1 * (size_t)n;
    l.prod = at, at += (2 * m1) * (2 * n1);
    l.net = at, at += nc * 3;
    l.mag = at, at += nc;
    l.dirs = at, at += nc * 3;
    l.total = at;
    return l;
}

size_t sw_lod_gauss_scratch_bound(int32_t deg_u, int32_t deg_v)
{
    return layout_of(deg_u, deg_v).total;
}

/* Homogeneous difference net along dir (dim 4): the hodograph of the numerator and the weight. */
static void hodograph(int32_t m, int32_t n, const double *cpw, int dir, double *out)
{
    const int32_t ou = dir ? m : m - 1, ov = dir ? n - 1 : n;
    const double deg = dir ? n : m;
    for (int32_t j = 0; j <= ov; ++j)
        for (int32_t i = 0; i <= ou; ++i) {
            const double *a = cpw + ((size_t)j * (size_t)(m + 1) + (size_t)i) * 4;
            const double *b = a + (dir ? (size_t)(m + 1) * 4 : 4);
            double *o = out + ((size_t)j * (size_t)(ou + 1) + (size_t)i) * 4;
            for (int k = 0; k < 4; ++k)
                o[k] = deg * (b[k] - a[k]);
        }
}

/* Scalar net of the norms of the first three components of a dim-4 net. */
static void norms(size_t count, const double *net, double *out)
{
    for (size_t k = 0; k < count; ++k)
        out[k] = sqrt(net[4 * k] * net[4 * k] + net[4 * k + 1] * net[4 * k + 1] +
                      net[4 * k + 2] * net[4 * k + 2]);
}

/* out (dim 3, degrees (au+bu, av+bv), zeroed by the caller) = A x B for the first three
 * components of the dim-4 nets A and B: the Bernstein product of sw_lod_bez_mul_add with the
 * cross product in place of the scalar one. */
static void cross_net(int32_t au, int32_t av, const double *a, int32_t bu, int32_t bv,
                      const double *b, double *out)
{
    sw_lod_bez_product_weights w;
    sw_lod_bez_product_weights_init(&w, au, av, bu, bv);
    const size_t ou = (size_t)(au + bu + 1);
    for (int32_t j2 = 0; j2 <= bv; ++j2)
        for (int32_t i2 = 0; i2 <= bu; ++i2) {
            const double *bc = b + ((size_t)j2 * (size_t)(bu + 1) + (size_t)i2) * 4;
            for (int32_t j1 = 0; j1 <= av; ++j1)
                for (int32_t i1 = 0; i1 <= au; ++i1) {
                    const double f = sw_lod_bez_product_weight(&w, i1, j1, i2, j2);
                    const double *ac = a + ((size_t)j1 * (size_t)(au + 1) + (size_t)i1) * 4;
                    double *o = out + ((size_t)(j1 + j2) * ou + (size_t)(i1 + i2)) * 3;
                    o[0] += f * (ac[1] * bc[2] - ac[2] * bc[1]);
                    o[1] += f * (ac[2] * bc[0] - ac[0] * bc[2]);
                    o[2] += f * (ac[0] * bc[1] - ac[1] * bc[0]);
                }
        }
}

/* One term sign * X * (A x B) of eq. 1 added to the net (and |X| |A| |B| to the magnitudes). */
static void add_term(const layout *l, double *s, int32_t xu, int32_t xv, const double *x,
                     int32_t au, int32_t av, const double *a, const double *na, int32_t bu,
                     int32_t bv, const double *b, const double *nb, double sign, double *out,
                     double *mag)
{
    const int32_t cu = au + bu, cv = av + bv;
    double *cross = s + l->cross;
    memset(cross, 0, sw_lod_bez_count(cu, cv, 3) * sizeof *cross);
    cross_net(au, av, a, bu, bv, b, cross);
    sw_lod_bez_mul_add(3, cu, cv, cross, xu, xv, x, sign, out);
    if (!mag)
        return;
    double *prod = s + l->prod;
    memset(prod, 0, sw_lod_bez_count(cu, cv, 1) * sizeof *prod);
    sw_lod_bez_mul_add(1, au, av, na, bu, bv, nb, 1.0, prod);
    /* |X|: the weight is positive, its hodographs need not be */
    double absx[(SW_LOD_GAUSS_MAX_DEGREE + 1) * (SW_LOD_GAUSS_MAX_DEGREE + 1)];
    const size_t nx = sw_lod_bez_count(xu, xv, 1);
    for (size_t k = 0; k < nx; ++k)
        absx[k] = fabs(x[k]);
    sw_lod_bez_mul_add(1, cu, cv, prod, xu, xv, absx, 1.0, mag);
}

void sw_lod_pseudo_normal_net(int32_t deg_u, int32_t deg_v, const double *cpw, double *scratch,
                              double *out, double *mag)
{
    const int32_t m = deg_u, n = deg_v;
    assert(m >= 1 && m <= SW_LOD_GAUSS_MAX_DEGREE && n >= 1 && n <= SW_LOD_GAUSS_MAX_DEGREE);
    const layout l = layout_of(m, n);
    double *s = scratch;
    hodograph(m, n, cpw, 0, s + l.du);
    hodograph(m, n, cpw, 1, s + l.dv);
    sw_lod_bez_component(m, n, 4, cpw, 3, s + l.w);
    sw_lod_bez_component(m - 1, n, 4, s + l.du, 3, s + l.wu);
    sw_lod_bez_component(m, n - 1, 4, s + l.dv, 3, s + l.wv);
    norms(sw_lod_bez_count(m, n, 1), cpw, s + l.np);
    norms(sw_lod_bez_count(m - 1, n, 1), s + l.du, s + l.npu);
    norms(sw_lod_bez_count(m, n - 1, 1), s + l.dv, s + l.npv);
    const size_t nc = sw_lod_bez_count(3 * m - 1, 3 * n - 1, 1);
    memset(out, 0, nc * 3 * sizeof *out);
    if (mag)
        memset(mag, 0, nc * sizeof *mag);
    /* N = W (P_u x P_v) - W_v (P_u x P) - W_u (P x P_v) */
    add_term(&l, s, m, n, s + l.w, m - 1, n, s + l.du, s + l.npu, m, n - 1, s + l.dv, s + l.npv,
             1.0, out, mag);
    add_term(&l, s, m, n - 1, s + l.wv, m - 1, n, s + l.du, s + l.npu, m, n, cpw, s + l.np, -1.0,
             out, mag);
    add_term(&l, s, m - 1, n, s + l.wu, m, n, cpw, s + l.np, m, n - 1, s + l.dv, s + l.npv, -1.0,
             out, mag);
}

/* ---- cones ----------------------------------------------------------------------------------- */
static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

/* Angle between unit vectors, accurate near 0 and pi (atan2 of sine and cosine). */
static double angle3(const double *a, const double *b)
{
    double c[3];
    cross3(a, b, c);
    return atan2(norm3(c), dot3(a, b));
}

void sw_lod_cone_set_angle(sw_lod_cone *c, double half_angle)
{
    c->half_angle = half_angle < 0.0 ? 0.0 : half_angle >= M_PI ? M_PI : half_angle;
    c->cos_half_angle = c->half_angle >= M_PI ? -1.0 : cos(c->half_angle);
}

static void set_full(sw_lod_cone *c)
{
    c->axis[0] = 0.0, c->axis[1] = 0.0, c->axis[2] = 1.0;
    sw_lod_cone_set_angle(c, M_PI);
}

/* The unit vector at angle phi from unit a, turned toward unit b (in their plane; any plane when
 * b is parallel to a). */
static void turn_toward(const double *a, const double *b, double phi, double *out)
{
    double u[3], d = dot3(a, b);
    for (int k = 0; k < 3; ++k)
        u[k] = b[k] - d * a[k];
    double len = norm3(u);
    if (!(len > 1e-300)) {
        const double e[3] = {fabs(a[0]) < 0.9 ? 1.0 : 0.0, fabs(a[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        cross3(a, e, u);
        len = norm3(u);
    }
    const double c = cos(phi), s = sin(phi);
    double r[3];
    for (int k = 0; k < 3; ++k)
        r[k] = c * a[k] + s * u[k] / len;
    const double rl = norm3(r);
    for (int k = 0; k < 3; ++k)
        out[k] = r[k] / rl;
}

/* Caps given by axes (stride `stride` doubles) and half-angles (NULL: all zero). */
typedef struct caps {
    const double *axes;
    size_t stride;
    const double *half;
    size_t half_stride;
    size_t n;
} caps;

static double cap_half(const caps *c, size_t k)
{
    return c->half ? c->half[k * c->half_stride] : 0.0;
}

/* Half-angle `axis` needs to contain every cap; *far gets the cap that needs the most. `exact`
 * takes every angle by atan2 (accurate near 0 and pi); otherwise plain caps are ranked by their
 * dot product and only the farthest one's angle is taken, and caps by acos — for the search. */
static double needed(const caps *c, const double *axis, size_t *far, int exact)
{
    if (!exact && !c->half) {
        double lowest = INFINITY;
        for (size_t k = 0; k < c->n; ++k) {
            const double d = dot3(axis, c->axes + k * c->stride);
            if (d < lowest)
                lowest = d, *far = k;
        }
        return angle3(axis, c->axes + *far * c->stride);
    }
    double worst = -1.0;
    for (size_t k = 0; k < c->n; ++k) {
        const double *a = c->axes + k * c->stride;
        const double g = exact ? angle3(axis, a) : acos(fmax(-1.0, fmin(1.0, dot3(axis, a))));
        if (g + cap_half(c, k) > worst)
            worst = g + cap_half(c, k), *far = k;
    }
    return worst;
}

/* Bădoiu-Clarkson on the sphere: from the mean direction, step toward the farthest cap by a
 * shrinking fraction and keep the best axis seen. Any axis gives a valid cone with the half-angle
 * it needs (taken exactly at the end); the iteration only makes it smaller. */
static void enclose_caps(const caps *c, sw_lod_cone *out)
{
    double axis[3] = {0.0, 0.0, 0.0};
    for (size_t k = 0; k < c->n; ++k)
        for (int a = 0; a < 3; ++a)
            axis[a] += c->axes[k * c->stride + a];
    double len = norm3(axis);
    if (!(len > 1e-12 * (double)c->n)) {
        memcpy(axis, c->axes, sizeof axis);
        len = 1.0;
    }
    for (int a = 0; a < 3; ++a)
        axis[a] /= len;
    size_t far = 0;
    double best = needed(c, axis, &far, 0);
    memcpy(out->axis, axis, sizeof axis);
    for (int it = 0, since_best = 0; it < 32 && since_best < 8 && best > 0.0; ++it) {
        const double *f = c->axes + far * c->stride;
        const double gap = angle3(axis, f) + cap_half(c, far);
        double next[3];
        turn_toward(axis, f, gap / (double)(it + 2), next);
        memcpy(axis, next, sizeof axis);
        const double need = needed(c, axis, &far, 0);
        ++since_best;
        if (need < best) {
            best = need, since_best = 0;
            memcpy(out->axis, axis, sizeof axis);
        }
    }
    best = needed(c, out->axis, &far, 1);
    if (!(best < M_PI))
        set_full(out);
    else
        sw_lod_cone_set_angle(out, best);
}

void sw_lod_cone_enclose(const sw_lod_cone *cones, size_t n, sw_lod_cone *out)
{
    assert(n >= 1);
    for (size_t k = 0; k < n; ++k)
        if (cones[k].half_angle >= M_PI) {
            set_full(out);
            return;
        }
    const caps c = {cones[0].axis, sizeof *cones / sizeof(double), &cones[0].half_angle,
                    sizeof *cones / sizeof(double), n};
    enclose_caps(&c, out);
}

void sw_lod_cone_merge(const sw_lod_cone *a, const sw_lod_cone *b, sw_lod_cone *out)
{
    if (a->half_angle >= M_PI || b->half_angle >= M_PI) {
        set_full(out);
        return;
    }
    const double g = angle3(a->axis, b->axis);
    if (g + b->half_angle <= a->half_angle) {
        *out = *a;
        return;
    }
    if (g + a->half_angle <= b->half_angle) {
        *out = *b;
        return;
    }
    const double h = 0.5 * (a->half_angle + b->half_angle + g);
    if (!(h < M_PI)) {
        set_full(out);
        return;
    }
    double axis[3];
    turn_toward(a->axis, b->axis, h - a->half_angle, axis);
    memcpy(out->axis, axis, sizeof axis);
    sw_lod_cone_set_angle(out, h);
}

int sw_lod_cone_contains(const sw_lod_cone *outer, const sw_lod_cone *inner, double slack)
{
    if (outer->half_angle >= M_PI)
        return 1;
    return angle3(outer->axis, inner->axis) + inner->half_angle <= outer->half_angle + slack;
}

int sw_lod_gauss_cone(int32_t deg_u, int32_t deg_v, const double *cpw, double *scratch,
                      sw_lod_cone *out)
{
    if (deg_u < 1 || deg_v < 1 || deg_u > SW_LOD_GAUSS_MAX_DEGREE ||
        deg_v > SW_LOD_GAUSS_MAX_DEGREE) {
        set_full(out);
        return 0;
    }
    const layout l = layout_of(deg_u, deg_v);
    double *net = scratch + l.net, *mag = scratch + l.mag, *dirs = scratch + l.dirs;
    sw_lod_pseudo_normal_net(deg_u, deg_v, cpw, scratch, net, mag);
    const size_t nc = sw_lod_bez_count(3 * deg_u - 1, 3 * deg_v - 1, 1);
    const double ulps =
        SW_LOD_GAUSS_ROUNDING_ULPS * (2.0 * (deg_u + 1) * (deg_v + 1) + 16.0) * DBL_EPSILON;
    double longest = 0.0, dropped = 0.0, rounding = 0.0;
    size_t kept = 0;
    for (size_t k = 0; k < nc; ++k) {
        const double len = norm3(net + 3 * k), noise = ulps * mag[k];
        if (!isfinite(len) || !isfinite(noise)) {
            set_full(out);
            return 0;
        }
        rounding = fmax(rounding, noise);
        longest = fmax(longest, len);
        if (len <= noise) {
            dropped = fmax(dropped, len);
            continue;
        }
        for (int a = 0; a < 3; ++a)
            dirs[3 * kept + a] = net[3 * k + a] / len;
        ++kept;
    }
    const double floor = SW_LOD_GAUSS_VALID_REL * longest, e = dropped + rounding;
    if (kept == 0 || !(e < floor)) {
        set_full(out);
        return 0;
    }
    const caps c = {dirs, 3, NULL, 0, kept};
    enclose_caps(&c, out);
    /* A cone wider than a half-space is not convex: it holds the rays but not necessarily their
     * non-negative combinations, the normals. */
    if (!(out->half_angle < 0.5 * M_PI)) {
        set_full(out);
        return 0;
    }
    sw_lod_cone_set_angle(out, out->half_angle + asin(e / floor));
    return out->half_angle < M_PI;
}

/* SPDX-License-Identifier: MIT */
/* Unit properties of lod/'s Bézier utilities, degree reduction and error bound, each against an
 * independent reference (the scenegraph evaluators sw_sg_bezier_patch_eval, sw_sg_curve_eval,
 * sw_sg_surface_eval_d2, or a closed form):
 *  - degree elevation is exact (1e-12 relative), de Casteljau subdivision and restriction
 *    reproduce the patch, products of Bernstein polynomials are pointwise products;
 *  - G1 reduction keeps the corners and both tangent directions at every corner (angle < 1e-9),
 *    keeps every weight positive, and reproduces a degree-elevated bicubic exactly;
 *  - the error bound: zero for equal nets, exact for a translated copy (also of a small part far
 *    from the origin, whose rounding allowance must stay under a close view's tolerance), and
 *    above the measured distance for the quarter circle whose paper-style ε_c (projected control
 *    points) is 0.
 */
#include "sw_lod_bezier.h"
#include "sw_lod_error.h"
#include "sw_lod_reduce.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

static uint64_t rng = 0x2545F4914F6CDD1Dull;

static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1.0p-53;
}

static void random_net(int32_t du, int32_t dv, double *cpw)
{
    for (int32_t j = 0; j <= dv; ++j)
        for (int32_t i = 0; i <= du; ++i) {
            double *p = cpw + (j * (du + 1) + i) * 4;
            double w = exp(log(0.2) + rnd() * (log(5.0) - log(0.2)));
            p[0] = w * ((double)i / du + 0.3 * (2 * rnd() - 1) + 100.0);
            p[1] = w * ((double)j / dv + 0.3 * (2 * rnd() - 1) - 50.0);
            p[2] = w * 0.4 * (2 * rnd() - 1);
            p[3] = w;
        }
}

static void eval(int32_t du, int32_t dv, double *cpw, double s, double t, double out[3])
{
    sw_sg_bezier_patch p = {du, dv, 0, 0, 0.0, 1.0, 0.0, 1.0, cpw};
    sw_sg_bezier_patch_eval(&p, s, t, out);
}

static double dist(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

static void test_elevation_exact(void **state)
{
    (void)state;
    double cpw[8 * 8 * 4], up[16 * 16 * 4];
    double worst = 0.0;
    for (int32_t du = 1; du <= 7; ++du)
        for (int32_t dv = 1; dv <= 7; ++dv) {
            random_net(du, dv, cpw);
            const int32_t nu = du + (du % 3) + 1, nv = dv + (dv % 4);
            sw_lod_bez_elevate(du, dv, 4, cpw, nu, nv, up);
            for (int k = 0; k < 20; ++k) {
                double s = rnd(), t = rnd(), a[3], b[3];
                eval(du, dv, cpw, s, t, a);
                eval(nu, nv, up, s, t, b);
                worst = fmax(worst, dist(a, b) / 100.0);
            }
        }
    print_message("elevation: worst relative difference %.3g\n", worst);
    assert_true(worst < 1e-12);
}

static void test_subdivision_reproduces(void **state)
{
    (void)state;
    double cpw[8 * 8 * 4], lo[8 * 8 * 4], hi[8 * 8 * 4], cut[8 * 8 * 4];
    double worst = 0.0;
    for (int32_t d = 1; d <= 7; ++d) {
        const int32_t du = d, dv = 8 - d;
        random_net(du, dv, cpw);
        for (int dir = 0; dir < 2; ++dir) {
            const double s = 0.1 + 0.8 * rnd();
            sw_lod_bez_subdivide(du, dv, 4, cpw, dir, s, lo, hi);
            const double rect[4] = {0.2 * rnd(), 0.8 + 0.2 * rnd(), 0.3 * rnd(), 0.5 + 0.5 * rnd()};
            sw_lod_bez_restrict(du, dv, 4, cpw, rect, cut);
            for (int k = 0; k < 20; ++k) {
                double x = rnd(), y = rnd(), a[3], b[3];
                double sx = dir ? x : s * x, sy = dir ? s * y : y;
                eval(du, dv, cpw, sx, sy, a);
                eval(du, dv, lo, x, y, b);
                worst = fmax(worst, dist(a, b) / 100.0);
                sx = dir ? x : s + (1 - s) * x, sy = dir ? s + (1 - s) * y : y;
                eval(du, dv, cpw, sx, sy, a);
                eval(du, dv, hi, x, y, b);
                worst = fmax(worst, dist(a, b) / 100.0);
                eval(du, dv, cpw, rect[0] + x * (rect[1] - rect[0]),
                     rect[2] + y * (rect[3] - rect[2]), a);
                eval(du, dv, cut, x, y, b);
                worst = fmax(worst, dist(a, b) / 100.0);
            }
        }
    }
    print_message("subdivision / restriction: worst relative difference %.3g\n", worst);
    assert_true(worst < 1e-12);
}

/* Reference Bernstein evaluation of a scalar net, written out. */
static double bern_scalar(int32_t du, int32_t dv, const double *c, double s, double t)
{
    double r = 0.0;
    for (int32_t j = 0; j <= dv; ++j)
        for (int32_t i = 0; i <= du; ++i) {
            double bu = tgamma(du + 1.0) / (tgamma(i + 1.0) * tgamma(du - i + 1.0)) * pow(s, i) *
                        pow(1 - s, du - i);
            double bv = tgamma(dv + 1.0) / (tgamma(j + 1.0) * tgamma(dv - j + 1.0)) * pow(t, j) *
                        pow(1 - t, dv - j);
            r += c[j * (du + 1) + i] * bu * bv;
        }
    return r;
}

static void test_product(void **state)
{
    (void)state;
    double a[6 * 4], b[3 * 5], out[8 * 8];
    for (int k = 0; k < 24; ++k)
        a[k] = 2 * rnd() - 1;
    for (int k = 0; k < 15; ++k)
        b[k] = 2 * rnd() - 1;
    memset(out, 0, sizeof out);
    sw_lod_bez_mul_add(1, 5, 3, a, 2, 4, b, 2.0, out); /* degrees (5,3) x (2,4) -> (7,7) */
    for (int k = 0; k < 50; ++k) {
        double s = rnd(), t = rnd();
        double want = 2.0 * bern_scalar(5, 3, a, s, t) * bern_scalar(2, 4, b, s, t);
        assert_true(fabs(bern_scalar(7, 7, out, s, t) - want) < 1e-13);
    }
}

static void bezier_surface(int32_t du, int32_t dv, double *knots, sw_sg_surface *s,
                           const double *cpw)
{
    for (int32_t k = 0; k < 2 * (du + 1); ++k)
        knots[k] = k <= du ? 0.0 : 1.0;
    for (int32_t k = 0; k < 2 * (dv + 1); ++k)
        knots[64 + k] = k <= dv ? 0.0 : 1.0;
    *s = (sw_sg_surface){du, dv, du + 1, dv + 1, knots, knots + 64, cpw};
}

static double angle(const double a[3], const double b[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                 a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

static void test_g1_reduction(void **state)
{
    (void)state;
    double cpw[8 * 8 * 4], bic[64], knots[128], knots3[128];
    double worst_angle = 0.0, worst_corner = 0.0;
    int clamped = 0, checked = 0;
    for (int rep = 0; rep < 4; ++rep)
        for (int32_t du = 2; du <= 7; ++du)
            for (int32_t dv = 2; dv <= 7; ++dv) {
                random_net(du, dv, cpw);
                sw_lod_reduce_info info;
                sw_lod_reduce_bicubic(du, dv, cpw, bic, &info);
                clamped += info.clamped != 0;
                for (int k = 0; k < 16; ++k)
                    assert_true(bic[k * 4 + 3] > 0.0);
                sw_sg_surface so, sr;
                bezier_surface(du, dv, knots, &so, cpw);
                bezier_surface(3, 3, knots3, &sr, bic);
                for (int c = 0; c < 4; ++c) {
                    const double u = c & 1, v = c >> 1;
                    sw_sg_surface_d2 a, b;
                    sw_sg_surface_eval_d2(&so, u, v, &a);
                    sw_sg_surface_eval_d2(&sr, u, v, &b);
                    worst_corner = fmax(worst_corner, dist(a.p, b.p) / 100.0);
                    worst_angle = fmax(worst_angle, angle(a.du, b.du));
                    worst_angle = fmax(worst_angle, angle(a.dv, b.dv));
                    checked += 2;
                }
            }
    print_message("G1: %d corner tangents, worst angle %.3g rad, worst corner %.3g; %d of 144 "
                  "reductions clamped\n",
                  checked, worst_angle, worst_corner, clamped);
    assert_true(worst_angle < 1e-9);
    assert_true(worst_corner < 1e-13);
}

static void test_reduction_of_elevated_cubic_is_exact(void **state)
{
    (void)state;
    double cub[64], up[8 * 8 * 4], back[64];
    random_net(3, 3, cub);
    sw_lod_bez_elevate(3, 3, 4, cub, 7, 6, up);
    sw_lod_reduce_bicubic(7, 6, up, back, NULL);
    sw_lod_error_result er;
    assert_int_equal(sw_lod_error_bound(4, 7, 6, up, 3, 3, back, NULL, &er, NULL), SW_OK);
    print_message("reduced elevated bicubic: bound %.3g\n", er.bound);
    assert_true(er.bound < 1e-7);
}

static void test_error_bound_examples(void **state)
{
    (void)state;
    /* equal nets and a translated copy (D / W is the constant translation) */
    double a[36 * 4], b[36 * 4];
    random_net(5, 5, a);
    memcpy(b, a, sizeof b);
    sw_lod_error_result er;
    assert_int_equal(sw_lod_error_bound(4, 5, 5, a, 5, 5, b, NULL, &er, NULL), SW_OK);
    assert_true(er.bound < 1e-7); /* rounding allowance only: points near (100, -50, 0) */
    for (int k = 0; k < 36; ++k)
        b[k * 4 + 2] += 0.25 * b[k * 4 + 3];
    assert_int_equal(sw_lod_error_bound(4, 5, 5, a, 5, 5, b, NULL, &er, NULL), SW_OK);
    assert_true(er.bound >= 0.25 && er.bound < 0.25 + 1e-7);

    /* quarter circle vs the parabola with the same projected control points: ε_c = 0 */
    const double h = sqrt(0.5);
    const double circle[9] = {1, 0, 1, h, h, h, 0, 1, 1}, parabola[9] = {1, 0, 1, 1, 1, 1, 0, 1, 1};
    assert_int_equal(sw_lod_error_bound(3, 2, 0, circle, 2, 0, parabola, NULL, &er, NULL), SW_OK);
    double measured = 0.0;
    for (int k = 0; k <= 10000; ++k) {
        double t = k / 10000.0, pc[2], pp[2], ws = 0.0, wp = 0.0;
        const double bs[3] = {(1 - t) * (1 - t), 2 * t * (1 - t), t * t};
        pc[0] = pc[1] = pp[0] = pp[1] = 0.0;
        for (int i = 0; i < 3; ++i) {
            pc[0] += bs[i] * circle[3 * i], pc[1] += bs[i] * circle[3 * i + 1],
                ws += bs[i] * circle[3 * i + 2];
            pp[0] += bs[i] * parabola[3 * i], pp[1] += bs[i] * parabola[3 * i + 1],
                wp += bs[i] * parabola[3 * i + 2];
        }
        measured = fmax(measured, hypot(pc[0] / ws - pp[0] / wp, pc[1] / ws - pp[1] / wp));
    }
    print_message("quarter circle vs parabola: ε_c 0, measured %.6f, bound %.6f\n", measured,
                  er.bound);
    assert_true(measured > 0.05);
    assert_true(er.bound >= measured && er.bound < 1.03 * measured);
}

/* A part 0.01 across, 2e4 from the origin (a scaled copy of a CAD part, about its box centre),
 * against its copy moved by 1e-8: the bound must hold the distance and leave the tolerance of a
 * close view (~1e-8 here) to the approximation. An allowance that multiplies the distance from
 * the origin by the steps of the products and of de Casteljau (16 (P + Q + 2) ulps of 2e4 times
 * the weights' spread: 2.5e-8, planted: FAIL) kept the part's hierarchy refining to its node cap
 * (a close view of it took 36 s instead of 15 ms). */
static void test_error_bound_far_from_origin(void **state)
{
    (void)state;
    double a[36 * 4], b[36 * 4];
    const double centre[3] = {-4281.1, 19153.5, 5738.6};
    for (int32_t j = 0; j <= 5; ++j)
        for (int32_t i = 0; i <= 5; ++i) {
            double *p = a + (j * 6 + i) * 4, w = 0.5 + 1.5 * rnd();
            const double x[3] = {0.002 * i, 0.002 * j, 0.001 * (2 * rnd() - 1)};
            for (int c = 0; c < 3; ++c)
                p[c] = w * (centre[c] + x[c]);
            p[3] = w;
        }
    memcpy(b, a, sizeof b);
    for (int k = 0; k < 36; ++k)
        b[k * 4 + 2] = b[k * 4 + 3] * (a[k * 4 + 2] / a[k * 4 + 3] + 1e-8);
    sw_lod_error_result er;
    assert_int_equal(sw_lod_error_bound(4, 5, 5, a, 5, 5, b, NULL, &er, NULL), SW_OK);
    print_message("part 2e4 from the origin moved by 1e-8: bound %.6g\n", er.bound);
    assert_true(er.bound >= 1e-8 * (1.0 - 1e-3)); /* the move, up to the rounding of 2e4 + 1e-8 */
    assert_true(er.bound < 1e-8 + 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_elevation_exact),
        cmocka_unit_test(test_subdivision_reproduces),
        cmocka_unit_test(test_product),
        cmocka_unit_test(test_g1_reduction),
        cmocka_unit_test(test_reduction_of_elevated_cubic_is_exact),
        cmocka_unit_test(test_error_bound_examples),
        cmocka_unit_test(test_error_bound_far_from_origin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

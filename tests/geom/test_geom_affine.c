/* SPDX-License-Identifier: MIT */
/* sw_sg_surface_affine: a surface is reported affine, S(u, v) = origin + u du + v dv, exactly when
 * it is one, checked against the surface's own dense evaluation (a 17 x 17 grid over its domain):
 *   - a bilinear plane, a bicubic B-spline plane with interior knots and poles at the Greville
 *     abscissae of an affine map (linear precision), and a plane with equal weights w != 1:
 *     reported affine, and origin + u du + v dv matches every evaluated point within 1e-12;
 *   - a twisted bilinear patch, a curved bicubic, the plane's poles with one weight changed, and a
 *     plane whose poles sit off the Greville abscissae (same control net box, non-linear
 *     parametrisation): not affine, and the evaluation shows each is not (so a detector
 *     answering "affine" for them would draw planar ribbons off the surface).
 * Planted faults seen failing: the weight test removed (the reweighted plane passes as affine);
 * Greville abscissae replaced by uniform i/(n-1) (the B-spline plane is refused). */
#include "geom_test_util.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

enum { N_MAX = 6, GRID = 17 };

typedef struct surf {
    double ku[N_MAX + 4], kv[N_MAX + 4], cpw[N_MAX * N_MAX * 4];
    sw_sg_surface s;
} surf;

/* A clamped knot vector of degree p for n poles with interior knots at the given parameters. */
static void clamped(double *k, int p, int n, const double *interior)
{
    for (int i = 0; i <= p; ++i) {
        k[i] = 0.0;
        k[n + i] = 1.0;
    }
    for (int i = p + 1; i < n; ++i)
        k[i] = interior[i - p - 1];
}

static double greville(const double *k, int p, int i)
{
    double s = 0.0;
    for (int j = 1; j <= p; ++j)
        s += k[i + j];
    return s / p;
}

static const double k_o[3] = {3.0, -2.0, 7.5}, k_du[3] = {10.0, 1.0, -2.0},
                    k_dv[3] = {-1.0, 6.0, 0.5};

/* Poles of the affine map at (a, b) parameters of each pole, weight w. */
static void affine_net(surf *f, int p, int nu, int nv, const double *iu, const double *iv, double w,
                       int off_greville)
{
    clamped(f->ku, p, nu, iu);
    clamped(f->kv, p, nv, iv);
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            double a = off_greville ? (double)i / (nu - 1) : greville(f->ku, p, i);
            double b = off_greville ? (double)j / (nv - 1) : greville(f->kv, p, j);
            double *c = f->cpw + 4 * (j * nu + i);
            for (int d = 0; d < 3; ++d)
                c[d] = w * (k_o[d] + a * k_du[d] + b * k_dv[d]);
            c[3] = w;
        }
    f->s = (sw_sg_surface){p, p, nu, nv, f->ku, f->kv, f->cpw};
}

/* Largest distance between the surface and origin + u du + v dv on a dense grid. */
static double max_deviation(const sw_sg_surface *s, const double o[3], const double du[3],
                            const double dv[3])
{
    double worst = 0.0;
    for (int j = 0; j < GRID; ++j)
        for (int i = 0; i < GRID; ++i) {
            double u = (double)i / (GRID - 1), v = (double)j / (GRID - 1), p[3];
            sw_sg_surface_eval(s, u, v, p);
            for (int d = 0; d < 3; ++d)
                worst = fmax(worst, fabs(p[d] - (o[d] + u * du[d] + v * dv[d])));
        }
    return worst;
}

/* Deviation of the surface from the affine map through its corners (nonzero: not affine). */
static double corner_deviation(const sw_sg_surface *s)
{
    double p00[3], p10[3], p01[3], du[3], dv[3];
    sw_sg_surface_eval(s, 0.0, 0.0, p00);
    sw_sg_surface_eval(s, 1.0, 0.0, p10);
    sw_sg_surface_eval(s, 0.0, 1.0, p01);
    for (int d = 0; d < 3; ++d) {
        du[d] = p10[d] - p00[d];
        dv[d] = p01[d] - p00[d];
    }
    return max_deviation(s, p00, du, dv);
}

static void expect_affine(const surf *f, const char *name)
{
    double o[3], du[3], dv[3];
    int a = sw_sg_surface_affine(&f->s, o, du, dv);
    double dev = a ? max_deviation(&f->s, o, du, dv) : INFINITY;
    printf("  %-30s affine %d, deviation %.3g\n", name, a, dev);
    assert_int_equal(a, 1);
    assert_true(dev <= 1e-12 * 20.0);
}

static void expect_not_affine(const surf *f, const char *name)
{
    double o[3], du[3], dv[3];
    int a = sw_sg_surface_affine(&f->s, o, du, dv);
    double dev = corner_deviation(&f->s);
    printf("  %-30s affine %d, deviation from its corners' map %.3g\n", name, a, dev);
    assert_true(dev > 1e-6); /* the case really is not affine */
    assert_int_equal(a, 0);
}

static const double k_iu[2] = {0.3, 0.55}, k_iv[1] = {0.7};

static void test_affine_planes(void **state)
{
    (void)state;
    surf f;
    affine_net(&f, 1, 2, 2, NULL, NULL, 1.0, 0);
    expect_affine(&f, "bilinear plane");
    affine_net(&f, 3, 6, 5, k_iu, k_iv, 1.0, 0);
    expect_affine(&f, "bicubic B-spline plane");
    affine_net(&f, 3, 6, 5, k_iu, k_iv, 0.8, 0);
    expect_affine(&f, "plane, equal weights 0.8");
}

static void test_not_affine(void **state)
{
    (void)state;
    surf f;
    affine_net(&f, 1, 2, 2, NULL, NULL, 1.0, 0);
    f.cpw[4 * 3 + 2] += 1.0; /* one corner lifted: a twisted bilinear patch */
    expect_not_affine(&f, "twisted bilinear");
    affine_net(&f, 3, 6, 5, k_iu, k_iv, 1.0, 0);
    f.cpw[4 * (2 * 6 + 2) + 2] += 0.5; /* an inner pole lifted: curved */
    expect_not_affine(&f, "curved bicubic");
    affine_net(&f, 3, 6, 5, k_iu, k_iv, 1.0, 0);
    for (int d = 0; d < 4; ++d)
        f.cpw[4 * (2 * 6 + 3) + d] *= 3.0; /* same point, weight 3: a rational reparametrisation */
    expect_not_affine(&f, "plane, one weight 3");
    affine_net(&f, 3, 6, 5, k_iu, k_iv, 1.0, 1);
    expect_not_affine(&f, "plane, poles off Greville");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_affine_planes),
        cmocka_unit_test(test_not_affine),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

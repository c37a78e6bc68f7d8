/* SPDX-License-Identifier: MIT */
/* Values, first and second derivatives of rational B-spline curves and surfaces against two
 * independent references:
 *  1. random rational surfaces (degrees 1..7 x 1..7) and curves, evaluated by a separate textbook
 *     Cox-de Boor recursion over bicomplex numbers (numerator and weight evaluated separately, then
 *     divided): the multicomplex step f(u + i h + j h) yields f_u, f_uu and f_uv without any
 *     derivative formula and without cancellation (Lantoine et al., "Using multicomplex variables
 *     for automatic computation of high-order derivatives", 2012);
 *  2. an exact NURBS torus (four rational quadratic quarter arcs per direction, double knots),
 *     whose derivatives are known in closed form: a quarter arc with middle weight cos(pi/4) has
 *     tan((theta - centre)/2) = tan(pi/8) (2t - 1).
 * Errors are relative to each quantity's largest magnitude over the surface's samples. */
#include "geom_test_util.h"

#include <complex.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#define TOL 1e-10
#define H 1e-20 /* multicomplex step: no subtraction, so it can be tiny */

/* Bicomplex number a + b j with a, b complex in i; i j = j i, i^2 = j^2 = -1. */
typedef struct bc {
    double complex a, b;
} bc;

static bc bc_real(double x)
{
    return (bc){x, 0};
}
static bc bc_add(bc x, bc y)
{
    return (bc){x.a + y.a, x.b + y.b};
}
static bc bc_sub(bc x, bc y)
{
    return (bc){x.a - y.a, x.b - y.b};
}
static bc bc_scale(bc x, double s)
{
    return (bc){x.a * s, x.b * s};
}
static bc bc_mul(bc x, bc y)
{
    return (bc){x.a * y.a - x.b * y.b, x.a * y.b + x.b * y.a};
}
static bc bc_div(bc x, bc y)
{
    const double complex d = y.a * y.a + y.b * y.b; /* y times its j-conjugate */
    const bc num = bc_mul(x, (bc){y.a, -y.b});
    return (bc){num.a / d, num.b / d};
}
/* Parts: real, i, j and ij coefficients. */
static double bc_re(bc x)
{
    return creal(x.a);
}
static double bc_i(bc x)
{
    return cimag(x.a);
}
static double bc_ij(bc x)
{
    return cimag(x.b);
}

/* Textbook B-spline basis N_{span-p..span, p}(t) by the Cox-de Boor recursion; the span is chosen
 * from the real part of t by a linear scan (last non-empty span closed). */
static int ref_basis(const double *U, int p, int n, bc t, bc *N)
{
    const double x = bc_re(t);
    int span = -1;
    for (int k = p; k < n; k++)
        if (U[k] < U[k + 1] && U[k] <= x)
            span = k;
    for (int r = 0; r <= p + 1; r++)
        N[r] = bc_real(0.0);
    N[p] = bc_real(1.0); /* N_{span,0} */
    for (int k = 1; k <= p; k++)
        for (int i = span - k; i <= span; i++) {
            const int r = i - (span - p);
            bc v = bc_real(0.0);
            const double d0 = U[i + k] - U[i], d1 = U[i + k + 1] - U[i + 1];
            if (d0 > 0)
                v = bc_add(v, bc_mul(bc_scale(bc_sub(t, bc_real(U[i])), 1.0 / d0), N[r]));
            if (d1 > 0)
                v = bc_add(v,
                           bc_mul(bc_scale(bc_sub(bc_real(U[i + k + 1]), t), 1.0 / d1), N[r + 1]));
            N[r] = v;
        }
    return span;
}

/* Homogeneous surface point (4 bicomplex coordinates) at bicomplex (u, v). */
static void ref_surface_h(const sw_sg_surface *s, bc u, bc v, bc out[4])
{
    bc nu[SW_SG_MAX_DEGREE + 2], nv[SW_SG_MAX_DEGREE + 2];
    const int p = s->deg_u, q = s->deg_v;
    const int su = ref_basis(s->knots_u, p, s->n_u, u, nu);
    const int sv = ref_basis(s->knots_v, q, s->n_v, v, nv);
    for (int c = 0; c < 4; c++)
        out[c] = bc_real(0.0);
    for (int j = 0; j <= q; j++)
        for (int i = 0; i <= p; i++) {
            const bc b = bc_mul(nu[i], nv[j]);
            const double *pw = s->cpw + ((size_t)(sv - q + j) * (size_t)s->n_u + (su - p + i)) * 4;
            for (int c = 0; c < 4; c++)
                out[c] = bc_add(out[c], bc_scale(b, pw[c]));
        }
}

static void ref_surface(const sw_sg_surface *s, bc u, bc v, bc out[3])
{
    bc h[4];
    ref_surface_h(s, u, v, h);
    for (int c = 0; c < 3; c++)
        out[c] = bc_div(h[c], h[3]);
}

/* Reference value and derivatives of the Euclidean surface; hu = dS^w/du for eval_h1. */
static void ref_d2(const sw_sg_surface *s, double u, double v, sw_sg_surface_d2 *d, double hu[4],
                   double hv[4])
{
    const bc ih = {I * H, 0}, jh = {0, H};
    bc r[3], h[4];
    ref_surface(s, bc_add(bc_real(u), ih), bc_real(v), r);
    ref_surface_h(s, bc_add(bc_real(u), ih), bc_real(v), h);
    for (int c = 0; c < 4; c++)
        hu[c] = bc_i(h[c]) / H;
    for (int c = 0; c < 3; c++) {
        d->p[c] = bc_re(r[c]);
        d->du[c] = bc_i(r[c]) / H;
    }
    ref_surface(s, bc_real(u), bc_add(bc_real(v), ih), r);
    ref_surface_h(s, bc_real(u), bc_add(bc_real(v), ih), h);
    for (int c = 0; c < 4; c++)
        hv[c] = bc_i(h[c]) / H;
    for (int c = 0; c < 3; c++)
        d->dv[c] = bc_i(r[c]) / H;
    ref_surface(s, bc_add(bc_add(bc_real(u), ih), jh), bc_real(v), r);
    for (int c = 0; c < 3; c++)
        d->duu[c] = bc_ij(r[c]) / (H * H);
    ref_surface(s, bc_add(bc_real(u), ih), bc_add(bc_real(v), jh), r);
    for (int c = 0; c < 3; c++)
        d->duv[c] = bc_ij(r[c]) / (H * H);
    ref_surface(s, bc_real(u), bc_add(bc_add(bc_real(v), ih), jh), r);
    for (int c = 0; c < 3; c++)
        d->dvv[c] = bc_ij(r[c]) / (H * H);
}

enum { Q_P, Q_U, Q_V, Q_UU, Q_UV, Q_VV, Q_HU, Q_HV, Q_COUNT };
static const char *const q_names[Q_COUNT] = {"S",    "S_u",  "S_v",   "S_uu",
                                             "S_uv", "S_vv", "S^w_u", "S^w_v"};

/* Per-quantity largest |ours - ref| and largest |ref|. */
typedef struct err_acc {
    double err[Q_COUNT], mag[Q_COUNT];
} err_acc;

static void acc_add(err_acc *e, int k, const double *ours, const double *ref, int dim)
{
    double de = 0.0, m = 0.0;
    for (int c = 0; c < dim; c++) {
        de += (ours[c] - ref[c]) * (ours[c] - ref[c]);
        m += ref[c] * ref[c];
    }
    e->err[k] = fmax(e->err[k], sqrt(de));
    e->mag[k] = fmax(e->mag[k], sqrt(m));
}

static double acc_rel(const err_acc *e, int k)
{
    return e->mag[k] > 0 ? e->err[k] / e->mag[k] : e->err[k];
}

static void test_derivs_random_surfaces(void **state)
{
    (void)state;
    const uint64_t seed = gt_seed();
    gt_rng r = {seed};
    double worst[Q_COUNT] = {0};
    long samples = 0;
    const int per_surface = 1000;
    for (int p = 1; p <= 7; p++)
        for (int q = 1; q <= 7; q++) {
            gt_surface g;
            gt_surface_make(&r, p, q, p + 1 + gt_int(&r, 0, 6), q + 1 + gt_int(&r, 0, 6), &g);
            double u0, u1, v0, v1;
            gt_domain(&g.s, &u0, &u1, &v0, &v1);
            err_acc e = {{0}, {0}};
            for (int k = 0; k < per_surface; k++) {
                const double u = gt_uniform(&r, u0, u1), v = gt_uniform(&r, v0, v1);
                sw_sg_surface_d2 ours, ref;
                double h1[12], hu[4], hv[4], p0[3];
                sw_sg_surface_eval_d2(&g.s, u, v, &ours);
                sw_sg_surface_eval_h1(&g.s, u, v, h1);
                sw_sg_surface_eval(&g.s, u, v, p0);
                ref_d2(&g.s, u, v, &ref, hu, hv);
                acc_add(&e, Q_P, ours.p, ref.p, 3);
                acc_add(&e, Q_P, p0, ref.p, 3);
                acc_add(&e, Q_U, ours.du, ref.du, 3);
                acc_add(&e, Q_V, ours.dv, ref.dv, 3);
                acc_add(&e, Q_UU, ours.duu, ref.duu, 3);
                acc_add(&e, Q_UV, ours.duv, ref.duv, 3);
                acc_add(&e, Q_VV, ours.dvv, ref.dvv, 3);
                acc_add(&e, Q_HU, h1 + 4, hu, 4);
                acc_add(&e, Q_HV, h1 + 8, hv, 4);
            }
            samples += per_surface;
            for (int k = 0; k < Q_COUNT; k++) {
                const double rel = acc_rel(&e, k);
                if (!(rel <= TOL))
                    printf("  degree %d x %d: %s error %.3g relative\n", p, q, q_names[k], rel);
                worst[k] = fmax(worst[k], rel);
                assert_true(rel <= TOL);
            }
            gt_surface_free(&g);
        }
    printf("derivatives vs bicomplex-step reference: seed %llu, 49 surfaces (degrees 1..7 x 1..7), "
           "%ld samples; max relative error:",
           (unsigned long long)seed, samples);
    for (int k = 0; k < Q_COUNT; k++)
        printf(" %s %.2g", q_names[k], worst[k]);
    printf(" (tolerance %.0e)\n", TOL);
}

/* Homogeneous curve derivatives (nd = 2) and the projected point, for dims 3 (trim curves) to 5. */
static void test_derivs_random_curves(void **state)
{
    (void)state;
    gt_rng r = {gt_seed() + 7};
    double worst[3] = {0};
    for (int trial = 0; trial < 300; trial++) {
        const int p = gt_int(&r, 1, 12), n = p + 1 + gt_int(&r, 0, 8), dim = gt_int(&r, 3, 5);
        double knots[64], cpw[32 * 5];
        gt_random_knots(&r, p, n, knots);
        for (int i = 0; i < n; i++) {
            const double w = gt_uniform(&r, 0.2, 5.0);
            for (int c = 0; c < dim - 1; c++)
                cpw[i * dim + c] = w * gt_uniform(&r, -1, 1);
            cpw[i * dim + dim - 1] = w;
        }
        sw_sg_curve c = {.degree = p, .n = n, .dim = dim, .knots = knots, .cpw = cpw};
        double t0, t1, mag[3] = {0}, err[3] = {0};
        sw_sg_knots_domain(knots, p, n, &t0, &t1);
        for (int k = 0; k < 200; k++) {
            const double t = gt_uniform(&r, t0, t1);
            bc nb[SW_SG_MAX_DEGREE + 2];
            const bc tt = bc_add(bc_add(bc_real(t), (bc){I * H, 0}), (bc){0, H});
            const int span = ref_basis(knots, p, n, tt, nb);
            double ours[3 * 5], ref[3][5] = {{0}}, pt[4];
            for (int i = 0; i <= p; i++)
                for (int d = 0; d < dim; d++) {
                    const double x = cpw[(span - p + i) * dim + d];
                    ref[0][d] += bc_re(nb[i]) * x;
                    ref[1][d] += bc_i(nb[i]) / H * x;
                    ref[2][d] += bc_ij(nb[i]) / (H * H) * x;
                }
            sw_sg_curve_eval_h(&c, t, 2, ours);
            sw_sg_curve_eval(&c, t, pt);
            for (int o = 0; o < 3; o++)
                for (int d = 0; d < dim; d++) {
                    err[o] = fmax(err[o], fabs(ours[o * dim + d] - ref[o][d]));
                    mag[o] = fmax(mag[o], fabs(ref[o][d]));
                }
            for (int d = 0; d < dim - 1; d++)
                assert_true(fabs(pt[d] - ref[0][d] / ref[0][dim - 1]) <= 1e-12);
        }
        for (int o = 0; o < 3; o++) {
            const double rel = mag[o] > 0 ? err[o] / mag[o] : err[o];
            worst[o] = fmax(worst[o], rel);
            assert_true(rel <= TOL);
        }
    }
    printf("curves (degrees 1..12, dim 3..5): 300 x 200 samples; max relative error C^w %.2g, "
           "C^w' %.2g, C^w'' %.2g\n",
           worst[0], worst[1], worst[2]);
}

/* ---- the exact torus ------------------------------------------------------------------------ */

static const double circle_xy[9][2] = {{1, 0},   {1, 1},  {0, 1},  {-1, 1}, {-1, 0},
                                       {-1, -1}, {0, -1}, {1, -1}, {1, 0}};
static const double circle_knots[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};

static double circle_w(int i)
{
    return i % 2 ? sqrt(0.5) : 1.0;
}

/* Angle and its first two derivatives at parameter x in [0, 4]; at a knot the right span. */
static void circle_angle(double x, double a[3])
{
    int k = (int)floor(x);
    if (k > 3)
        k = 3;
    const double t = x - k, tau = tan(M_PI / 8), y = 2 * t - 1, den = 1 + tau * tau * y * y;
    a[0] = k * M_PI / 2 + M_PI / 4 + 2 * atan(tau * y);
    a[1] = 4 * tau / den;
    a[2] = -16 * tau * tau * tau * y / (den * den);
}

static void test_derivs_exact_torus(void **state)
{
    (void)state;
    const double R = 3.0, rr = 1.0;
    double cpw[81 * 4];
    for (int j = 0; j < 9; j++)
        for (int i = 0; i < 9; i++) {
            const double w = circle_w(i) * circle_w(j);
            const double rho = R + rr * circle_xy[j][0], z = rr * circle_xy[j][1];
            double *pw = cpw + (j * 9 + i) * 4;
            pw[0] = w * rho * circle_xy[i][0];
            pw[1] = w * rho * circle_xy[i][1];
            pw[2] = w * z;
            pw[3] = w;
        }
    sw_sg_surface s = {.deg_u = 2,
                       .deg_v = 2,
                       .n_u = 9,
                       .n_v = 9,
                       .knots_u = circle_knots,
                       .knots_v = circle_knots,
                       .cpw = cpw};
    assert_int_equal(sw_sg_surface_validate(&s, "torus", NULL), SW_OK);

    gt_rng r = {gt_seed() + 11};
    err_acc e = {{0}, {0}};
    double worst_radius = 0.0;
    int count = 0;
    for (int k = 0; k < 10000 + 25; k++) {
        double u, v;
        if (k < 25) { /* every knot pair, including the closed end 4 */
            u = k % 5;
            v = k / 5;
        } else {
            u = gt_uniform(&r, 0, 4);
            v = gt_uniform(&r, 0, 4);
        }
        double th[3], ph[3];
        circle_angle(u, th);
        circle_angle(v, ph);
        const double ct = cos(th[0]), st = sin(th[0]), cp = cos(ph[0]), sp = sin(ph[0]);
        const double rho = R + rr * cp;
        sw_sg_surface_d2 ref = {
            .p = {rho * ct, rho * st, rr * sp},
            .du = {-th[1] * rho * st, th[1] * rho * ct, 0},
            .dv = {-ph[1] * rr * sp * ct, -ph[1] * rr * sp * st, ph[1] * rr * cp},
            .duu = {-th[2] * rho * st - th[1] * th[1] * rho * ct,
                    th[2] * rho * ct - th[1] * th[1] * rho * st, 0},
            .duv = {th[1] * ph[1] * rr * sp * st, -th[1] * ph[1] * rr * sp * ct, 0},
            .dvv = {-ph[2] * rr * sp * ct - ph[1] * ph[1] * rr * cp * ct,
                    -ph[2] * rr * sp * st - ph[1] * ph[1] * rr * cp * st,
                    ph[2] * rr * cp - ph[1] * ph[1] * rr * sp},
        };
        sw_sg_surface_d2 d;
        sw_sg_surface_eval_d2(&s, u, v, &d);
        acc_add(&e, Q_P, d.p, ref.p, 3);
        acc_add(&e, Q_U, d.du, ref.du, 3);
        acc_add(&e, Q_V, d.dv, ref.dv, 3);
        acc_add(&e, Q_UU, d.duu, ref.duu, 3);
        acc_add(&e, Q_UV, d.duv, ref.duv, 3);
        acc_add(&e, Q_VV, d.dvv, ref.dvv, 3);
        /* Distance to the core circle must be the minor radius exactly. */
        const double ring = hypot(d.p[0], d.p[1]) - R;
        worst_radius = fmax(worst_radius, fabs(hypot(ring, d.p[2]) - rr));
        count++;
    }
    printf("exact torus (R = 3, r = 1, 4 x 4 rational quadratic spans): %d samples; |dist - r| max "
           "%.2g; max relative error:",
           count, worst_radius);
    for (int k = Q_P; k <= Q_VV; k++)
        printf(" %s %.2g", q_names[k], acc_rel(&e, k));
    printf("\n");
    assert_true(worst_radius <= 1e-14 * R);
    for (int k = Q_P; k <= Q_VV; k++)
        assert_true(acc_rel(&e, k) <= TOL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_derivs_random_surfaces),
        cmocka_unit_test(test_derivs_random_curves),
        cmocka_unit_test(test_derivs_exact_torus),
    };
    return cmocka_run_group_tests_name("geom_derivs", tests, NULL, NULL);
}

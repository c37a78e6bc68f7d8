/* SPDX-License-Identifier: MIT */
/* lod/bezier/sampling.c against independent references (no GL):
 *  - the derivative bounds of random rational Bézier patches (degrees 1..5, weights 0.2..5, far
 *    from the origin) are >= the derivatives the scenegraph's NURBS evaluator
 * (sw_sg_surface_eval_d2) finds on a dense grid, equal for a polynomial quadratic (tight), and
 * translation-invariant;
 *  - a grid at the Filip density stays within eps of the surface at dense samples inside every
 *    triangle (the property the renderer relies on);
 *  - the object-space tolerance keeps random displacements inside the frustum within eps pixels
 *    when projected by a pinhole camera written here.
 */
#include "sw_lod_sampling.h"
#include "sw_sg_geom.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t g_rng = 0x9e3779b97f4a7c15ull;
static double rnd(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

typedef struct patch {
    int32_t p, q;
    double knots_u[12], knots_v[12];
    double cpw[6 * 6 * 4];
    sw_sg_surface s;
} patch;

static void make_patch(patch *pt, int32_t p, int32_t q, int rational, double offset)
{
    pt->p = p;
    pt->q = q;
    for (int i = 0; i <= p; ++i) {
        pt->knots_u[i] = 0.0;
        pt->knots_u[p + 1 + i] = 1.0;
    }
    for (int j = 0; j <= q; ++j) {
        pt->knots_v[j] = 0.0;
        pt->knots_v[q + 1 + j] = 1.0;
    }
    for (int j = 0; j <= q; ++j)
        for (int i = 0; i <= p; ++i) {
            double *c = pt->cpw + (j * (p + 1) + i) * 4;
            double w = rational ? 0.2 + 4.8 * rnd() * rnd() : 1.0;
            double x[3] = {offset + (double)i / p + 0.4 * (rnd() - 0.5),
                           offset + (double)j / q + 0.4 * (rnd() - 0.5), 0.5 * (rnd() - 0.5)};
            for (int k = 0; k < 3; ++k)
                c[k] = w * x[k];
            c[3] = w;
        }
    pt->s = (sw_sg_surface){p, q, p + 1, q + 1, pt->knots_u, pt->knots_v, pt->cpw};
}

static double n3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* max over a dense grid of |S_s|, |S_t|, |S_ss|, |S_st|, |S_tt|. */
static void measure(const patch *pt, double m[5])
{
    memset(m, 0, 5 * sizeof *m);
    for (int j = 0; j <= 60; ++j)
        for (int i = 0; i <= 60; ++i) {
            sw_sg_surface_d2 d;
            sw_sg_surface_eval_d2(&pt->s, i / 60.0, j / 60.0, &d);
            double v[5] = {n3(d.du), n3(d.dv), n3(d.duu), n3(d.duv), n3(d.dvv)};
            for (int k = 0; k < 5; ++k)
                m[k] = fmax(m[k], v[k]);
        }
}

static int check_bounds(const patch *pt, const sw_lod_patch_bounds *b, double *worst_ratio)
{
    double m[5], bd[5] = {b->d1[0], b->d1[1], b->d2[0], b->d2[1], b->d2[2]};
    measure(pt, m);
    int ok = 1;
    for (int k = 0; k < 5; ++k) {
        double scale = fmax(bd[k], 1e-12);
        if (m[k] > bd[k] + 1e-9 * scale) {
            fprintf(stderr, "  bound %d violated (deg %d,%d): measured %.9g > bound %.9g\n", k,
                    pt->p, pt->q, m[k], bd[k]);
            ok = 0;
        }
        if (m[k] > 1e-9)
            *worst_ratio = fmax(*worst_ratio, bd[k] / m[k]);
    }
    return ok;
}

/* Max deviation of the Filip grid's triangles (diagonal (0,0)-(1,1) of each cell) from the patch.
 */
static double grid_error(const patch *pt, int32_t nu, int32_t nv)
{
    double worst = 0.0;
    enum { SUB = 5 };
    for (int32_t b = 0; b < nv; ++b)
        for (int32_t a = 0; a < nu; ++a) {
            double c[4][3], s0 = (double)a / nu, t0 = (double)b / nv, ds = 1.0 / nu, dt = 1.0 / nv;
            sw_sg_surface_eval(&pt->s, s0, t0, c[0]);
            sw_sg_surface_eval(&pt->s, s0 + ds, t0, c[1]);
            sw_sg_surface_eval(&pt->s, s0 + ds, t0 + dt, c[2]);
            sw_sg_surface_eval(&pt->s, s0, t0 + dt, c[3]);
            for (int y = 0; y <= SUB; ++y)
                for (int x = 0; x <= SUB; ++x) {
                    double fx = (double)x / SUB, fy = (double)y / SUB, l[3], p[3];
                    for (int k = 0; k < 3; ++k)
                        l[k] = fx >= fy
                                   ? c[0][k] + fx * (c[1][k] - c[0][k]) + fy * (c[2][k] - c[1][k])
                                   : c[0][k] + fy * (c[3][k] - c[0][k]) + fx * (c[2][k] - c[3][k]);
                    sw_sg_surface_eval(&pt->s, s0 + fx * ds, t0 + fy * dt, p);
                    double d[3] = {p[0] - l[0], p[1] - l[1], p[2] - l[2]};
                    worst = fmax(worst, n3(d));
                }
        }
    return worst;
}

static int test_patches(void)
{
    int ok = 1, n = 0;
    double worst_ratio = 0.0, worst_grid = 0.0;
    for (int32_t p = 1; p <= 5; ++p)
        for (int32_t q = 1; q <= 5; ++q)
            for (int rep = 0; rep < 4; ++rep, ++n) {
                patch pt, moved;
                uint64_t seed = g_rng;
                make_patch(&pt, p, q, rep > 0, 0.0);
                g_rng = seed; /* the same patch far from the origin */
                make_patch(&moved, p, q, rep > 0, 1e4);
                sw_lod_patch_bounds b, bm;
                sw_lod_rational_bezier_bounds(p, q, pt.cpw, &b);
                sw_lod_rational_bezier_bounds(p, q, moved.cpw, &bm);
                ok &= check_bounds(&pt, &b, &worst_ratio);
                for (int k = 0; k < 3; ++k)
                    if (fabs(bm.d2[k] - b.d2[k]) > 1e-6 * fmax(b.d2[k], 1.0)) {
                        fprintf(stderr, "  bound not translation-invariant: %g vs %g\n", bm.d2[k],
                                b.d2[k]);
                        ok = 0;
                    }
                for (int e = 0; e < 2; ++e) {
                    double eps = e ? 1e-4 : 1e-2;
                    int32_t nu = sw_lod_filip_segments(b.d2[0], b.d2[1], 1.0, eps, 4096);
                    int32_t nv = sw_lod_filip_segments(b.d2[2], b.d2[1], 1.0, eps, 4096);
                    if (nu * nv > 10000)
                        continue;
                    double err = grid_error(&pt, nu, nv);
                    worst_grid = fmax(worst_grid, err / eps);
                    if (err > eps) {
                        fprintf(stderr, "  grid %dx%d of a (%d,%d) patch: error %g > eps %g\n", nu,
                                nv, p, q, err, eps);
                        ok = 0;
                    }
                }
            }
    printf("sampling: %d patches; bounds hold (worst bound/measured %.2f); Filip grids reach at "
           "most %.3f of eps\n",
           n, worst_ratio, worst_grid);
    return ok;
}

/* A polynomial patch whose rows are one parabola: S_ss is constant and the bound is exact. */
static int test_tight(void)
{
    int ok = 1;
    sw_lod_patch_bounds b;
    double m[5];
    patch line;
    make_patch(&line, 2, 1, 0, 0.0);
    for (int j = 0; j < 2; ++j) /* every row the same parabola */
        for (int i = 0; i < 3; ++i) {
            double *c = line.cpw + (j * 3 + i) * 4;
            c[0] = i * 0.5;
            c[1] = j;
            c[2] = (i == 1) ? 1.0 : 0.0;
        }
    sw_lod_rational_bezier_bounds(2, 1, line.cpw, &b);
    measure(&line, m);
    if (fabs(b.d2[0] - m[2]) > 1e-9 * m[2]) {
        fprintf(stderr, "  parabola: bound %g, exact %g\n", b.d2[0], m[2]);
        ok = 0;
    }
    printf("sampling: parabola S_ss bound %.6g vs exact %.6g\n", b.d2[0], m[2]);

    /* A quarter cylinder (exact rational quadratic x line): straight along t, so S_st = S_tt = 0
     * and one segment suffices that way. */
    patch cyl;
    make_patch(&cyl, 2, 1, 1, 0.0);
    static const double arc[3][3] = {{1, 0, 1}, {1, 1, 0.70710678118654752}, {0, 1, 1}};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) {
            double *c = cyl.cpw + (j * 3 + i) * 4, w = arc[i][2];
            c[0] = w * (5.0 + arc[i][0]);
            c[1] = w * arc[i][1];
            c[2] = w * 3.0 * j;
            c[3] = w;
        }
    sw_lod_rational_bezier_bounds(2, 1, cyl.cpw, &b);
    printf("sampling: quarter cylinder bounds S_ss %.4g S_st %.3g S_tt %.3g\n", b.d2[0], b.d2[1],
           b.d2[2]);
    if (!(b.d2[1] <= 1e-9 && b.d2[2] <= 1e-9) ||
        sw_lod_filip_segments(b.d2[2], b.d2[1], 1.0, 1e-6, 256) != 1)
        ok = 0;
    return ok;
}

/* Pinhole projection to pixels of an eye-space point (x right, y up, z depth). */
static void project(const double p[3], double focal, double out[2])
{
    out[0] = focal * p[0] / p[2];
    out[1] = focal * p[1] / p[2];
}

static int test_object_tolerance(void)
{
    double tan_y = tan(20.0 * M_PI / 180.0), tan_x = tan_y * 16.0 / 9.0, focal = 360.0 / tan_y;
    double worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
        double z = 0.1 + 100.0 * rnd();
        double p[3] = {(2 * rnd() - 1) * tan_x * z, (2 * rnd() - 1) * tan_y * z, z};
        double eps = sw_lod_object_tolerance(0.5, z, focal, tan_x, tan_y);
        double d[3] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5}, nd = n3(d);
        double q[3] = {p[0] + eps * d[0] / nd, p[1] + eps * d[1] / nd, p[2] + eps * d[2] / nd};
        double a[2], b[2];
        project(p, focal, a);
        project(q, focal, b);
        worst = fmax(worst, hypot(a[0] - b[0], a[1] - b[1]));
    }
    printf("sampling: object tolerance for 0.5 px moves points at most %.4f px\n", worst);
    return worst <= 0.5 * (1.0 + 1e-3);
}

int main(void)
{
    int ok = test_patches();
    ok &= test_tight();
    ok &= test_object_tolerance();
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

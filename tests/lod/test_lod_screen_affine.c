/* SPDX-License-Identifier: MIT */
/* The affine fast path of the screen-space grid density (lod/bezier/sampling.c affine_segments):
 * planes' patches take the coarsest allowed grid without the full bound, and must stay within
 * ε_img. Random views of random patches, degrees 1-5 in each direction, eye-relative as the frame
 * gives them, over random ranges of their local domain:
 *  - exact planes (an affine map of the parameters, equal weights): the fast path's grid is the
 *    coarsest allowed and equals the full bound's choice; its eps_obj equals the full bound's; its
 *    d1 is at least the largest derivative sampled densely;
 *  - planes with every pole displaced by delta (near-affine, delta from far below to far above
 *    the pixel's tolerance) and curved patches: the grid chosen with the fast path on is checked
 *    against the screen error measured independently: the patch point (sw_sg_bezier_patch_eval)
 *    and the grid triangle's point at the same parameters, both projected, on a dense sample of
 *    every cell (both diagonals), must be within eps_px where the triangle is drawn (in front of
 *    the near plane, inside the frustum: the bound's P is capped by the frustum's corner).
 * Catches a fast-path test that is too lax (planted: 2 delta (1 + P) f <= 10 eps z: 8 of 400
 * near-affine patches over 0.5 px, up to 0.97 px) and a fast path taken for unequal weights.
 * Also the coarsest-grid fast path (whole_measure: difference bounds first, the second-derivative
 * products skipped when they already pass the coarsest grid): curved rational patches of degrees
 * 1-7 and pieces of cylinders from near to far, with it on and off, must give the same grid,
 * eps_obj and d1 bit for bit (catches the path skipping the first-derivative products: planted: 159
 * of 400 differ in d1), and the coarsest grids chosen must be within eps_px measured as above.
 * Usage: test_lod_screen_affine [N] (N patches of each kind, default 400). */
#include "sw_lod_sampling.h"
#include "sw_sg_geom.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t g_rng = 0x2545F4914F6CDD1Dull;

static double rnd(void) /* [0, 1) */
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

static void normalize(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k)
        v[k] /= n;
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* A camera looking at the origin from a random direction at distance `dist`; the patch is placed
 * eye-relative, so the eye is at 0 and the patch around -eye. */
static void random_view(double dist, sw_lod_screen_view *v, double eye[3])
{
    double d[3] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5}, up[3] = {0, 0, 1};
    normalize(d);
    for (int k = 0; k < 3; ++k) {
        eye[k] = -d[k] * dist;
        v->fwd[k] = d[k];
    }
    cross(v->fwd, up, v->right);
    normalize(v->right);
    cross(v->right, v->fwd, v->up);
    const double tan_y = tan(20.0 * M_PI / 180.0), aspect = 16.0 / 9.0;
    v->focal_px = 720.0 / (2.0 * tan_y);
    v->tan_corner = tan_y * sqrt(1.0 + aspect * aspect);
    v->near_plane = 0.01;
    v->eps_px = 0.5;
}

typedef enum kind { PLANE, NEAR_PLANE, CURVED } kind;

/* Homogeneous net (u fastest) of a patch of size ~1 around the origin, moved by -eye. */
static void random_patch(kind k, int32_t p, int32_t q, double delta, const double eye[3],
                         double *cpw)
{
    double o[3], a[3], b[3];
    for (int c = 0; c < 3; ++c) {
        o[c] = rnd() - 0.5;
        a[c] = 2.0 * rnd() - 1.0;
        b[c] = 2.0 * rnd() - 1.0;
    }
    const double w = k == CURVED ? 1.0 : 0.5 + rnd();
    for (int32_t j = 0; j <= q; ++j)
        for (int32_t i = 0; i <= p; ++i) {
            double *c = cpw + 4 * ((size_t)j * (p + 1) + i);
            double dir[3] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5};
            normalize(dir);
            const double off = k == NEAR_PLANE ? delta : k == CURVED ? 0.3 * rnd() : 0.0;
            for (int e = 0; e < 3; ++e)
                c[e] = (o[e] + a[e] * i / p + b[e] * j / q + off * dir[e] - eye[e]) * w;
            c[3] = k == CURVED ? 0.5 + rnd() : w;
            if (k == CURVED)
                for (int e = 0; e < 3; ++e)
                    c[e] *= c[3];
        }
}

static void project(const sw_lod_screen_view *v, const double x[3], double out[2])
{
    double z = v->fwd[0] * x[0] + v->fwd[1] * x[1] + v->fwd[2] * x[2];
    out[0] = v->focal_px * (v->right[0] * x[0] + v->right[1] * x[1] + v->right[2] * x[2]) / z;
    out[1] = v->focal_px * (v->up[0] * x[0] + v->up[1] * x[1] + v->up[2] * x[2]) / z;
}

static double depth(const sw_lod_screen_view *v, const double x[3])
{
    return v->fwd[0] * x[0] + v->fwd[1] * x[1] + v->fwd[2] * x[2];
}

/* The largest screen distance between the patch and its nu x nv grid over range, sampled on every
 * cell with both diagonals; points not in front of the near plane are left out (clipped). */
static double grid_error_px(const sw_sg_bezier_patch *bp, const double r[4], int32_t nu, int32_t nv,
                            const sw_lod_screen_view *v)
{
    enum { S = 6 };
    double worst = 0.0;
    for (int32_t b = 0; b < nv; ++b)
        for (int32_t a = 0; a < nu; ++a) {
            double s0 = r[0] + (r[1] - r[0]) * a / nu, s1 = r[0] + (r[1] - r[0]) * (a + 1) / nu;
            double t0 = r[2] + (r[3] - r[2]) * b / nv, t1 = r[2] + (r[3] - r[2]) * (b + 1) / nv;
            double c[4][3];
            sw_sg_bezier_patch_eval(bp, s0, t0, c[0]);
            sw_sg_bezier_patch_eval(bp, s1, t0, c[1]);
            sw_sg_bezier_patch_eval(bp, s0, t1, c[2]);
            sw_sg_bezier_patch_eval(bp, s1, t1, c[3]);
            for (int y = 0; y <= S; ++y)
                for (int x = 0; x <= S; ++x) {
                    double fx = (double)x / S, fy = (double)y / S, p[3], t[2][3];
                    sw_sg_bezier_patch_eval(bp, s0 + (s1 - s0) * fx, t0 + (t1 - t0) * fy, p);
                    for (int e = 0; e < 3; ++e) {
                        /* diagonal 0-3: the triangle (0,1,3) below it, (0,3,2) above */
                        t[0][e] =
                            fx >= fy
                                ? c[0][e] + fx * (c[1][e] - c[0][e]) + fy * (c[3][e] - c[1][e])
                                : c[0][e] + fy * (c[2][e] - c[0][e]) + fx * (c[3][e] - c[2][e]);
                        /* diagonal 1-2: (0,1,2) below it, (1,3,2) above */
                        t[1][e] = fx + fy <= 1.0 ? c[0][e] + fx * (c[1][e] - c[0][e]) +
                                                       fy * (c[2][e] - c[0][e])
                                                 : c[3][e] + (1.0 - fx) * (c[2][e] - c[3][e]) +
                                                       (1.0 - fy) * (c[1][e] - c[3][e]);
                    }
                    if (depth(v, p) <= v->near_plane)
                        continue;
                    double pp[2];
                    project(v, p, pp);
                    for (int d = 0; d < 2; ++d) {
                        if (depth(v, t[d]) <= v->near_plane)
                            continue;
                        double tp[2];
                        project(v, t[d], tp);
                        /* the bound holds where the triangle is drawn: inside the frustum */
                        if (fabs(tp[0]) > v->focal_px * v->tan_corner ||
                            fabs(tp[1]) > v->focal_px * v->tan_corner)
                            continue;
                        worst = fmax(worst, hypot(tp[0] - pp[0], tp[1] - pp[1]));
                    }
                }
        }
    return worst;
}

static const int32_t k_allowed[] = {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256};
enum { N_ALLOWED = sizeof k_allowed / sizeof k_allowed[0] };

static int same_density(const sw_lod_screen_density *a, const sw_lod_screen_density *b)
{
    return a->nu == b->nu && a->nv == b->nv && a->eps_obj == b->eps_obj && a->d1[0] == b->d1[0] &&
           a->d1[1] == b->d1[1];
}

/* A piece of a cylinder of radius ~0.5 as CAD files store it (rational quadratic arc x line,
 * weights 1, cos(a/2), 1), randomly turned, around the origin moved by -eye: its first-derivative
 * product bounds are tighter than the difference bounds, which random nets rarely show. */
static void random_cylinder(const double eye[3], int32_t *p, int32_t *q, double *cpw)
{
    const double a = 0.3 + 1.8 * rnd(), r = 0.2 + 0.6 * rnd(), h = 0.2 + rnd(), w = cos(0.5 * a);
    const double arc[3][3] = {{r, 0, 0}, {r, r * tan(0.5 * a), 0}, {r * cos(a), r * sin(a), 0}};
    double x[3] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5}, y[3], z[3], t[3] = {0, 0, 1};
    normalize(x);
    cross(x, t, y);
    normalize(y);
    cross(x, y, z);
    *p = 2;
    *q = 1;
    for (int32_t j = 0; j <= 1; ++j)
        for (int32_t i = 0; i <= 2; ++i) {
            double *c = cpw + 4 * ((size_t)j * 3 + i), wi = i == 1 ? w : 1.0;
            for (int e = 0; e < 3; ++e)
                c[e] =
                    (arc[i][0] * x[e] + arc[i][1] * y[e] + (j * h - 0.5 * h) * z[e] - eye[e]) * wi;
            c[3] = wi;
        }
}

/* The coarsest-grid fast path against the full analysis; returns the failures. */
static int check_coarsest_fast(int n)
{
    int failures = 0, coarsest = 0;
    double worst = 0.0;
    for (int it = 0; it < n; ++it) {
        int32_t p = 1 + (int32_t)(rnd() * 7), q = 1 + (int32_t)(rnd() * 7);
        sw_lod_screen_view v;
        double eye[3], cpw[8 * 8 * 4];
        /* distances of 1.5 to ~6000 patch sizes: fine grids near, the coarsest far */
        random_view(1.5 * pow(4000.0, rnd()), &v, eye);
        if (it % 2)
            random_cylinder(eye, &p, &q, cpw);
        else
            random_patch(CURVED, p, q, 0.0, eye, cpw);
        double r0 = 0.5 * rnd(), r2 = 0.5 * rnd();
        const double range[4] = {r0, r0 + (1.0 - r0) * (0.2 + 0.8 * rnd()), r2,
                                 r2 + (1.0 - r2) * (0.2 + 0.8 * rnd())};
        sw_lod_screen_density fast, full;
        sw_lod_screen_coarsest_fast(1);
        int ok_fast = sw_lod_screen_segments(p, q, cpw, range, &v, k_allowed, N_ALLOWED, 4, &fast);
        sw_lod_screen_coarsest_fast(0);
        int ok_full = sw_lod_screen_segments(p, q, cpw, range, &v, k_allowed, N_ALLOWED, 4, &full);
        sw_lod_screen_coarsest_fast(1);
        if (ok_fast != ok_full || !same_density(&fast, &full)) {
            fprintf(stderr,
                    "coarsest %d (%dx%d): fast %d x %d eps %.17g d1 %.17g %.17g, full %d x %d "
                    "eps %.17g d1 %.17g %.17g\n",
                    it, p, q, fast.nu, fast.nv, fast.eps_obj, fast.d1[0], fast.d1[1], full.nu,
                    full.nv, full.eps_obj, full.d1[0], full.d1[1]);
            failures++;
        }
        if (ok_fast && fast.nu == k_allowed[0] && fast.nv == k_allowed[0]) {
            coarsest++;
            sw_sg_bezier_patch bp = {p, q, 0, 0, 0, 1, 0, 1, cpw};
            const double err = grid_error_px(&bp, range, fast.nu, fast.nv, &v);
            worst = fmax(worst, err);
            if (err > v.eps_px + 1e-9) {
                fprintf(stderr, "coarsest %d (%dx%d): error %.4f px > %.2f\n", it, p, q, err,
                        v.eps_px);
                failures++;
            }
        }
    }
    printf("coarsest-grid fast path: %d of %d curved patches on the coarsest grid (worst %.4f "
           "px), the same densities with it off\n",
           coarsest, n, worst);
    /* a quarter at least, or the comparison says little about the fast path */
    if (coarsest < n / 4) {
        fprintf(stderr, "only %d of %d patches took the coarsest grid\n", coarsest, n);
        failures++;
    }
    return failures;
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 400;
    int failures = 0, fast_taken = 0, near_fast = 0;
    double worst_near = 0.0, worst_curved = 0.0;
    for (int kk = 0; kk < 3; ++kk)
        for (int it = 0; it < n; ++it) {
            const kind k = (kind)kk;
            int32_t p = 1 + (int32_t)(rnd() * 5), q = 1 + (int32_t)(rnd() * 5);
            sw_lod_screen_view v;
            double eye[3], cpw[6 * 6 * 4];
            random_view(1.5 + 40.0 * rnd() * rnd(), &v, eye);
            /* delta from 1e-7 to 1e-1 of the patch's size: across the tolerance of a pixel */
            const double delta = pow(10.0, -7.0 + 6.0 * rnd());
            random_patch(k, p, q, delta, eye, cpw);
            double r0 = 0.5 * rnd(), r2 = 0.5 * rnd();
            const double range[4] = {r0, r0 + (1.0 - r0) * (0.2 + 0.8 * rnd()), r2,
                                     r2 + (1.0 - r2) * (0.2 + 0.8 * rnd())};
            sw_lod_screen_density fast, full;
            sw_lod_screen_affine_fast(1);
            int ok_fast =
                sw_lod_screen_segments(p, q, cpw, range, &v, k_allowed, N_ALLOWED, 4, &fast);
            sw_lod_screen_affine_fast(0);
            int ok_full =
                sw_lod_screen_segments(p, q, cpw, range, &v, k_allowed, N_ALLOWED, 4, &full);
            sw_lod_screen_affine_fast(1);
            sw_sg_bezier_patch bp = {p, q, 0, 0, 0, 1, 0, 1, cpw};
            if (k == PLANE) {
                if (!ok_fast || fast.nu != 1 || fast.nv != 1 || full.nu != 1 || full.nv != 1 ||
                    fabs(fast.eps_obj - full.eps_obj) > 1e-12 * full.eps_obj) {
                    fprintf(stderr, "plane %d (%dx%d): fast %d x %d eps %g, full %d x %d eps %g\n",
                            it, p, q, fast.nu, fast.nv, fast.eps_obj, full.nu, full.nv,
                            full.eps_obj);
                    failures++;
                }
                /* d1 bounds the derivative (local patch parameters) sampled densely */
                for (int y = 0; y <= 8; ++y)
                    for (int x = 0; x <= 8; ++x) {
                        const double h = 1e-6, s = range[0] + (range[1] - range[0]) * x / 8.0,
                                     t = range[2] + (range[3] - range[2]) * y / 8.0;
                        double a[3], b[3], c[3];
                        sw_sg_bezier_patch_eval(&bp, fmin(s + h, 1.0), t, a);
                        sw_sg_bezier_patch_eval(&bp, s, fmin(t + h, 1.0), c);
                        sw_sg_bezier_patch_eval(&bp, s, fmin(t + h, 1.0) - h, b);
                        double dt = hypot(hypot(c[0] - b[0], c[1] - b[1]), c[2] - b[2]) / h;
                        sw_sg_bezier_patch_eval(&bp, fmin(s + h, 1.0) - h, t, b);
                        double ds = hypot(hypot(a[0] - b[0], a[1] - b[1]), a[2] - b[2]) / h;
                        if (ds > fast.d1[0] * (1.0 + 1e-6) || dt > fast.d1[1] * (1.0 + 1e-6)) {
                            fprintf(stderr, "plane %d: |S_s| %g, |S_t| %g above d1 %g, %g\n", it,
                                    ds, dt, fast.d1[0], fast.d1[1]);
                            failures++;
                            x = y = 9;
                        }
                    }
                fast_taken++;
                continue;
            }
            const double err = grid_error_px(&bp, range, fast.nu, fast.nv, &v);
            if (k == NEAR_PLANE) {
                worst_near = fmax(worst_near, err);
                near_fast += fast.nu == 1 && fast.nv == 1 && (full.nu != 1 || full.nv != 1);
            } else
                worst_curved = fmax(worst_curved, err);
            /* 1e-9 px: the projection's own rounding */
            if (ok_fast && ok_full && err > v.eps_px + 1e-9) {
                fprintf(stderr, "%s %d (%dx%d, delta %g): grid %d x %d, error %.4f px > %.2f\n",
                        k == NEAR_PLANE ? "near-plane" : "curved", it, p, q, delta, fast.nu,
                        fast.nv, err, v.eps_px);
                failures++;
            }
        }
    printf("%d planes on the fast path; near-planes: worst %.4f px, %d drawn coarser than the "
           "full bound would; curved: worst %.4f px (limit 0.5)\n",
           fast_taken, worst_near, near_fast, worst_curved);
    failures += check_coarsest_fast(n);
    if (failures)
        fprintf(stderr, "%d failure(s)\n", failures);
    return failures != 0;
}

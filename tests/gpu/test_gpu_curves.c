/* SPDX-License-Identifier: MIT */
/* Exact anti-aliased outlines (gpu/curves.c; Santana §3-§5) against exact
 * area coverage computed here in double precision.
 *
 * One curve class per run (argv[2]): quadratic (a closed quadratic B-spline, TrueType-like, no
 * corner), conic (an annulus of two rational-quadratic circles, even-odd), loop (a cubic whose
 * loop lies inside its parameter range, closed by a line), cusp (a cubic with a cusp, closed by a
 * line), nurbs7 (a rational degree-7 NURBS with interior knots, closed by a line: drawn through
 * the Hermite approximation, whose bound must stay <= SW__CURVES_REFIT_PX = 1/32 px at every
 * zoom).
 *
 * Each is drawn at zooms x1, x10, x100, x1000 (and x0.08, where the shape is ~15 px wide and
 * takes the 8x view-based path of §5), rotated, with a sub-pixel offset, into a 256x256 RGBA8
 * target whose left half is first filled with an opaque green rectangle and whose right half with
 * dark blue: the red shape is composited over both, so red = coverage and the background channel
 * must be (1 - coverage) times its colour (the "over" composite checked on every pixel).
 *
 * The reference: the outline flattened in pixel space (double precision) until every control
 * point of every subdivided rational Bézier piece lies within 1e-3 px of its chord (the convex
 * hull property then puts the curve within 1e-3 px of the polyline), then for each pixel square
 * S the area of the polygon inside S by Green's theorem over the outline clamped to S:
 * A = sum over edges of integral (clamp(x) - x0) d clamp(y), exact for straight edges (the
 * clamp is a retraction onto S homotopic to the identity outside S's interior, so winding
 * numbers inside S are kept).
 *
 * Pass: along edges (pixels whose reference or rendered coverage is fractional) the mean error
 * <= 2/255; every pixel whose centre is more than 1 px from a corner, cusp or self-crossing
 * within 12/255. Pixels near those points are reported separately.
 *
 * What it catches: with `plant` as argv[3] the renderer runs with a sign error planted in the
 * implicit form (k^n + l m instead of k^n - l m, glsl/curves.frag.glsl's u_fault): every curved
 * triangle then fills its whole hull or nothing, the coverage is off by up to 255/255 along every
 * curved edge, and the run must fail (ctest test_gpu_curves_planted has WILL_FAIL). Similar
 * errors the comparison catches: a wrong s_in / s_chord orientation, k, l, m of the wrong cubic
 * class, a band too narrow or cut lines overlapping at joins, a missing re-approximation.
 */
#include "curves_reference.h"
#include "sw_curves.h"
#include "sw_gpu.h"

#include <GL/glcorearb.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define W 256
#define H 256
#define S0 110.0 /* px per model unit at zoom 1 */
#define ROT 0.13

/* ---- the test shapes ------------------------------------------------------------------------- */

typedef struct tcurve {
    int deg, n;
    double knots[64];
    double cpw[3 * 48];
} tcurve;

typedef struct tshape {
    tcurve c[4];
    int n_curves;
    int loop_of[4]; /* loop index of each curve (curves of one loop are consecutive) */
    double sign[4]; /* the reference's winding weight per loop */
    int n_loops;
    double corners[8][2];
    int n_corners;
    double focus[2]; /* an on-curve point the zooms centre on */
} tshape;

static void line_curve(tcurve *c, const double a[2], const double b[2])
{
    c->deg = 1;
    c->n = 2;
    double k[4] = {0, 0, 1, 1};
    memcpy(c->knots, k, sizeof k);
    double p[6] = {a[0], a[1], 1, b[0], b[1], 1};
    memcpy(c->cpw, p, sizeof p);
}

static void circle(tcurve *c, double cx, double cy, double r, double phase)
{
    c->deg = 2;
    c->n = 9;
    double k[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    memcpy(c->knots, k, sizeof k);
    for (int i = 0; i < 9; ++i) {
        double a = phase + M_PI / 4 * i, w = (i % 2) ? sqrt(0.5) : 1.0,
               rr = (i % 2) ? r * sqrt(2) : r;
        c->cpw[3 * i] = w * (cx + rr * cos(a));
        c->cpw[3 * i + 1] = w * (cy + rr * sin(a));
        c->cpw[3 * i + 2] = w;
    }
    c->cpw[24] = c->cpw[0]; /* bit-identical closure */
    c->cpw[25] = c->cpw[1];
}

static void eval(const tcurve *c, double t, double out[2])
{
    sw_sg_curve g = {c->deg, c->n, 3, c->knots, c->cpw};
    sw_sg_curve_eval(&g, t, out);
}

static int make_shape(const char *cls, tshape *s)
{
    memset(s, 0, sizeof *s);
    if (!strcmp(cls, "quadratic")) {
        const int n = 7;
        double q[7][2];
        for (int i = 0; i < n; ++i) {
            double a = 2 * M_PI * i / n + 0.3, r = (i % 2) ? 0.5 : 0.95;
            q[i][0] = r * cos(a);
            q[i][1] = r * sin(a);
        }
        tcurve *c = &s->c[0];
        c->deg = 2;
        c->n = n + 2;
        double m[2] = {0.5 * (q[n - 1][0] + q[0][0]), 0.5 * (q[n - 1][1] + q[0][1])};
        int k = 0;
        for (int i = 0; i < 3; ++i)
            c->knots[k++] = 0;
        for (int i = 1; i < n; ++i)
            c->knots[k++] = i;
        for (int i = 0; i < 3; ++i)
            c->knots[k++] = n;
        double pts[9][2];
        memcpy(pts[0], m, sizeof m);
        memcpy(pts[1], q, sizeof(double) * 2 * n);
        memcpy(pts[n + 1], m, sizeof m);
        for (int i = 0; i < n + 2; ++i) {
            c->cpw[3 * i] = pts[i][0];
            c->cpw[3 * i + 1] = pts[i][1];
            c->cpw[3 * i + 2] = 1;
        }
        s->n_curves = 1;
        s->n_loops = 1;
        s->sign[0] = 1;
        eval(c, 2.3, s->focus);
    } else if (!strcmp(cls, "conic")) {
        circle(&s->c[0], 0, 0, 0.9, 0.2);
        circle(&s->c[1], 0.2, 0.1, 0.45, 1.1);
        s->loop_of[1] = 1;
        s->n_curves = 2;
        s->n_loops = 2;
        s->sign[0] = 1;
        s->sign[1] = -1;
        eval(&s->c[0], 0.6, s->focus);
    } else if (!strcmp(cls, "loop") || !strcmp(cls, "cusp")) {
        int loop = !strcmp(cls, "loop");
        double b[4][2] = {{0, 0}, {1, 1}, {0, 1}, {1, 0}};
        if (loop) {
            b[1][0] = 1.5;
            b[1][1] = 1.1;
            b[2][0] = -0.5;
            b[2][1] = 1.1;
        }
        tcurve *c = &s->c[0];
        c->deg = 3;
        c->n = 4;
        double k[8] = {0, 0, 0, 0, 1, 1, 1, 1};
        memcpy(c->knots, k, sizeof k);
        for (int i = 0; i < 4; ++i) {
            b[i][0] = 1.8 * b[i][0] - 0.9;
            b[i][1] = 1.8 * b[i][1] - 0.7;
            c->cpw[3 * i] = b[i][0];
            c->cpw[3 * i + 1] = b[i][1];
            c->cpw[3 * i + 2] = 1;
        }
        line_curve(&s->c[1], b[3], b[0]);
        s->n_curves = 2;
        s->n_loops = 1;
        s->sign[0] = 1;
        memcpy(s->corners[0], b[0], sizeof b[0]);
        memcpy(s->corners[1], b[3], sizeof b[3]);
        s->n_corners = 2;
        eval(c, loop ? 0.4 : 0.42, s->focus);
    } else if (!strcmp(cls, "nurbs7")) {
        tcurve *c = &s->c[0];
        c->deg = 7;
        c->n = 12;
        double k[20] = {0, 0, 0, 0, 0, 0, 0, 0, 0.15, 0.3, 0.45, 0.7, 1, 1, 1, 1, 1, 1, 1, 1};
        memcpy(c->knots, k, sizeof k);
        for (int i = 0; i < 12; ++i) {
            double a = M_PI * i / 11.0;
            double x = 0.9 * cos(a) + 0.12 * sin(3.0 * i);
            double y = -0.5 + 1.4 * sin(a) + 0.15 * cos(2.0 * i) * (i > 0 && i < 11);
            double w = 1.0 + 0.6 * sin(1.7 * i);
            if (i == 0 || i == 11) {
                x = i ? -0.9 : 0.9;
                y = -0.5;
            }
            c->cpw[3 * i] = w * x;
            c->cpw[3 * i + 1] = w * y;
            c->cpw[3 * i + 2] = w;
        }
        double a[2] = {-0.9, -0.5}, b[2] = {0.9, -0.5};
        line_curve(&s->c[1], a, b);
        s->n_curves = 2;
        s->n_loops = 1;
        s->sign[0] = 1;
        memcpy(s->corners[0], a, sizeof a);
        memcpy(s->corners[1], b, sizeof b);
        s->n_corners = 2;
        eval(c, 0.37, s->focus);
    } else {
        return 0;
    }
    return 1;
}

/* ---- reference: flattening and exact clipped area ----------------------------------------------
 */

static void to_px(const double v[6], const double p[2], double out[2])
{
    out[0] = v[0] * p[0] + v[1] * p[1] + v[2];
    out[1] = v[3] * p[0] + v[4] * p[1] + v[5];
}

typedef struct px_flatten {
    const double *v;
    ref_poly *pl;
} px_flatten;

/* One Bézier piece mapped to pixel space (an affine map: weights kept) and flattened. */
static void flatten_piece(void *ctx, const double *cpw, int p)
{
    const px_flatten *f = ctx;
    double h[3 * 32];
    for (int i = 0; i <= p; ++i) {
        double e[2] = {cpw[3 * i] / cpw[3 * i + 2], cpw[3 * i + 1] / cpw[3 * i + 2]}, q[2];
        to_px(f->v, e, q);
        double w = cpw[3 * i + 2];
        h[3 * i] = w * q[0];
        h[3 * i + 1] = w * q[1];
        h[3 * i + 2] = w;
    }
    ref_flatten_bezier(h, p, f->pl, 0);
}

/* A curve's Bézier pieces (full knot insertion) flattened in pixel space. */
static void flatten_curve(const tcurve *c, const double v[6], ref_poly *pl)
{
    px_flatten f = {v, pl};
    ref_curve_pieces(c->deg, c->n, c->knots, c->cpw, flatten_piece, &f);
}

/* A local form's value and gradient (polynomial kinds only), for the probe. */
static double probe_form(const double *cf, double U, double V, double g[2])
{
    g[0] =
        cf[1] + 2 * cf[3] * U + cf[4] * V + 3 * cf[6] * U * U + 2 * cf[7] * U * V + cf[8] * V * V;
    g[1] =
        cf[2] + cf[4] * U + 2 * cf[5] * V + cf[7] * U * U + 2 * cf[8] * U * V + 3 * cf[9] * V * V;
    return cf[0] + cf[1] * U + cf[2] * V + cf[3] * U * U + cf[4] * U * V + cf[5] * V * V +
           cf[6] * U * U * U + cf[7] * U * U * V + cf[8] * U * V * V + cf[9] * V * V * V;
}

/* ---- timing (argv[3] "time"; figures for docs/curves.md, not a pass/fail test) ----------------
 */

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median wall time of shape creation, and of a draw (until glFinish) at zoom x1 and x1000 with
 * the view held still and with the view moving by a sub-pixel offset every draw. */
static void time_draws(sw__curves_renderer *r, const sw__curves_loop *loops, uint32_t n_loops,
                       const tshape *ts, GLuint fbo)
{
    enum { N = 41 };
    double t[N];
    sw_status st = {0};
    for (double zc = 1; zc <= 1000; zc *= 1000) {
        size_t np = 0;
        for (int i = 0; i < N; ++i) {
            sw__curves_shape *sh = NULL;
            double t0 = now_ms();
            if (sw__curves_shape_create(loops, n_loops, S0 * zc, &sh, &st) != SW_OK)
                return;
            t[i] = now_ms() - t0;
            np = sh->n_pieces;
            sw__curves_shape_free(sh);
        }
        qsort(t, N, sizeof t[0], cmp_double);
        printf("  shape create (x%g tolerance): median %.3f ms (%zu pieces)\n", zc, t[N / 2], np);
    }
    sw__curves_shape *shape = NULL;
    if (sw__curves_shape_create(loops, n_loops, S0, &shape, &st) != SW_OK)
        return;
    static const double zooms[2] = {1, 1000};
    for (int z = 0; z < 2; ++z)
        for (int moving = 0; moving < 2; ++moving) {
            double s = S0 * zooms[z], c = cos(ROT), sn = sin(ROT), centre[2];
            if (zooms[z] <= 1.0) {
                centre[0] = 0.5 * (shape->box[0] + shape->box[2]);
                centre[1] = 0.5 * (shape->box[1] + shape->box[3]);
            } else {
                memcpy(centre, ts->focus, sizeof centre);
            }
            sw__curves_view view = {{s * c, -s * sn, 0, s * sn, s * c, 0}, W, H};
            const float red[4] = {1, 0, 0, 1};
            for (int i = -1; i < N; ++i) { /* i = -1: warm-up (re-approximation, first upload) */
                double off = moving ? 0.01 * i : 0.0;
                view.m[2] = W / 2 + 0.37 + off - (view.m[0] * centre[0] + view.m[1] * centre[1]);
                view.m[5] = H / 2 + 0.21 - (view.m[3] * centre[0] + view.m[4] * centre[1]);
                glFinish();
                double t0 = now_ms();
                if (sw__curves_draw(r, shape, &view, red, fbo, &st) != SW_OK) {
                    fprintf(stderr, "FAIL: draw: %s\n", st.message);
                    return;
                }
                glFinish();
                if (i >= 0)
                    t[i] = now_ms() - t0;
            }
            qsort(t, N, sizeof t[0], cmp_double);
            printf("  draw x%g, view %s: median %.3f ms (%zu pieces)\n", zooms[z],
                   moving ? "moving" : "still ", t[N / 2], shape->n_pieces);
        }
    sw__curves_shape_free(shape);
}

/* ---- the run ----------------------------------------------------------------------------------
 */

static int run_zoom(sw__curves_renderer *r, sw__curves_shape *shape, const tshape *ts, double zoom,
                    GLuint fbo, int print_only_fail, double *worst_mean, double *worst_max)
{
    (void)print_only_fail;
    double centre[2];
    if (zoom <= 1.0) {
        centre[0] = 0.5 * (shape->box[0] + shape->box[2]);
        centre[1] = 0.5 * (shape->box[1] + shape->box[3]);
    } else {
        memcpy(centre, ts->focus, sizeof centre);
    }
    double s = S0 * zoom, c = cos(ROT), sn = sin(ROT);
    double v[6] = {s * c, -s * sn, 0, s * sn, s * c, 0};
    v[2] = W / 2 + 0.37 - (v[0] * centre[0] + v[1] * centre[1]);
    v[5] = H / 2 + 0.21 - (v[3] * centre[0] + v[4] * centre[1]);

    /* background: an opaque green rectangle on the left half, dark blue elsewhere */
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, W, H);
    glDisable(GL_SCISSOR_TEST);
    glClearColor(0, 0, 0.25f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, W / 2, H);
    glClearColor(0, 1, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);

    sw__curves_view view = {{v[0], v[1], v[2], v[3], v[4], v[5]}, W, H};
    const float red[4] = {1, 0, 0, 1};
    sw_status st = {0};
    if (sw__curves_draw(r, shape, &view, red, fbo, &st) != SW_OK) {
        fprintf(stderr, "FAIL: draw: %s\n", st.message);
        return 0;
    }
    static unsigned char px[W * H * 4];
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);

    static double ref[W * H];
    memset(ref, 0, sizeof ref);
    for (int L = 0; L < ts->n_loops; ++L) {
        ref_poly pl = {0};
        for (int k = 0; k < ts->n_curves; ++k)
            if (ts->loop_of[k] == L)
                flatten_curve(&ts->c[k], v, &pl);
        ref_area_accumulate(&pl, ts->sign[L], W, H, ref);
        free(pl.p);
    }
    /* corners: the shape's own list (cusps, crossings, joins) and the test's */
    double(*cn)[2] = malloc(sizeof *cn * (shape->n_corners + ts->n_corners + 1));
    size_t ncn = 0;
    for (size_t k = 0; k < shape->n_corners; ++k)
        to_px(v, shape->corners[k], cn[ncn++]);
    for (int k = 0; k < ts->n_corners; ++k)
        to_px(v, ts->corners[k], cn[ncn++]);

    double sum = 0, mx = 0, csum = 0, cmx = 0;
    size_t n_edge = 0, n_corner = 0, bad_comp = 0;
    int mxi = 0, mxj = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const unsigned char *q = px + 4 * (j * W + i);
            double got = q[0] / 255.0, want = fabs(ref[j * W + i]);
            want = want > 1 ? 1 : want;
            double err = fabs(got - want);
            /* the composite: the background shows through in proportion */
            double bg = i < W / 2 ? q[1] / 255.0 : q[2] / (0.25 * 255.0);
            if (fabs(bg - (1 - got)) > (i < W / 2 ? 1.5 / 255 : 6.0 / 255) ||
                (i < W / 2 ? q[2] : q[1]) != 0)
                bad_comp++;
            int near = 0;
            for (size_t k = 0; k < ncn && !near; ++k)
                near = hypot(i + 0.5 - cn[k][0], j + 0.5 - cn[k][1]) <= 1.0;
            int edge = (want > 1e-9 && want < 1 - 1e-9) || (q[0] > 0 && q[0] < 255);
            if (near) {
                n_corner++;
                csum += err;
                cmx = fmax(cmx, err);
                continue;
            }
            if (edge) {
                n_edge++;
                sum += err;
            }
            if (err > mx) {
                mx = err;
                mxi = i;
                mxj = j;
            }
        }
    free(cn);
    if (getenv("SW_CURVES_PROBE") && zoom == atof(getenv("SW_CURVES_PROBE"))) {
        double det = v[0] * v[4] - v[1] * v[3], X = mxi + 0.5 - v[2], Y = mxj + 0.5 - v[5];
        double mx_ = (v[4] * X - v[1] * Y) / det, my_ = (-v[3] * X + v[0] * Y) / det;
        for (size_t k = 0; k < shape->n_pieces; ++k) {
            const sw__curves_piece *p = &shape->pieces[k];
            double lo0 = 1e9, lo1 = 1e9, hi0 = -1e9, hi1 = -1e9;
            for (int q = 0; q < p->n_cp; ++q) {
                lo0 = fmin(lo0, p->cp[q][0]);
                hi0 = fmax(hi0, p->cp[q][0]);
                lo1 = fmin(lo1, p->cp[q][1]);
                hi1 = fmax(hi1, p->cp[q][1]);
            }
            double m = (getenv("SW_CURVES_PROBE_ALL") ? 1e9 : 3) / s;
            if (mx_ > lo0 - m && mx_ < hi0 + m && my_ > lo1 - m && my_ < hi1 + m) {
                printf("piece %zu kind %d s_chord %g s_in %g F %g:", k, p->kind, p->s_chord,
                       p->s_in, sw__curves_piece_eval(p, mx_, my_));
                for (int q = 0; q < p->n_cp; ++q)
                    printf(" (%.6f,%.6f)", p->cp[q][0], p->cp[q][1]);
                double ce[2], sz, cf[10];
                sw__curves_piece_local_form(p, ce, &sz, cf);
                float u = (float)((mx_ - ce[0]) / sz), vv = (float)((my_ - ce[1]) / sz);
                float uu[10] = {1,       u,         vv,         u * u,       u * vv,
                                vv * vv, u * u * u, u * u * vv, u * vv * vv, vv * vv * vv};
                float Ff = 0;
                for (int q = 0; q < 10; ++q)
                    Ff += (float)cf[q] * uu[q];
                double U = (mx_ - ce[0]) / sz, V = (my_ - ce[1]) / sz;
                double Fd = cf[0] + cf[1] * U + cf[2] * V + cf[3] * U * U + cf[4] * U * V +
                            cf[5] * V * V + cf[6] * U * U * U + cf[7] * U * U * V +
                            cf[8] * U * V * V + cf[9] * V * V * V;
                double Fu = cf[1] + 2 * cf[3] * U + cf[4] * V + 3 * cf[6] * U * U +
                            2 * cf[7] * U * V + cf[8] * V * V;
                double Fv = cf[2] + cf[4] * U + 2 * cf[5] * V + cf[7] * U * U + 2 * cf[8] * U * V +
                            3 * cf[9] * V * V;
                double cut0 = (mx_ - p->cp[0][0]) * p->tan0[0] + (my_ - p->cp[0][1]) * p->tan0[1];
                double cut1 = (p->cp[p->n_cp - 1][0] - mx_) * p->tan1[0] +
                              (p->cp[p->n_cp - 1][1] - my_) * p->tan1[1];
                {
                    double gx = Fu / sz, gy = Fv / sz; /* model gradient */
                    /* pixel gradient: grad_px = M^-T grad_model */
                    double ipx = (v[4] * gx - v[3] * gy) / det,
                           ipy = (-v[1] * gx + v[0] * gy) / det;
                    double dd = p->s_in * Fd / hypot(ipx, ipy);
                    double nx = p->s_in * ipx / hypot(ipx, ipy),
                           ny = p->s_in * ipy / hypot(ipx, ipy);
                    double a = fmax(fabs(nx), fabs(ny)), bq = fmin(fabs(nx), fabs(ny));
                    double lo = 0.5 * (a - bq), hi = 0.5 * (a + bq), t = -dd, at = fabs(t), cv;
                    if (at >= hi)
                        cv = 1;
                    else if (at <= lo)
                        cv = 0.5 + at / a;
                    else
                        cv = 1 - (hi - at) * (hi - at) / (2 * a * bq);
                    if (t < 0)
                        cv = 1 - cv;
                    printf("\n   pixel d %g cov %g correction %g", dd, cv, cv - (dd < 0));
                    /* two Newton steps as the shader takes them, in model units */
                    double P[2] = {U, V}, gg[2];
                    for (int it = 0; it < 3; ++it) {
                        double F0 = probe_form(cf, P[0], P[1], gg),
                               g2 = gg[0] * gg[0] + gg[1] * gg[1];
                        printf("\n   newton %d: F %g at offset (%g, %g) px", it, F0,
                               (P[0] - U) * sz * s, (P[1] - V) * sz * s);
                        P[0] -= F0 / g2 * gg[0];
                        P[1] -= F0 / g2 * gg[1];
                    }
                    double cx_ = P[0] * sz + ce[0], cy_ = P[1] * sz + ce[1],
                           cd = hypot(cx_ - mx_, cy_ - my_) * s;
                    printf("\n   foot at %g px", cd);
                }
                printf("\n   d_px %g (s_in d %g) cut0 %g cut1 %g px", Fd / hypot(Fu, Fv) * sz * s,
                       p->s_in * Fd / hypot(Fu, Fv) * sz * s, cut0 * s, cut1 * s);
                printf("\n   local u %g v %g Ffloat %g coefs", u, vv, Ff);
                for (int q = 0; q < 10; ++q)
                    printf(" %.3g", cf[q]);
                printf("\n");
            }
        }
        for (int j = mxj + 3; j >= mxj - 3; --j) {
            for (int i = mxi - 4; i <= mxi + 4; ++i)
                if (i >= 0 && j >= 0 && i < W && j < H)
                    printf(" %3d/%5.1f", px[4 * (j * W + i)], 255 * fmin(fabs(ref[j * W + i]), 1));
            printf("\n");
        }
    }
    if (getenv("SW_CURVES_DUMP")) { /* error image: red = rendered too high, green = too low */
        char path[256];
        snprintf(path, sizeof path, "%s/curves_err_x%g.ppm", getenv("SW_CURVES_DUMP"), zoom);
        FILE *f = fopen(path, "wb");
        if (f) {
            fprintf(f, "P6 %d %d 255\n", W, H);
            for (int j = H - 1; j >= 0; --j)
                for (int i = 0; i < W; ++i) {
                    double e = px[4 * (j * W + i)] / 255.0 - fmin(fabs(ref[j * W + i]), 1.0);
                    unsigned char o[3] = {(unsigned char)fmin(255, fmax(0, e * 2550)),
                                          (unsigned char)fmin(255, fmax(0, -e * 2550)),
                                          (unsigned char)(px[4 * (j * W + i)] / 4)};
                    fwrite(o, 1, 3, f);
                }
            fclose(f);
        }
    }
    double mean = n_edge ? sum / n_edge : 0;
    printf("  zoom x%-6g pieces %4zu (approx %3u, bound %.4f px, rebuilds %u)  edge px %5zu  "
           "mean %5.2f/255  max %5.2f/255 at (%d,%d)  | near corners: %3zu px, mean %6.2f/255, "
           "max %6.2f/255  | composite mismatches %zu\n",
           zoom, shape->n_pieces, shape->n_approx, shape->approx_bound * s, shape->rebuilds, n_edge,
           mean * 255, mx * 255, mxi, mxj, n_corner, n_corner ? csum / n_corner * 255 : 0.0,
           cmx * 255, bad_comp);
    *worst_mean = fmax(*worst_mean, mean);
    *worst_max = fmax(*worst_max, mx);
    int ok = mean <= 2.0 / 255 && mx <= 12.0 / 255 && bad_comp == 0 && n_edge > 0 &&
             shape->approx_bound * s <= SW__CURVES_REFIT_PX;
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DIR quadratic|conic|loop|cusp|nurbs7 [plant|time]\n", argv[0]);
        return 2;
    }
    tshape ts;
    if (!make_shape(argv[2], &ts)) {
        fprintf(stderr, "unknown class %s\n", argv[2]);
        return 2;
    }
    int plant = argc > 3 && !strcmp(argv[3], "plant");
    int timing = argc > 3 && !strcmp(argv[3], "time");
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    sw__curves_renderer *r = NULL;
    if (sw__curves_renderer_create(&r, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    if (plant)
        sw__curves_renderer_set_fault(r, 1);
    GLuint fbo, rb;
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);

    sw_sg_curve curves[4];
    for (int k = 0; k < ts.n_curves; ++k)
        curves[k] = (sw_sg_curve){ts.c[k].deg, ts.c[k].n, 3, ts.c[k].knots, ts.c[k].cpw};
    sw__curves_loop loops[4];
    for (int L = 0; L < ts.n_loops; ++L) {
        loops[L].curves = NULL;
        loops[L].n_curves = 0;
        for (int k = 0; k < ts.n_curves; ++k)
            if (ts.loop_of[k] == L) {
                if (!loops[L].curves)
                    loops[L].curves = &curves[k];
                loops[L].n_curves++;
            }
    }
    sw__curves_shape *shape = NULL;
    if (sw__curves_shape_create(loops, (uint32_t)ts.n_loops, S0, &shape, &st) != SW_OK) {
        fprintf(stderr, "FAIL: shape: %s\n", st.message);
        return 1;
    }
    printf("%s%s: %zu pieces, %zu corners\n", argv[2], plant ? " (planted sign error)" : "",
           shape->n_pieces, shape->n_corners);
    if (timing) {
        time_draws(r, loops, (uint32_t)ts.n_loops, &ts, fbo);
        sw__curves_shape_free(shape);
        sw__curves_renderer_free(r);
        sw_gpu_context_free(ctx);
        return 0;
    }
    static const double zooms[5] = {1, 10, 100, 1000, 0.08};
    int ok = 1;
    double wm = 0, wx = 0;
    for (int z = 0; z < 5; ++z)
        if (!run_zoom(r, shape, &ts, zooms[z], fbo, 0, &wm, &wx))
            ok = 0;
    printf("%s: worst mean %.2f/255, worst max %.2f/255: %s\n", argv[2], wm * 255, wx * 255,
           ok ? "ok" : "FAIL");
    sw__curves_shape_free(shape);
    sw__curves_renderer_free(r);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    sw_gpu_context_free(ctx);
    return ok ? 0 : 1;
}

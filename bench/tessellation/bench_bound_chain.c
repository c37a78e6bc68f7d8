/* SPDX-License-Identifier: MIT */
/* bench/tessellation: where splinewalk's grid densities lose against the screen-space error they
 * promise (Guthe et al. 2005 §5.2, §7). For every patch piece a frame draws (the frame's debug
 * hook), each link of the chain ε_img -> object tolerance -> Filip bound -> segments -> grid class
 * is measured against dense evaluation:
 *   (a) derivative bounds (lod/bezier/sampling.c) vs the sampled sup of |S_ss|, |S_st|, |S_tt| over
 * the drawn part of the patch; (b) Filip's bound at the drawn grid vs the largest object-space
 * deviation of its triangles; (c) the object tolerance vs the screen error it turns into (px per
 * object unit); (d) Filip's segments (unrounded) vs the drawn grid (class rounding, row / column
 * unification); and the drawn error in pixels. Triangle totals: drawn; the §5.2 formula
 * (whole-patch bounds, ε/2 per direction, at the frame's isotropic object tolerance) before
 * rounding; the same with the sampled M; the smallest uniform grid of the drawn grid's aspect that
 * meets ε_img when measured.
 *
 * Usage: bench_bound_chain [--error PX] [FILE...]   (no FILE: the benchmark's wavy patch at 32,
 * 256 and 1024 px in 1280 x 1024; FILEs: iso view fitted to the box, 1280 x 720). A benchmark,
 * not a test.
 */
#include "cli_numbers.h"
#include "sw_gpu_internal.h"
#include "sw_lod_sampling.h"
#include "wavy_patch.h"
#ifdef BT_WITH_IMPORT
#include "sw_sg_import.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_PIECES = 1 << 16, SUP_SAMPLES = 48 };

typedef struct piece {
    sw__gpu_drawn_patch d;
    double *cpw; /* owned copy */
    double knots_u[2 * (SW_SG_MAX_DEGREE + 1)], knots_v[2 * (SW_SG_MAX_DEGREE + 1)];
} piece;

typedef struct collector {
    piece *p;
    size_t n;
    sw__gpu_view view;
} collector;

static void hook(void *user, const sw__gpu_drawn_patch *d)
{
    collector *c = user;
    if (c->n >= MAX_PIECES)
        return;
    size_t n = (size_t)(d->deg_u + 1) * (size_t)(d->deg_v + 1) * 4;
    double *cpw = malloc(n * sizeof *cpw);
    if (!cpw)
        return;
    piece *p = &c->p[c->n++];
    p->d = *d;
    p->cpw = cpw;
    memcpy(p->cpw, d->cpw, n * sizeof *p->cpw);
    p->d.cpw = p->cpw;
    c->view = *d->view;
    for (int k = 0; k <= d->deg_u; ++k) {
        p->knots_u[k] = 0.0;
        p->knots_u[d->deg_u + 1 + k] = 1.0;
    }
    for (int k = 0; k <= d->deg_v; ++k) {
        p->knots_v[k] = 0.0;
        p->knots_v[d->deg_v + 1 + k] = 1.0;
    }
}

static sw_sg_surface piece_surface(const piece *p)
{
    return (sw_sg_surface){p->d.deg_u, p->d.deg_v, p->d.deg_u + 1, p->d.deg_v + 1,
                           p->knots_u, p->knots_v, p->cpw};
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* Pixel position of an eye-relative point. */
static void project(const sw__gpu_view *v, const double p[3], double px[2])
{
    double x = 0.0, y = 0.0, w = 0.0;
    for (int k = 0; k < 3; ++k) {
        x += v->right[k] * p[k];
        y += v->up[k] * p[k];
        w += v->fwd[k] * p[k];
    }
    px[0] = v->focal_px * x / w;
    px[1] = v->focal_px * y / w;
}

/* Sampled sup of |S_ss|, |S_st|, |S_tt| over [s0,s1] x [t0,t1]. */
static void sampled_sup(const piece *p, double m[3])
{
    sw_sg_surface s = piece_surface(p);
    m[0] = m[1] = m[2] = 0.0;
    for (int j = 0; j <= SUP_SAMPLES; ++j)
        for (int i = 0; i <= SUP_SAMPLES; ++i) {
            double u = p->d.s0 + (p->d.s1 - p->d.s0) * i / SUP_SAMPLES;
            double v = p->d.t0 + (p->d.t1 - p->d.t0) * j / SUP_SAMPLES;
            sw_sg_surface_d2 d;
            sw_sg_surface_eval_d2(&s, u, v, &d);
            m[0] = fmax(m[0], norm3(d.duu));
            m[1] = fmax(m[1], norm3(d.duv));
            m[2] = fmax(m[2], norm3(d.dvv));
        }
}

/* Grid parameter k of n over [a, b], as the drawing path computes it. */
static double grid_param(const piece *p, double a, double b, int32_t k, int32_t n)
{
    if (k == n)
        return b;
    if (p->d.gpu) {
        float fa = (float)a, fb = (float)b;
        return (double)(fa + (fb - fa) * (float)k / (float)n);
    }
    return a + (b - a) * (double)k / (double)n;
}

typedef struct grid_err {
    double obj, px; /* largest deviation of the triangles from the surface at the same (s, t) */
} grid_err;

/* Deviation of the nu x nv grid's triangles (split like gpu/grid_set.c) at edge midpoints,
 * centroids and three interior points per triangle. */
static grid_err measure_grid(const piece *p, const sw__gpu_view *v, int32_t nu, int32_t nv)
{
    static const double bc[7][3] = {{.5, .5, 0},
                                    {0, .5, .5},
                                    {.5, 0, .5},
                                    {1. / 3, 1. / 3, 1. / 3},
                                    {2. / 3, 1. / 6, 1. / 6},
                                    {1. / 6, 2. / 3, 1. / 6},
                                    {1. / 6, 1. / 6, 2. / 3}};
    sw_sg_surface s = piece_surface(p);
    grid_err e = {0.0, 0.0};
    double *row0 = malloc((size_t)(nu + 1) * 5 * sizeof *row0);
    double *row1 = malloc((size_t)(nu + 1) * 5 * sizeof *row1);
    if (!row0 || !row1) {
        free(row0);
        free(row1);
        return (grid_err){INFINITY, INFINITY};
    }
    for (int32_t l = 0; l <= nv; ++l) {
        double t = grid_param(p, p->d.t0, p->d.t1, l, nv);
        for (int32_t k = 0; k <= nu; ++k) {
            double *q = row1 + 5 * k;
            q[0] = grid_param(p, p->d.s0, p->d.s1, k, nu);
            q[1] = t;
            sw_sg_surface_eval(&s, q[0], q[1], q + 2);
        }
        if (l > 0) {
            for (int32_t k = 0; k < nu; ++k) {
                const double *a = row0 + 5 * k, *b = row0 + 5 * (k + 1), *dd = row1 + 5 * k,
                             *ee = row1 + 5 * (k + 1);
                const double *tri[2][3] = {{a, b, ee}, {a, ee, dd}};
                for (int h = 0; h < 2; ++h)
                    for (int c = 0; c < 7; ++c) {
                        double st[2] = {0, 0}, x[3] = {0, 0, 0}, y[3], px[2], py[2], d[3];
                        for (int r = 0; r < 3; ++r) {
                            for (int q = 0; q < 2; ++q)
                                st[q] += bc[c][r] * tri[h][r][q];
                            for (int q = 0; q < 3; ++q)
                                x[q] += bc[c][r] * tri[h][r][2 + q];
                        }
                        sw_sg_surface_eval(&s, st[0], st[1], y);
                        for (int q = 0; q < 3; ++q)
                            d[q] = x[q] - y[q];
                        e.obj = fmax(e.obj, norm3(d));
                        project(v, x, px);
                        project(v, y, py);
                        e.px = fmax(e.px, hypot(px[0] - py[0], px[1] - py[1]));
                    }
            }
        }
        double *tmp = row0;
        row0 = row1;
        row1 = tmp;
    }
    free(row0);
    free(row1);
    return e;
}

static double filip_n(double m_dir, double m_mixed, double len, double eps)
{
    double n = ceil(len * sqrt((m_dir + m_mixed) / (4.0 * eps)));
    return n < 1.0 ? 1.0 : n;
}

typedef struct totals {
    double drawn, filip, filip_true_m, ideal;
    double bound_ratio[3], worst_px, ideal_cost_px;
    double filip_over_dev, px_per_obj_ratio, n_pieces;
    double min_ratio[3];
} totals;

/* Smallest scale lambda (to 1 %) such that the grid (ceil(lambda nu), ceil(lambda nv)) meets
 * eps_px when measured; returns its triangles. */
static double ideal_triangles(const piece *p, const sw__gpu_view *v, double eps_px)
{
    double lo = 0.0, hi = 1.0;
    int32_t nu = p->d.nu, nv = p->d.nv;
    if (measure_grid(p, v, nu, nv).px > eps_px)
        return 2.0 * nu * nv;
    for (int it = 0; it < 12; ++it) {
        double mid = 0.5 * (lo + hi);
        int32_t a = (int32_t)ceil(mid * nu), b = (int32_t)ceil(mid * nv);
        if (measure_grid(p, v, a < 1 ? 1 : a, b < 1 ? 1 : b).px <= eps_px)
            hi = mid;
        else
            lo = mid;
    }
    double a = fmax(1.0, ceil(hi * nu)), b = fmax(1.0, ceil(hi * nv));
    return 2.0 * a * b;
}

static void analyse(const collector *c, double eps_px, int verbose, totals *t)
{
    memset(t, 0, sizeof *t);
    for (int k = 0; k < 3; ++k)
        t->min_ratio[k] = INFINITY;
    for (size_t i = 0; i < c->n; ++i) {
        const piece *p = &c->p[i];
        sw_lod_patch_bounds b;
        sw_lod_rational_bezier_bounds(p->d.deg_u, p->d.deg_v, p->cpw, &b);
        double m[3];
        sampled_sup(p, m);
        double ls = p->d.s1 - p->d.s0, lt = p->d.t1 - p->d.t0, eps = p->d.eps_obj;
        double fu = filip_n(b.d2[0], b.d2[1], ls, eps), fv = filip_n(b.d2[2], b.d2[1], lt, eps);
        double tu = filip_n(m[0], m[1], ls, eps), tv = filip_n(m[2], m[1], lt, eps);
        grid_err g = measure_grid(p, &c->view, p->d.nu, p->d.nv);
        double fb = sw_lod_filip_error(&b, ls / p->d.nu, lt / p->d.nv);
        double ideal = ideal_triangles(p, &c->view, eps_px);
        t->drawn += 2.0 * p->d.nu * p->d.nv;
        t->filip += 2.0 * fu * fv;
        t->filip_true_m += 2.0 * tu * tv;
        t->ideal += ideal;
        t->worst_px = fmax(t->worst_px, g.px);
        double mscale = fmax(fmax(m[0], m[1]), fmax(m[2], 1e-300));
        for (int k = 0; k < 3; ++k)
            if (m[k] > 1e-9 * mscale) {
                t->bound_ratio[k] = fmax(t->bound_ratio[k], b.d2[k] / m[k]);
                t->min_ratio[k] = fmin(t->min_ratio[k], b.d2[k] / m[k]);
            }
        t->n_pieces += 1.0;
        if (verbose)
            printf("  piece %zu deg %dx%d %s: bounds Mss %.4g Mst %.4g Mtt %.4g | sampled %.4g "
                   "%.4g %.4g | eps_obj %.4g | Filip n %g x %g (true M %g x %g) drawn %d x %d | "
                   "Filip err bound %.4g, real %.4g obj (%.2f x) | real %.3f px, eps %.2f px "
                   "(px per eps: %.3f) | ideal %g triangles\n",
                   i, p->d.deg_u, p->d.deg_v, p->d.gpu ? "gpu" : "cpu", b.d2[0], b.d2[1], b.d2[2],
                   m[0], m[1], m[2], eps, fu, fv, tu, tv, p->d.nu, p->d.nv, fb, g.obj,
                   fb / fmax(g.obj, 1e-300), g.px, eps_px, g.px / eps_px, ideal);
    }
}

static void print_totals(const char *what, const totals *t)
{
    printf("%s: %g pieces | triangles drawn %g, Filip before rounding %g, Filip with sampled M "
           "%g, smallest uniform grid meeting eps %g | drawn / ideal %.2f | bound / sampled sup: "
           "ss %.2f..%.2f st %.2f..%.2f tt %.2f..%.2f | worst drawn error %.3f px\n",
           what, t->n_pieces, t->drawn, t->filip, t->filip_true_m, t->ideal,
           t->drawn / fmax(t->ideal, 1.0), t->min_ratio[0], t->bound_ratio[0], t->min_ratio[1],
           t->bound_ratio[1], t->min_ratio[2], t->bound_ratio[2], t->worst_px);
}

static void collector_clear(collector *c)
{
    for (size_t i = 0; i < c->n; ++i)
        free(c->p[i].cpw);
    c->n = 0;
}

static int run_frame(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_gpu_frame_desc *desc,
                     collector *c, const char *what, int verbose)
{
    collector_clear(c);
    sw__gpu_set_patch_hook(ctx, hook, c);
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    sw_status st = {0};
    sw_result r = sw_gpu_render_scene(ctx, scene, desc, &img, &fs, &st);
    sw__gpu_set_patch_hook(ctx, NULL, NULL);
    if (r != SW_OK) {
        fprintf(stderr, "render: %s\n", st.message);
        return 0;
    }
    sw_gpu_image_free(&img);
    totals t;
    analyse(c, desc->error_px, verbose, &t);
    print_totals(what, &t);
    printf("  frame: %llu triangles, draw %.2f ms\n", (unsigned long long)fs.triangles, fs.ms_draw);
    return 1;
}

static sw_gpu_camera iso_camera(const double b[6])
{
    static const double from[3] = {1, 1, 1}, up[3] = {0, 0, 1};
    sw_gpu_camera c;
    sw_gpu_camera_fit_box(b, from, up, &c);
    return c;
}

int main(int argc, char **argv)
{
    double eps_px = 0.5;
    int first_file = 1;
    if (argc > 2 && strcmp(argv[1], "--error") == 0) {
        if (sw_cli_parse_error_px(argv[2], &eps_px))
            return sw_cli_bad_value("bench_bound_chain", argv[1], argv[2], NULL);
        first_file = 3;
    }
    if (!getenv("LP_NUM_THREADS"))
        setenv("LP_NUM_THREADS", "2", 0);
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    collector c;
    memset(&c, 0, sizeof c);
    c.p = calloc(MAX_PIECES, sizeof(piece));
    if (!c.p || sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "context: %s\n", st.message);
        free(c.p);
        return 1;
    }
    int ok = 1;
    if (first_file >= argc) {
        double cpw[64];
        bt_wavy_cpw(cpw);
        sw_sg_scene *scene = NULL;
        ok = bt_wavy_scene(cpw, &scene, &st) == SW_OK;
        static const int sizes[3] = {32, 256, 1024};
        for (int k = 0; k < 3 && ok; ++k) {
            double got, dist = bt_wavy_fit_distance(cpw, sizes[k], 1280, 1024, &got);
            sw_gpu_frame_desc desc;
            memset(&desc, 0, sizeof desc);
            desc.width = 1280;
            desc.height = 1024;
            desc.error_px = eps_px;
            desc.camera = bt_wavy_camera_at(dist);
            char what[64];
            snprintf(what, sizeof what, "wavy patch %d px", sizes[k]);
            ok = run_frame(ctx, scene, &desc, &c, what, 1);
        }
        sw_sg_scene_free(scene);
    }
#ifdef BT_WITH_IMPORT
    for (int a = first_file; a < argc && ok; ++a) {
        sw_sg_import_desc id = {argv[a], NULL, NULL, NULL, NULL, 0};
        sw_sg_scene *scene = NULL;
        if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
            fprintf(stderr, "import %s: %s\n", argv[a], st.message);
            ok = 0;
            break;
        }
        sw_sg_scene_stats ss;
        sw_sg_scene_compute_stats(scene, &ss);
        sw_gpu_frame_desc desc;
        memset(&desc, 0, sizeof desc);
        desc.width = 1280;
        desc.height = 720;
        desc.error_px = eps_px;
        desc.camera = iso_camera(ss.bbox);
        ok = run_frame(ctx, scene, &desc, &c, argv[a], 0);
        sw_sg_scene_free(scene);
    }
#else
    (void)iso_camera;
#endif
    sw_gpu_context_free(ctx);
    collector_clear(&c);
    free(c.p);
    return ok ? 0 : 1;
}

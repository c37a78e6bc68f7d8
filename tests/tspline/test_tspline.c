/* SPDX-License-Identifier: MIT */
/* tests/tspline: T-splines (scenegraph/sw_sg_tspline.h) against independent references.
 *  - local_refinement.tsm equals its source NURBS (sw_sg_surface_eval, the NURBS kernel) to 1e-9
 *    relative at 20,000 random points, through all three evaluators;
 *  - t_junctions.tsm: Bézier extraction, direct blending-function evaluation and region
 *    evaluation agree to 1e-9 (also with random weights), the blending functions sum to one
 *    within 1e-12, the region point lists equal the brute-force supports, and the sample really
 *    needs more points as a NURBS (third-derivative jumps along its knot lines);
 *  - the scene builder hand-over: faces evaluate like the T-spline;
 *  - the parser's errors on bad input: result id and "file:line" in the message.
 */
#include "sw_sg_tspline.h"
#include "tspline_samples.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#ifndef SW_TSPLINE_SAMPLES_DIR
#error "SW_TSPLINE_SAMPLES_DIR must point at samples/tsplines"
#endif

enum { N_RANDOM = 20000 };

static uint64_t g_rng = 0x9e3779b97f4a7c15ull;
static double rnd(void)
{
    g_rng ^= g_rng << 13, g_rng ^= g_rng >> 7, g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

static sw_sg_tspline *load_sample(const char *file)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", SW_TSPLINE_SAMPLES_DIR, file);
    sw_sg_tspline *ts = NULL;
    sw_status st = {0};
    sw_result r = sw_sg_tspline_load(path, &ts, &st);
    if (r != SW_OK)
        fail_msg("%s: %s", sw_result_id_str(r), st.message);
    return ts;
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Diagonal of the control points' box: the scale of "relative". */
static double scale_of(const sw_sg_tspline *ts)
{
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < v->n_points; i++)
        for (int c = 0; c < 3; c++) {
            const double x = v->cpw[i * 4 + c] / v->cpw[i * 4 + 3];
            lo[c] = fmin(lo[c], x), hi[c] = fmax(hi[c], x);
        }
    return dist3(lo, hi);
}

/* Evaluates through the Bézier patches, found by a linear scan (independent of the regions). */
static void eval_bezier(const sw_sg_tspline_bezier *bz, const sw_sg_tspline_view *v, double u,
                        double w, double p[3])
{
    for (uint32_t k = 0; k < bz->n_patches; k++) {
        const sw_sg_bezier_patch *q = &bz->patches[k];
        const int in_u = u >= q->u0 && (u < q->u1 || (u == q->u1 && u == v->domain[1]));
        const int in_v = w >= q->v0 && (w < q->v1 || (w == q->v1 && w == v->domain[3]));
        if (in_u && in_v) {
            sw_sg_bezier_patch_eval(q, (u - q->u0) / (q->u1 - q->u0), (w - q->v0) / (q->v1 - q->v0),
                                    p);
            return;
        }
    }
    fail_msg("no Bézier patch holds (%g, %g)", u, w);
}

/* Random parameter in the domain; one in 16 on a domain edge or a region boundary. */
static void random_uv(const sw_sg_tspline_view *v, double *u, double *w)
{
    *u = v->domain[0] + rnd() * (v->domain[1] - v->domain[0]);
    *w = v->domain[2] + rnd() * (v->domain[3] - v->domain[2]);
    const double pick = rnd();
    if (pick < 1.0 / 32)
        *u = v->bu[(uint32_t)(rnd() * v->n_bu) % v->n_bu];
    else if (pick < 2.0 / 32)
        *w = v->bv[(uint32_t)(rnd() * v->n_bv) % v->n_bv];
}

typedef struct max_err {
    double direct, region, bezier;
} max_err;

/* Max distances of the three evaluators from `ref` (NULL: from the direct evaluation). */
static max_err compare_evaluators(const sw_sg_tspline *ts, const sw_sg_surface *ref, int n)
{
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    sw_sg_tspline_bezier bz;
    sw_status st = {0};
    assert_int_equal(sw_sg_tspline_extract_bezier(ts, &bz, &st), SW_OK);
    max_err e = {0, 0, 0};
    for (int k = 0; k < n; k++) {
        double u, w, pd[3], pr[3], pb[3], pref[3];
        random_uv(v, &u, &w);
        sw_sg_tspline_eval_direct(ts, u, w, pd);
        sw_sg_tspline_eval(ts, u, w, pr);
        eval_bezier(&bz, v, u, w, pb);
        if (ref)
            sw_sg_surface_eval(ref, u, w, pref);
        else
            memcpy(pref, pd, sizeof pref);
        e.direct = fmax(e.direct, dist3(pd, pref));
        e.region = fmax(e.region, dist3(pr, pref));
        e.bezier = fmax(e.bezier, dist3(pb, pref));
    }
    sw_sg_tspline_bezier_free(&bz);
    return e;
}

static void test_local_refinement_equals_nurbs(void **state)
{
    (void)state;
    sw_sg_tspline *ts = load_sample("local_refinement.tsm");
    double cpw[LR_NU * LR_NV * 4];
    lr_source_cpw(cpw);
    const sw_sg_surface src = lr_source_surface(cpw);
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    assert_int_equal(v->n_points, LR_NU * LR_NV + 1);
    assert_true(v->domain[0] == 0 && v->domain[1] == 2 && v->domain[2] == 0 && v->domain[3] == 1.5);
    const double scale = scale_of(ts);
    const max_err e = compare_evaluators(ts, &src, N_RANDOM);
    print_message("local refinement vs NURBS, %d points, %u regions: direct %.3g, region %.3g, "
                  "Bézier %.3g (relative to %.3g)\n",
                  N_RANDOM, v->n_regions, e.direct / scale, e.region / scale, e.bezier / scale,
                  scale);
    assert_true(e.direct <= 1e-9 * scale);
    assert_true(e.region <= 1e-9 * scale);
    assert_true(e.bezier <= 1e-9 * scale);

    /* The refinement is local: the new knot appears in the first row's knot vectors only. */
    int with_new = 0;
    for (uint32_t i = 0; i < v->n_points; i++)
        for (int k = 0; k < 5; k++)
            if (v->knots_u[i * 5 + k] == LR_NEW_KNOT) {
                with_new++;
                assert_true(v->knots_v[i * 5 + 0] == 0 && v->knots_v[i * 5 + 4] == 0.6);
                break;
            }
    assert_int_equal(with_new, 5);
    sw_sg_tspline_free(ts);
}

static void test_t_junctions_evaluators_agree(void **state)
{
    (void)state;
    sw_sg_tspline *ts = load_sample("t_junctions.tsm");
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    const double scale = scale_of(ts);
    max_err e = compare_evaluators(ts, NULL, N_RANDOM);
    print_message(
        "T-junctions, %u points, %u regions on a %u x %u grid: region %.3g, Bézier %.3g\n",
        v->n_points, v->n_regions, v->n_bu - 1, v->n_bv - 1, e.region / scale, e.bezier / scale);
    assert_true(e.region <= 1e-9 * scale && e.bezier <= 1e-9 * scale);
    /* Fewer regions than grid cells: regions are merged where no knot line runs. */
    assert_true(v->n_regions < (v->n_bu - 1) * (v->n_bv - 1));

    /* The same mesh with random weights in [0.3, 3]: a rational T-spline. */
    double *cpw = malloc(sizeof(double) * 4 * v->n_points);
    assert_non_null(cpw);
    for (uint32_t i = 0; i < v->n_points; i++) {
        const double w = 0.3 + 2.7 * rnd();
        for (int c = 0; c < 3; c++)
            cpw[i * 4 + c] = v->cpw[i * 4 + c] / v->cpw[i * 4 + 3] * w;
        cpw[i * 4 + 3] = w;
    }
    sw_sg_tspline_desc d = {v->n_points, cpw, v->knots_u, v->knots_v, {0, 0, 0, 0}};
    memcpy(d.domain, v->domain, sizeof d.domain);
    sw_sg_tspline *rt = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_tspline_create(&d, "rational", &rt, &st), SW_OK);
    e = compare_evaluators(rt, NULL, N_RANDOM);
    print_message("T-junctions, random weights: region %.3g, Bézier %.3g\n", e.region / scale,
                  e.bezier / scale);
    assert_true(e.region <= 1e-9 * scale && e.bezier <= 1e-9 * scale);
    sw_sg_tspline_free(rt);
    free(cpw);
    sw_sg_tspline_free(ts);
}

static void check_partition_of_unity(const char *file)
{
    sw_sg_tspline *ts = load_sample(file);
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    double worst = 0;
    for (int k = 0; k < N_RANDOM + 41 * 41; k++) {
        double u, w;
        if (k < 41 * 41) { /* a grid that includes the domain's edges and corners */
            u = v->domain[0] + (v->domain[1] - v->domain[0]) * (k % 41) / 40.0;
            w = v->domain[2] + (v->domain[3] - v->domain[2]) * (k / 41) / 40.0;
        } else {
            random_uv(v, &u, &w);
        }
        double sum = 0;
        for (uint32_t i = 0; i < v->n_points; i++)
            sum += sw_sg_tspline_blend(ts, i, u, w);
        worst = fmax(worst, fabs(sum - 1.0));
    }
    print_message("%s: partition of unity, max |sum B_i - 1| = %.3g\n", file, worst);
    assert_true(worst <= 1e-12);
    sw_sg_tspline_free(ts);
}

static void test_partition_of_unity(void **state)
{
    (void)state;
    check_partition_of_unity("t_junctions.tsm");
    check_partition_of_unity("local_refinement.tsm");
}

/* Each region's list equals the points whose blending function is non-zero at its centre. */
static void test_region_lists_brute_force(void **state)
{
    (void)state;
    sw_sg_tspline *ts = load_sample("t_junctions.tsm");
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    for (uint32_t r = 0; r < v->n_regions; r++) {
        const sw_sg_tspline_region *g = &v->regions[r];
        const double u = 0.5 * (g->u0 + g->u1), w = 0.5 * (g->v0 + g->v1);
        assert_int_equal(sw_sg_tspline_find_region(ts, u, w), r);
        uint32_t n = 0;
        for (uint32_t i = 0; i < v->n_points; i++) {
            if (sw_sg_tspline_blend(ts, i, u, w) == 0.0)
                continue;
            n++;
            int listed = 0;
            for (uint32_t k = 0; k < g->count; k++)
                listed |= v->region_points[g->first + k] == i;
            assert_true(listed);
        }
        assert_int_equal(n, g->count);
    }
    sw_sg_tspline_free(ts);
}

/* Third u-derivative of a non-rational bicubic patch at local t (constant along u). */
static double d3u_z(const sw_sg_bezier_patch *q, double t)
{
    const double b[4] = {(1 - t) * (1 - t) * (1 - t), 3 * t * (1 - t) * (1 - t),
                         3 * t * t * (1 - t), t * t * t};
    double d = 0;
    for (int l = 0; l < 4; l++) {
        const double *row = q->cpw + l * 16;
        d += b[l] * (row[12 + 2] - 3 * row[8 + 2] + 3 * row[4 + 2] - row[2]);
    }
    const double h = q->u1 - q->u0;
    return 6.0 * d / (h * h * h);
}

/* Distinct interior u-values where the third u-derivative jumps (a NURBS needs a knot there). */
static int jump_lines(const sw_sg_tspline *ts, const sw_sg_tspline_bezier *bz, double *lines)
{
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    int n = 0;
    for (uint32_t a = 1; a + 1 < v->n_bu; a++) {
        const double c = v->bu[a];
        for (int k = 0; k < 200; k++) {
            const double w = v->domain[2] + (k + 0.5) / 200.0 * (v->domain[3] - v->domain[2]);
            const sw_sg_bezier_patch *l = &bz->patches[sw_sg_tspline_find_region(ts, c - 1e-7, w)];
            const sw_sg_bezier_patch *r = &bz->patches[sw_sg_tspline_find_region(ts, c, w)];
            if (l == r)
                continue;
            if (fabs(d3u_z(l, (w - l->v0) / (l->v1 - l->v0)) -
                     d3u_z(r, (w - r->v0) / (r->v1 - r->v0))) > 1e-6) {
                lines[n++] = c;
                break;
            }
        }
    }
    return n;
}

static void test_t_junctions_need_more_as_nurbs(void **state)
{
    (void)state;
    sw_sg_tspline *ts = load_sample("t_junctions.tsm");
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    sw_sg_tspline_bezier bz;
    sw_status st = {0};
    assert_int_equal(sw_sg_tspline_extract_bezier(ts, &bz, &st), SW_OK);
    for (uint32_t i = 0; i < v->n_points; i++)
        assert_true(v->cpw[i * 4 + 3] == 1.0); /* polynomial: knot lines are derivative jumps */
    double lines[64];
    const int n_u = jump_lines(ts, &bz, lines);
    int has_partial = 0;
    for (int k = 0; k < n_u; k++)
        has_partial |= lines[k] == 2.3;
    assert_true(has_partial);
    /* The v direction by symmetry: swap the roles through a transposed copy. */
    sw_sg_tspline_desc d = {v->n_points,
                            v->cpw,
                            v->knots_v,
                            v->knots_u,
                            {v->domain[2], v->domain[3], v->domain[0], v->domain[1]}};
    double *cpw = malloc(sizeof(double) * 4 * v->n_points);
    assert_non_null(cpw);
    for (uint32_t i = 0; i < v->n_points; i++) { /* swap x and y so z stays the height */
        cpw[i * 4 + 0] = v->cpw[i * 4 + 1];
        cpw[i * 4 + 1] = v->cpw[i * 4 + 0];
        cpw[i * 4 + 2] = v->cpw[i * 4 + 2];
        cpw[i * 4 + 3] = v->cpw[i * 4 + 3];
    }
    d.cpw = cpw;
    sw_sg_tspline *tt = NULL;
    assert_int_equal(sw_sg_tspline_create(&d, "transposed", &tt, &st), SW_OK);
    sw_sg_tspline_bezier bt;
    assert_int_equal(sw_sg_tspline_extract_bezier(tt, &bt, &st), SW_OK);
    const int n_v = jump_lines(tt, &bt, lines);
    int has_partial_v = 0;
    for (int k = 0; k < n_v; k++)
        has_partial_v |= lines[k] == 1.8;
    assert_true(has_partial_v);
    /* Simple knots at every jump line, clamped ends: (lines + 4) points per direction. */
    const unsigned nurbs_points = (unsigned)(n_u + 4) * (unsigned)(n_v + 4);
    print_message("T-junctions: %u T-spline points; jump lines %d in u, %d in v: a NURBS needs "
                  ">= %u points\n",
                  v->n_points, n_u, n_v, nurbs_points);
    assert_true(nurbs_points > v->n_points);
    sw_sg_tspline_bezier_free(&bt);
    sw_sg_tspline_free(tt);
    free(cpw);
    sw_sg_tspline_bezier_free(&bz);
    sw_sg_tspline_free(ts);
}

static void test_scene_builder(void **state)
{
    (void)state;
    sw_sg_tspline *ts = load_sample("t_junctions.tsm");
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    sw_sg_builder *b = sw_sg_builder_create();
    assert_non_null(b);
    sw_status st = {0};
    uint32_t group = SW_SG_NONE;
    const float color[4] = {0.2f, 0.5f, 0.9f, 1.0f};
    assert_int_equal(sw_sg_tspline_add_to_builder(b, ts, 0, NULL, color, "tj", &group, &st), SW_OK);
    sw_sg_scene *scene = NULL;
    sw_result r = sw_sg_builder_finish(b, &scene, &st);
    if (r != SW_OK)
        fail_msg("%s", st.message);
    const sw_sg_scene_view *sv = sw_sg_scene_view_ptr(scene);
    assert_int_equal(sv->n_faces, v->n_regions);
    assert_true(sv->n_adjacency >= v->n_regions - 1);
    double worst = 0;
    for (uint32_t f = 0; f < sv->n_faces; f++) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(scene, f, &s);
        for (int k = 0; k < 20; k++) {
            const double *box = sv->faces[f].uv_box;
            const double u = box[0] + rnd() * (box[1] - box[0]);
            const double w = box[2] + rnd() * (box[3] - box[2]);
            double p[3], q[3];
            sw_sg_surface_eval(&s, u, w, p);
            sw_sg_tspline_eval_direct(ts, u, w, q);
            worst = fmax(worst, dist3(p, q));
        }
    }
    assert_true(worst <= 1e-9 * scale_of(ts));
    sw_sg_scene_free(scene);

    char path[1024];
    snprintf(path, sizeof path, "%s/%s", SW_TSPLINE_SAMPLES_DIR, "local_refinement.tsm");
    assert_int_equal(sw_sg_tspline_import_file(path, &scene, &st), SW_OK);
    assert_true(sw_sg_scene_view_ptr(scene)->n_faces > 0);
    sw_sg_scene_free(scene);
    assert_int_equal(sw_sg_tspline_import_file("/nonexistent/x.tsm", &scene, &st),
                     SW_ERR_NOT_FOUND);
    sw_sg_tspline_free(ts);
}

/* ---- bad input ------------------------------------------------------------------------------ */

/* A valid 4 x 4 bicubic Bézier patch as a T-mesh; line `bad` (1-based) replaced by `repl`
 * (NULL: dropped). Lines: 1 header, 2 sknots, 3 tknots, 4 edges, 5-20 edges, 21 points,
 * 22-37 points, 38 end. */
static size_t make_text(char *buf, size_t cap, int bad, const char *repl)
{
    char lines[40][128];
    int n = 0;
    snprintf(lines[n++], 128, "tsm 1");
    snprintf(lines[n++], 128, "sknots 8 0 0 0 0 1 1 1 1");
    snprintf(lines[n++], 128, "tknots 8 0 0 0 0 1 1 1 1");
    snprintf(lines[n++], 128, "edges 16");
    for (int k = 0; k < 8; k++)
        snprintf(lines[n++], 128, "h %d 0 7", k);
    for (int k = 0; k < 8; k++)
        snprintf(lines[n++], 128, "v %d 0 7", k);
    snprintf(lines[n++], 128, "points 16");
    for (int j = 2; j < 6; j++)
        for (int i = 2; i < 6; i++)
            snprintf(lines[n++], 128, "%d %d %d %d %g 1", i, j, i - 2, j - 2, 0.1 * i * j);
    snprintf(lines[n++], 128, "end");
    size_t len = 0;
    for (int k = 0; k < n; k++) {
        const char *s = k + 1 == bad ? repl : lines[k];
        if (s)
            len += (size_t)snprintf(buf + len, cap - len, "%s\n", s);
    }
    return len;
}

typedef struct bad_case {
    const char *what;
    int line;         /* line to replace (0: none) */
    const char *repl; /* replacement, NULL: drop the line */
    int cut_percent;  /* > 0: keep only this share of the text, minus one byte */
    sw_result expect;
    int at_line; /* line the message must name (0: any) */
} bad_case;

static void test_parser_bad_input(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        {"valid", 0, NULL, 0, SW_OK, 0},
        {"truncated mid-points", 0, NULL, 80, SW_ERR_TRUNCATED, 0},
        {"truncated before end", 38, NULL, 0, SW_ERR_TRUNCATED, 37},
        {"empty", 0, NULL, 1, SW_ERR_TRUNCATED, 0}, /* 1 % - 1 byte: a few bytes of "tsm" */
        {"NaN coordinate", 25, "5 2 3 0 nan 1", 0, SW_ERR_FORMAT, 25},
        {"infinite knot", 2, "sknots 8 0 0 0 0 1 inf 1 1", 0, SW_ERR_FORMAT, 2},
        {"negative weight", 30, "2 4 0 2 0.8 -1", 0, SW_ERR_INVALID_GEOMETRY, 30},
        {"zero weight", 22, "2 2 0 0 0 0", 0, SW_ERR_INVALID_GEOMETRY, 22},
        {"count too high", 21, "points 17", 0, SW_ERR_FORMAT, 38},
        {"count too low", 21, "points 15", 0, SW_ERR_FORMAT, 37},
        {"knot count wrong", 2, "sknots 9 0 0 0 0 1 1 1 1", 0, SW_ERR_FORMAT, 2},
        {"extra knot", 2, "sknots 8 0 0 0 0 1 1 1 1 1", 0, SW_ERR_FORMAT, 2},
        {"decreasing knots", 3, "tknots 8 0 0 0 0 1 0.5 1 1", 0, SW_ERR_INVALID_GEOMETRY, 3},
        {"garbage header", 1,
         "\x7f"
         "ELF\x01\x02",
         0, SW_ERR_FORMAT, 1},
        {"garbage record", 21, "pointz 16", 0, SW_ERR_FORMAT, 21},
        {"garbage field", 23, "3 2 1 0 0.6 1x", 0, SW_ERR_FORMAT, 23},
        {"huge count", 21, "points 4000000000", 0, SW_ERR_FORMAT, 21},
        {"huge knot count", 2, "sknots 99999999 0", 0, SW_ERR_FORMAT, 2},
        {"short point", 24, "4 2 2 0", 0, SW_ERR_FORMAT, 24},
        {"anchor off the grid", 22, "9 2 0 0 0 1", 0, SW_ERR_INVALID_GEOMETRY, 22},
        {"anchor in the frame", 22, "1 2 0 0 0 1", 0, SW_ERR_INVALID_GEOMETRY, 22},
        {"duplicate anchor", 23, "2 2 0 0 0 1", 0, SW_ERR_INVALID_GEOMETRY, 23},
        {"edge out of range", 5, "h 0 0 8", 0, SW_ERR_INVALID_GEOMETRY, 5},
        {"backwards edge", 6, "h 1 7 0", 0, SW_ERR_INVALID_GEOMETRY, 6},
        {"version 2", 1, "tsm 2", 0, SW_ERR_VERSION, 1},
        {"no end of text", 38, "end extra", 0, SW_ERR_FORMAT, 38},
    };
    static char buf[8192], name[64];
    sw_sg_tspline *none = NULL;
    sw_status est = {0};
    assert_int_equal(sw_sg_tspline_load_mem("", 0, "empty.tsm", &none, &est), SW_ERR_TRUNCATED);
    assert_null(none);
    assert_non_null(strstr(est.message, "empty.tsm:0:"));
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const bad_case *k = &cases[c];
        size_t len = make_text(buf, sizeof buf, k->line, k->repl);
        if (k->cut_percent)
            len = len * (size_t)k->cut_percent / 100 - 1;
        snprintf(name, sizeof name, "case%zu.tsm", c);
        sw_sg_tspline *ts = NULL;
        sw_status st = {0};
        const sw_result r = sw_sg_tspline_load_mem(buf, len, name, &ts, &st);
        print_message("%-22s -> %-24s %s\n", k->what, sw_result_id_str(r), st.message);
        assert_int_equal(r, k->expect);
        assert_true((ts != NULL) == (r == SW_OK));
        if (r != SW_OK) {
            char at[96];
            snprintf(at, sizeof at, "%s:%d:", name, k->at_line);
            assert_non_null(strstr(st.message, name));
            if (k->at_line)
                assert_non_null(strstr(st.message, at));
        }
        sw_sg_tspline_free(ts);
    }
}

static void test_explicit_knotpoints(void **state)
{
    (void)state;
    /* One cubic Bézier patch as 16 explicit points; then a decreasing local knot vector. */
    char buf[4096];
    size_t len = (size_t)snprintf(buf, sizeof buf, "tsm 1\ndomain 0 1 0 1\nknotpoints 16\n");
    static const double k[4][5] = {
        {0, 0, 0, 0, 1}, {0, 0, 0, 1, 1}, {0, 0, 1, 1, 1}, {0, 1, 1, 1, 1}};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            len += (size_t)snprintf(buf + len, sizeof buf - len,
                                    "%d %d %g 1 %g %g %g %g %g %g %g %g %g %g\n", i, j, 0.1 * i * j,
                                    k[i][0], k[i][1], k[i][2], k[i][3], k[i][4], k[j][0], k[j][1],
                                    k[j][2], k[j][3], k[j][4]);
    len += (size_t)snprintf(buf + len, sizeof buf - len, "end\n");
    sw_sg_tspline *ts = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_tspline_load_mem(buf, len, "bez.tsm", &ts, &st), SW_OK);
    assert_int_equal(sw_sg_tspline_view_ptr(ts)->n_regions, 1);
    double p[3];
    sw_sg_tspline_eval(ts, 1.0, 1.0, p); /* the closed upper corner: the last point */
    assert_true(fabs(p[0] - 3) < 1e-15 && fabs(p[1] - 3) < 1e-15 && fabs(p[2] - 0.9) < 1e-15);
    sw_sg_tspline_free(ts);
    char *row = strstr(buf, "\n1 0 0 1 ");
    assert_non_null(row);
    memcpy(row + 1, "1 0 0 1 0 0 1 0 1", 17); /* local u knots 0 0 1 0 1 */
    assert_int_equal(sw_sg_tspline_load_mem(buf, len, "bez.tsm", &ts, &st),
                     SW_ERR_INVALID_GEOMETRY);
    print_message("decreasing local knots -> %s\n", st.message);
    assert_non_null(strstr(st.message, "bez.tsm:5:"));
}

/* --compare A B: the two .tsm files define the same T-spline to 1e-12 (the checked-in samples
 * against a fresh run of their generator; the last bits of libm's sin/cos may differ). */
static int compare_files(const char *a, const char *b)
{
    sw_sg_tspline *ta = NULL, *tb = NULL;
    sw_status st = {0};
    if (sw_sg_tspline_load(a, &ta, &st) != SW_OK || sw_sg_tspline_load(b, &tb, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    const sw_sg_tspline_view *va = sw_sg_tspline_view_ptr(ta), *vb = sw_sg_tspline_view_ptr(tb);
    int bad = va->n_points != vb->n_points;
    for (uint32_t i = 0; !bad && i < va->n_points; i++) {
        for (int c = 0; c < 4; c++)
            bad |= fabs(va->cpw[i * 4 + c] - vb->cpw[i * 4 + c]) > 1e-12;
        for (int k = 0; k < 5; k++)
            bad |= va->knots_u[i * 5 + k] != vb->knots_u[i * 5 + k] ||
                   va->knots_v[i * 5 + k] != vb->knots_v[i * 5 + k];
    }
    if (bad)
        fprintf(stderr, "%s and %s differ: regenerate with make_tspline_samples\n", a, b);
    sw_sg_tspline_free(ta);
    sw_sg_tspline_free(tb);
    return bad;
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "--compare"))
        return compare_files(argv[2], argv[3]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_local_refinement_equals_nurbs),
        cmocka_unit_test(test_t_junctions_evaluators_agree),
        cmocka_unit_test(test_partition_of_unity),
        cmocka_unit_test(test_region_lists_brute_force),
        cmocka_unit_test(test_t_junctions_need_more_as_nurbs),
        cmocka_unit_test(test_scene_builder),
        cmocka_unit_test(test_parser_bad_input),
        cmocka_unit_test(test_explicit_knotpoints),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

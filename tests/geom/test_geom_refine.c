/* SPDX-License-Identifier: MIT */
/* Knot insertion (Boehm) and Bézier extraction must not change a surface: random rational
 * surfaces of degrees 1..7 in u and v (random knot vectors with repeated knots, clamped and
 * unclamped ends, weights in [0.2, 5]) are evaluated at 10,000 random (u, v) each before and after,
 * and the largest distance must stay below 1e-10 x the diagonal of the sampled points' box.
 * Restricted extraction must produce exactly the patches that meet the box, bit-identical to the
 * full extraction's. The reference is the unrefined surface itself (an exact identity). */
#include "geom_test_util.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#define N_SAMPLES 10000
#define TOL 1e-10

/* Inserts t `times` times into the u (dir 0) or v (dir 1) knot vector of g, replacing g. */
static void surface_insert(gt_surface *g, int dir, double t, int times)
{
    const sw_sg_surface *s = &g->s;
    const int p = dir ? s->deg_v : s->deg_u;
    const int n = dir ? s->n_v : s->n_u, other = dir ? s->n_u : s->n_v;
    const double *knots = dir ? s->knots_v : s->knots_u;
    double *nk = malloc(sizeof(double) * (size_t)(n + p + 1 + times));
    double *ncpw = malloc(sizeof(double) * 4 * (size_t)(n + times) * (size_t)other);
    double *line = malloc(sizeof(double) * 4 * (size_t)n);
    double *nline = malloc(sizeof(double) * 4 * (size_t)(n + times));
    assert_non_null(nk);
    assert_non_null(ncpw);
    assert_non_null(line);
    assert_non_null(nline);
    const int new_nu = dir ? s->n_u : s->n_u + times;
    for (int o = 0; o < other; o++) {
        for (int i = 0; i < n; i++) {
            const int src = dir ? i * s->n_u + o : o * s->n_u + i;
            memcpy(line + i * 4, s->cpw + src * 4, sizeof(double) * 4);
        }
        sw_sg_curve c = {.degree = p, .n = n, .dim = 4, .knots = knots, .cpw = line};
        sw_sg_curve_insert_knot(&c, t, times, nk, nline);
        for (int i = 0; i < n + times; i++) {
            const int dst = dir ? i * new_nu + o : o * new_nu + i;
            memcpy(ncpw + dst * 4, nline + i * 4, sizeof(double) * 4);
        }
    }
    free(line);
    free(nline);
    free(g->cpw);
    g->cpw = ncpw;
    if (dir) {
        free(g->kv);
        g->kv = nk;
        g->s.knots_v = nk;
        g->s.n_v += times;
    } else {
        free(g->ku);
        g->ku = nk;
        g->s.knots_u = nk;
        g->s.n_u += times;
    }
    g->s.cpw = ncpw;
}

/* A parameter at which to insert: an existing interior knot half the time, else random. */
static void pick_insertion(gt_rng *r, const double *knots, int p, int n, double *t, int *times)
{
    double t0, t1;
    sw_sg_knots_domain(knots, p, n, &t0, &t1);
    for (;;) {
        *t = gt_uniform(r, t0, t1);
        if (n > p + 1 && gt_int(r, 0, 1)) {
            double cand = knots[gt_int(r, p + 1, n - 1)];
            if (cand > t0 && cand < t1)
                *t = cand;
        }
        int s = 0;
        for (int i = 0; i < n + p + 1; i++)
            s += knots[i] == *t;
        if (s < p + 1) {
            *times = gt_int(r, 1, p + 1 - s);
            return;
        }
    }
}

/* seg_of_span[k] = index among non-empty spans of span k. */
static int *segment_index(const double *knots, int p, int n)
{
    int *seg = calloc((size_t)n + 1, sizeof(int));
    assert_non_null(seg);
    int count = 0;
    for (int k = p; k < n; k++) {
        seg[k] = count;
        count += knots[k] < knots[k + 1];
    }
    return seg;
}

typedef struct refine_stats {
    double worst_insert, worst_bezier; /* relative to the box diagonal */
    long samples;
    int surfaces;
} refine_stats;

static double max_rel_error(const sw_sg_surface *b, const double *uv, const double *ref,
                            double diag)
{
    double worst = 0.0;
    for (int k = 0; k < N_SAMPLES; k++) {
        double q[3];
        sw_sg_surface_eval(b, uv[2 * k], uv[2 * k + 1], q);
        worst = fmax(worst, gt_dist3(ref + 3 * k, q) / diag);
    }
    return worst;
}

static double bezier_error(const sw_sg_surface *s, const sw_sg_bezier_set *set, const double *uv,
                           const double *ref, double diag)
{
    int *su = segment_index(s->knots_u, s->deg_u, s->n_u);
    int *sv = segment_index(s->knots_v, s->deg_v, s->n_v);
    double worst = 0.0;
    for (int k = 0; k < N_SAMPLES; k++) {
        const double u = uv[2 * k], v = uv[2 * k + 1];
        const int a = su[sw_sg_knots_find_span(s->knots_u, s->deg_u, s->n_u, u)];
        const int b = sv[sw_sg_knots_find_span(s->knots_v, s->deg_v, s->n_v, v)];
        const sw_sg_bezier_patch *pt = &set->patches[b * set->n_u + a];
        assert_int_equal(pt->seg_u, a);
        assert_int_equal(pt->seg_v, b);
        assert_true(u >= pt->u0 && u <= pt->u1 && v >= pt->v0 && v <= pt->v1);
        double q[3];
        sw_sg_bezier_patch_eval(pt, (u - pt->u0) / (pt->u1 - pt->u0),
                                (v - pt->v0) / (pt->v1 - pt->v0), q);
        worst = fmax(worst, gt_dist3(ref + 3 * k, q) / diag);
    }
    free(su);
    free(sv);
    return worst;
}

/* Restricted extraction yields exactly the patches whose rectangle overlaps the box. */
static void check_restricted(gt_rng *r, const sw_sg_surface *s, const sw_sg_bezier_set *full)
{
    double u0, u1, v0, v1;
    gt_domain(s, &u0, &u1, &v0, &v1);
    const double a0 = gt_uniform(r, u0 - 0.1 * (u1 - u0), u1), a1 = gt_uniform(r, a0, u1 + 0.1);
    const double b0 = gt_uniform(r, v0 - 0.1 * (v1 - v0), v1), b1 = gt_uniform(r, b0, v1 + 0.1);
    sw_sg_bezier_set part;
    sw_status st = {0};
    assert_int_equal(sw_sg_surface_extract_bezier_in(s, a0, a1, b0, b1, &part, &st), SW_OK);
    int expect = 0, found = 0;
    const size_t per = (size_t)(s->deg_u + 1) * (size_t)(s->deg_v + 1) * 4;
    for (int i = 0; i < full->n_u * full->n_v; i++) {
        const sw_sg_bezier_patch *f = &full->patches[i];
        const int meets = f->u0 < a1 && f->u1 > a0 && f->v0 < b1 && f->v1 > b0;
        expect += meets;
        for (int j = 0; j < part.n_u * part.n_v; j++) {
            const sw_sg_bezier_patch *g = &part.patches[j];
            if (g->seg_u == f->seg_u && g->seg_v == f->seg_v) {
                assert_true(meets);
                assert_memory_equal(g->cpw, f->cpw, per * sizeof(double));
                assert_true(g->u0 == f->u0 && g->u1 == f->u1 && g->v0 == f->v0 && g->v1 == f->v1);
                found++;
            }
        }
    }
    assert_int_equal(found, expect);
    assert_int_equal(part.n_u * part.n_v, expect);
    sw_sg_bezier_set_free(&part);
}

static void refine_one(gt_rng *r, int p, int q, refine_stats *st)
{
    gt_surface g;
    gt_surface_make(r, p, q, p + 1 + gt_int(r, 0, 7), q + 1 + gt_int(r, 0, 7), &g);
    sw_status status = {0};
    assert_int_equal(sw_sg_surface_validate(&g.s, "random surface", &status), SW_OK);

    double u0, u1, v0, v1;
    gt_domain(&g.s, &u0, &u1, &v0, &v1);
    double *uv = malloc(sizeof(double) * 2 * N_SAMPLES);
    double *ref = malloc(sizeof(double) * 3 * N_SAMPLES);
    assert_non_null(uv);
    assert_non_null(ref);
    gt_box box;
    gt_box_init(&box);
    for (int k = 0; k < N_SAMPLES; k++) {
        uv[2 * k] = gt_uniform(r, u0, u1);
        uv[2 * k + 1] = gt_uniform(r, v0, v1);
        sw_sg_surface_eval(&g.s, uv[2 * k], uv[2 * k + 1], ref + 3 * k);
        gt_box_add(&box, ref + 3 * k);
    }
    const double diag = gt_box_diag(&box);

    /* Bézier extraction of the original surface. */
    sw_sg_bezier_set set;
    assert_int_equal(sw_sg_surface_extract_bezier(&g.s, &set, &status), SW_OK);
    assert_int_equal(set.n_u, sw_sg_knots_segment_count(g.ku, p, g.s.n_u));
    assert_int_equal(set.n_v, sw_sg_knots_segment_count(g.kv, q, g.s.n_v));
    assert_true(sw_sg_surface_bezier_storage_bound(&g.s) ==
                (size_t)set.n_u * (size_t)set.n_v * (size_t)((p + 1) * (q + 1) * 4));
    const double eb = bezier_error(&g.s, &set, uv, ref, diag);
    for (int k = 0; k < 3; k++)
        check_restricted(r, &g.s, &set);
    sw_sg_bezier_set_free(&set);

    /* Two insertions in u and one in v, each at a random or an existing knot. */
    for (int k = 0; k < 3; k++) {
        const int dir = k == 2;
        double t;
        int times;
        pick_insertion(r, dir ? g.kv : g.ku, dir ? q : p, dir ? g.s.n_v : g.s.n_u, &t, &times);
        surface_insert(&g, dir, t, times);
        assert_int_equal(sw_sg_surface_validate(&g.s, "refined surface", &status), SW_OK);
    }
    const double ei = max_rel_error(&g.s, uv, ref, diag);

    st->worst_insert = fmax(st->worst_insert, ei);
    st->worst_bezier = fmax(st->worst_bezier, eb);
    st->samples += N_SAMPLES;
    st->surfaces++;
    if (!(ei <= TOL && eb <= TOL))
        printf("  degree %d x %d, %d x %d poles: insertion %.3g, Bézier %.3g (x diagonal)\n", p, q,
               g.s.n_u, g.s.n_v, ei, eb);
    assert_true(ei <= TOL);
    assert_true(eb <= TOL);
    free(uv);
    free(ref);
    gt_surface_free(&g);
}

static void test_refine_random_surfaces(void **state)
{
    (void)state;
    const uint64_t seed = gt_seed();
    gt_rng r = {seed};
    refine_stats st = {0};
    for (int round = 0; round < 3; round++)
        for (int p = 1; p <= 7; p++)
            for (int q = 1; q <= 7; q++)
                refine_one(&r, p, q, &st);
    printf("refine: seed %llu, %d surfaces (3 x degrees 1..7 x 1..7), %ld samples: max error / "
           "diagonal: knot insertion %.3g, Bézier extraction %.3g (tolerance %.0e)\n",
           (unsigned long long)seed, st.surfaces, st.samples, st.worst_insert, st.worst_bezier,
           TOL);
}

/* Inserting a knot up to full multiplicity into a trim curve (dim 3) keeps every point. */
static void test_insert_curve_full_multiplicity(void **state)
{
    (void)state;
    gt_rng r = {gt_seed() + 1};
    double worst = 0.0;
    for (int trial = 0; trial < 200; trial++) {
        const int p = gt_int(&r, 1, 9), n = p + 1 + gt_int(&r, 0, 6);
        double knots[64], cpw[64 * 3], nk[80], ncpw[80 * 3];
        gt_random_knots(&r, p, n, knots);
        for (int i = 0; i < n; i++) {
            const double w = gt_uniform(&r, 0.2, 5.0);
            cpw[i * 3] = w * gt_uniform(&r, -1, 1);
            cpw[i * 3 + 1] = w * gt_uniform(&r, -1, 1);
            cpw[i * 3 + 2] = w;
        }
        sw_sg_curve c = {.degree = p, .n = n, .dim = 3, .knots = knots, .cpw = cpw};
        assert_int_equal(sw_sg_curve_validate(&c, "trim curve", NULL), SW_OK);
        double t, t0, t1;
        int times;
        pick_insertion(&r, knots, p, n, &t, &times);
        sw_sg_curve_insert_knot(&c, t, times, nk, ncpw);
        sw_sg_curve d = {.degree = p, .n = n + times, .dim = 3, .knots = nk, .cpw = ncpw};
        assert_int_equal(sw_sg_curve_validate(&d, "refined trim curve", NULL), SW_OK);
        sw_sg_knots_domain(knots, p, n, &t0, &t1);
        for (int k = 0; k <= 200; k++) {
            const double x = t0 + (t1 - t0) * k / 200.0;
            double a[2], b[2];
            sw_sg_curve_eval(&c, x, a);
            sw_sg_curve_eval(&d, x, b);
            worst = fmax(worst, hypot(a[0] - b[0], a[1] - b[1]));
        }
        /* Ends evaluate to the end points of a clamped vector (last span closed). */
        if (knots[0] == t0) {
            double a[2];
            sw_sg_curve_eval(&c, t0, a);
            assert_true(fabs(a[0] - cpw[0] / cpw[2]) <= 1e-14 &&
                        fabs(a[1] - cpw[1] / cpw[2]) <= 1e-14);
        }
        if (knots[n + p] == t1) {
            double a[2];
            const double *e = cpw + (n - 1) * 3;
            sw_sg_curve_eval(&c, t1, a);
            assert_true(fabs(a[0] - e[0] / e[2]) <= 1e-14 && fabs(a[1] - e[1] / e[2]) <= 1e-14);
        }
    }
    printf("curve insertion: 200 curves of degree 1..9, 201 points each: max distance %.3g\n",
           worst);
    assert_true(worst <= 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refine_random_surfaces),
        cmocka_unit_test(test_insert_curve_full_multiplicity),
    };
    return cmocka_run_group_tests_name("geom_refine", tests, NULL, NULL);
}

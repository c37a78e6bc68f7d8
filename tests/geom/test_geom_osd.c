/* SPDX-License-Identifier: MIT */
/* The uniform bicubic B-spline evaluator against OpenSubdiv, linked for real through the
 * lod/osd/uniform_bicubic_osd.cpp shim: random regular control grids (random heights and jittered
 * x, y), every interior face whose 4x4 neighbourhood lies in the grid, random (s, t) plus the
 * corners. Compared directly, in Bézier form (sw_sg_uniform_bicubic_to_bezier + Bézier patch
 * evaluation), and as a uniform unclamped B-spline surface through the NURBS evaluator and its
 * Bézier extraction (positions and first derivatives). Tolerance 1e-10 relative to the grid's
 * bbox diagonal (derivatives: to their largest magnitude). */
#include "geom_test_util.h"
#include "sw_lod_osd.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#define TOL 1e-10
#define PER_FACE 200

typedef struct grid_case {
    int nx, ny;
} grid_case;

static void fill_grid(gt_rng *r, int nx, int ny, double *verts)
{
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double *p = verts + (j * nx + i) * 3;
            p[0] = i + gt_uniform(r, -0.3, 0.3);
            p[1] = j + gt_uniform(r, -0.3, 0.3);
            p[2] = gt_uniform(r, -2.0, 2.0);
        }
}

/* The 4x4 neighbourhood of face (fi, fj), u fastest. */
static void face_net(const double *verts, int nx, int fi, int fj, double cp[48])
{
    for (int b = 0; b < 4; b++)
        for (int a = 0; a < 4; a++)
            memcpy(cp + (b * 4 + a) * 3, verts + ((fj - 1 + b) * nx + (fi - 1 + a)) * 3,
                   sizeof(double) * 3);
}

static void test_osd_regular_grids(void **state)
{
    (void)state;
    const uint64_t seed = gt_seed();
    gt_rng r = {seed};
    const grid_case cases[] = {{8, 8}, {8, 8}, {8, 8}, {10, 7}, {5, 9}, {4, 4}};
    double worst_direct = 0, worst_bezier = 0, worst_nurbs = 0, worst_extract = 0;
    double worst_du = 0, worst_dv = 0, worst_net = 0;
    long samples = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const int nx = cases[c].nx, ny = cases[c].ny;
        double *verts = malloc(sizeof(double) * 3 * (size_t)(nx * ny));
        assert_non_null(verts);
        fill_grid(&r, nx, ny, verts);
        gt_box box;
        gt_box_init(&box);
        for (int k = 0; k < nx * ny; k++)
            gt_box_add(&box, verts + 3 * k);
        const double diag = gt_box_diag(&box);

        /* Interior faces: 1 <= fi <= nx - 3, 1 <= fj <= ny - 3. */
        const int fx = nx - 3, fy = ny - 3, count = fx * fy * (PER_FACE + 4);
        sw_lod_osd_sample *smp = malloc(sizeof *smp * (size_t)count);
        double *pos = malloc(sizeof(double) * 3 * (size_t)count);
        double *ds = malloc(sizeof(double) * 3 * (size_t)count);
        double *dt = malloc(sizeof(double) * 3 * (size_t)count);
        assert_true(smp && pos && ds && dt);
        int n = 0;
        for (int fj = 1; fj <= ny - 3; fj++)
            for (int fi = 1; fi <= nx - 3; fi++)
                for (int k = 0; k < PER_FACE + 4; k++) {
                    const double s = k < 4 ? (k & 1) : gt_uniform(&r, 0, 1);
                    const double t = k < 4 ? (k >> 1) : gt_uniform(&r, 0, 1);
                    smp[n++] = (sw_lod_osd_sample){fi, fj, s, t};
                }
        sw_status st = {0};
        const sw_result res = sw_lod_osd_eval_grid(verts, nx, ny, smp, (size_t)n, pos, ds, dt, &st);
        if (res != SW_OK)
            printf("OpenSubdiv failed: %s\n", st.message);
        assert_int_equal(res, SW_OK);

        /* The same net as a uniform unclamped bicubic B-spline surface: face i is knot span
         * [i + 2, i + 3] of the knot vector 0, 1, ..., n + 3. */
        double *cpw = malloc(sizeof(double) * 4 * (size_t)(nx * ny));
        double ku[64], kv[64];
        assert_non_null(cpw);
        for (int k = 0; k < nx * ny; k++) {
            memcpy(cpw + 4 * k, verts + 3 * k, sizeof(double) * 3);
            cpw[4 * k + 3] = 1.0;
        }
        for (int k = 0; k < nx + 4; k++)
            ku[k] = k;
        for (int k = 0; k < ny + 4; k++)
            kv[k] = k;
        sw_sg_surface surf = {
            .deg_u = 3, .deg_v = 3, .n_u = nx, .n_v = ny, .knots_u = ku, .knots_v = kv, .cpw = cpw};
        assert_int_equal(sw_sg_surface_validate(&surf, "grid", NULL), SW_OK);
        sw_sg_bezier_set set;
        assert_int_equal(sw_sg_surface_extract_bezier(&surf, &set, NULL), SW_OK);
        assert_int_equal(set.n_u, nx - 3);
        assert_int_equal(set.n_v, ny - 3);

        double mag_du = 0, mag_dv = 0, err_du = 0, err_dv = 0;
        for (int k = 0; k < n; k++) {
            const sw_lod_osd_sample *q = &smp[k];
            double cp[48], bez[48], a[3], b[3], c3[3];
            face_net(verts, nx, q->face_i, q->face_j, cp);
            sw_sg_uniform_bicubic_eval(cp, q->s, q->t, a);
            worst_direct = fmax(worst_direct, gt_dist3(a, pos + 3 * k) / diag);

            sw_sg_uniform_bicubic_to_bezier(cp, bez);
            double bcpw[64];
            for (int m = 0; m < 16; m++) {
                memcpy(bcpw + 4 * m, bez + 3 * m, sizeof(double) * 3);
                bcpw[4 * m + 3] = 1.0;
            }
            sw_sg_bezier_patch patch = {.deg_u = 3, .deg_v = 3, .cpw = bcpw};
            sw_sg_bezier_patch_eval(&patch, q->s, q->t, b);
            worst_bezier = fmax(worst_bezier, gt_dist3(b, pos + 3 * k) / diag);

            /* Bézier form from the NURBS extraction equals the uniform-bicubic conversion. */
            const sw_sg_bezier_patch *ex = &set.patches[(q->face_j - 1) * set.n_u + q->face_i - 1];
            assert_true(ex->u0 == q->face_i + 2 && ex->v0 == q->face_j + 2);
            for (int m = 0; m < 16; m++)
                worst_net = fmax(worst_net, gt_dist3(ex->cpw + 4 * m, bez + 3 * m) / diag);
            sw_sg_bezier_patch_eval(ex, q->s, q->t, c3);
            worst_extract = fmax(worst_extract, gt_dist3(c3, pos + 3 * k) / diag);

            sw_sg_surface_d2 d;
            sw_sg_surface_eval_d2(&surf, q->face_i + 2 + q->s, q->face_j + 2 + q->t, &d);
            worst_nurbs = fmax(worst_nurbs, gt_dist3(d.p, pos + 3 * k) / diag);
            err_du = fmax(err_du, gt_dist3(d.du, ds + 3 * k));
            err_dv = fmax(err_dv, gt_dist3(d.dv, dt + 3 * k));
            mag_du = fmax(mag_du, gt_norm3(ds + 3 * k));
            mag_dv = fmax(mag_dv, gt_norm3(dt + 3 * k));
        }
        worst_du = fmax(worst_du, err_du / mag_du);
        worst_dv = fmax(worst_dv, err_dv / mag_dv);
        samples += n;
        sw_sg_bezier_set_free(&set);
        free(cpw);
        free(smp);
        free(pos);
        free(ds);
        free(dt);
        free(verts);
    }
    printf("OpenSubdiv %s limit surface vs project, seed %llu, 6 grids (8x8 x3, 10x7, 5x9, 4x4), "
           "%ld samples on interior faces; max error / diagonal: uniform bicubic %.2g, its Bézier "
           "form %.2g, NURBS evaluator %.2g, extracted Bézier patch %.2g (nets differ by %.2g); "
           "derivatives relative: d/ds %.2g, d/dt %.2g (tolerance %.0e)\n",
           sw_lod_osd_version(), (unsigned long long)seed, samples, worst_direct, worst_bezier,
           worst_nurbs, worst_extract, worst_net, worst_du, worst_dv, TOL);
    assert_true(worst_direct <= TOL);
    assert_true(worst_bezier <= TOL);
    assert_true(worst_nurbs <= TOL);
    assert_true(worst_extract <= TOL);
    assert_true(worst_net <= TOL);
    assert_true(worst_du <= TOL);
    assert_true(worst_dv <= TOL);
}

/* The shim turns bad requests into results instead of crashing or throwing. */
static void test_osd_rejects_bad_requests(void **state)
{
    (void)state;
    double verts[4 * 4 * 3] = {0}, pos[3];
    sw_status st = {0};
    sw_lod_osd_sample bad_face = {3, 0, 0.5, 0.5};
    assert_int_equal(sw_lod_osd_eval_grid(verts, 4, 4, &bad_face, 1, pos, NULL, NULL, &st),
                     SW_ERR_INVALID_ARGUMENT);
    sw_lod_osd_sample bad_st = {1, 1, NAN, 0.5};
    assert_int_equal(sw_lod_osd_eval_grid(verts, 4, 4, &bad_st, 1, pos, NULL, NULL, &st),
                     SW_ERR_INVALID_ARGUMENT);
    assert_int_equal(sw_lod_osd_eval_grid(verts, 1, 4, &bad_st, 1, pos, NULL, NULL, &st),
                     SW_ERR_INVALID_ARGUMENT);
    assert_int_equal(sw_lod_osd_eval_grid(NULL, 4, 4, &bad_st, 1, pos, NULL, NULL, NULL),
                     SW_ERR_INVALID_ARGUMENT);
}

/* Boundary and corner faces go through OpenSubdiv's boundary patches and end caps: they must
 * evaluate, and the limit surface stays inside the control points' convex hull (so its box). */
static void test_osd_boundary_faces(void **state)
{
    (void)state;
    gt_rng r = {gt_seed() + 3};
    const int nx = 6, ny = 5;
    double verts[6 * 5 * 3];
    fill_grid(&r, nx, ny, verts);
    gt_box box;
    gt_box_init(&box);
    for (int k = 0; k < nx * ny; k++)
        gt_box_add(&box, verts + 3 * k);
    sw_lod_osd_sample smp[5 * 4 * 9];
    double pos[5 * 4 * 9 * 3];
    int n = 0;
    for (int fj = 0; fj < ny - 1; fj++)
        for (int fi = 0; fi < nx - 1; fi++)
            for (int k = 0; k < 9; k++)
                smp[n++] = (sw_lod_osd_sample){fi, fj, (k % 3) * 0.5, (k / 3) * 0.5};
    sw_status st = {0};
    assert_int_equal(sw_lod_osd_eval_grid(verts, nx, ny, smp, (size_t)n, pos, NULL, NULL, &st),
                     SW_OK);
    for (int k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            assert_true(pos[3 * k + c] >= box.lo[c] - 1e-12 && pos[3 * k + c] <= box.hi[c] + 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_osd_regular_grids),
        cmocka_unit_test(test_osd_rejects_bad_requests),
        cmocka_unit_test(test_osd_boundary_faces),
    };
    return cmocka_run_group_tests_name("geom_osd", tests, NULL, NULL);
}

/* SPDX-License-Identifier: MIT */
/* Trim loops (scenegraph/trim.c) against analytic shapes: a unit-square loop with a circular hole
 * made of exact rational quadratic arcs. Flattened vertices must lie on the circle, every chord
 * within the tolerance of it, join vertices bit-identical to the curves' first control points;
 * snapping closes gaps or refuses them; even-odd parity equals the analytic region. */
#include "sw_sg_trim.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

enum { N_ARCS = 4 };
static const double R = 0.3, CX = 0.5, CY = 0.45;

/* Quarter k of the circle as a rational quadratic (w = 1, sqrt(2)/2, 1), homogeneous. */
static void quarter(int k, double cpw[9])
{
    const double a0 = k * M_PI / 2, a1 = a0 + M_PI / 2, w = sqrt(0.5);
    const double p0[2] = {CX + R * cos(a0), CY + R * sin(a0)};
    const double p2[2] = {CX + R * cos(a1), CY + R * sin(a1)};
    /* corner of the tangents: centre + R (cos a0 + cos a1, sin a0 + sin a1) */
    const double p1[2] = {CX + R * (cos(a0) + cos(a1)), CY + R * (sin(a0) + sin(a1))};
    const double pts[3][2] = {{p0[0], p0[1]}, {p1[0], p1[1]}, {p2[0], p2[1]}};
    const double ws[3] = {1.0, w, 1.0};
    for (int i = 0; i < 3; i++) {
        cpw[3 * i] = pts[i][0] * ws[i];
        cpw[3 * i + 1] = pts[i][1] * ws[i];
        cpw[3 * i + 2] = ws[i];
    }
}

static uint32_t add_curve(sw_sg_builder *b, int degree, int n, const double *knots,
                          const double *cpw)
{
    sw_sg_curve_rec c = {(uint32_t)degree, (uint32_t)n, 0, 0};
    c.knots = sw_sg_builder_push_doubles(b, knots, (size_t)(n + degree + 1));
    c.cpw = sw_sg_builder_push_doubles(b, cpw, (size_t)n * 3);
    return sw_sg_builder_add_curve(b, &c);
}

/* Scene with loop 0 = unit square (4 lines), loop 1 = the circle (4 arcs), on a planar face. */
static sw_sg_scene *make_scene(void)
{
    sw_sg_builder *b = sw_sg_builder_create();
    assert_non_null(b);
    const double lk[4] = {0, 0, 1, 1}, qk[6] = {0, 0, 0, 1, 1, 1};
    const double sq[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
    uint32_t first = SW_SG_NONE;
    for (int k = 0; k < 4; k++) {
        double cpw[6] = {sq[k][0], sq[k][1], 1, sq[k + 1][0], sq[k + 1][1], 1};
        uint32_t c = add_curve(b, 1, 2, lk, cpw);
        if (first == SW_SG_NONE)
            first = c;
    }
    sw_sg_loop_rec outer = {first, 4, SW_SG_LOOP_OUTER, 0};
    uint32_t l0 = sw_sg_builder_add_loop(b, &outer);
    first = SW_SG_NONE;
    for (int k = 0; k < N_ARCS; k++) {
        double cpw[9];
        quarter(k, cpw);
        uint32_t c = add_curve(b, 2, 3, qk, cpw);
        if (first == SW_SG_NONE)
            first = c;
    }
    sw_sg_loop_rec hole = {first, N_ARCS, 0, 0};
    sw_sg_builder_add_loop(b, &hole);
    const double fk[4] = {0, 0, 1, 1};
    const double net[16] = {0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 1, 1, 0, 1};
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 1;
    f.n_u = f.n_v = 2;
    f.knots_u = sw_sg_builder_push_doubles(b, fk, 4);
    f.knots_v = sw_sg_builder_push_doubles(b, fk, 4);
    f.cpw = sw_sg_builder_push_doubles(b, net, 16);
    f.first_loop = l0;
    f.n_loops = 2;
    f.flags = SW_SG_FACE_TRIMMED;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    uint32_t fi = sw_sg_builder_add_face(b, &f);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, fi, NULL, NULL, NULL);
    sw_sg_scene *scene = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_builder_finish(b, &scene, &st), SW_OK);
    return scene;
}

static void test_flatten_circle(void **state)
{
    (void)state;
    sw_sg_scene *scene = make_scene();
    const double tols[3] = {1e-2, 1e-4, 1e-7};
    for (int t = 0; t < 3; t++) {
        const double tol = tols[t];
        sw_sg_polyline pl;
        sw_status st = {0};
        assert_int_equal(sw_sg_trim_flatten_loop(scene, 1, tol, 1u << 20, &pl, &st), SW_OK);
        /* the minimal count for sagitta tol is pi / acos(1 - tol / R); subdivision by halves may
         * need up to twice that */
        const double minimal = M_PI / acos(1.0 - tol / R);
        assert_true(pl.count >= (uint32_t)minimal && pl.count <= 2.5 * minimal + 8);
        double worst_radius = 0, worst_sagitta = 0;
        for (uint32_t i = 0; i < pl.count; i++) {
            const double *a = pl.uv + 2 * i, *b = pl.uv + 2 * ((i + 1) % pl.count);
            worst_radius = fmax(worst_radius, fabs(hypot(a[0] - CX, a[1] - CY) - R));
            const double half = 0.5 * hypot(b[0] - a[0], b[1] - a[1]);
            worst_sagitta = fmax(worst_sagitta, R - sqrt(R * R - half * half));
        }
        printf("tol %g: %u vertices (minimal %.0f), radius error %.2g, worst sagitta %.3g\n", tol,
               pl.count, ceil(minimal), worst_radius, worst_sagitta);
        assert_true(worst_radius < 1e-14);
        assert_true(worst_sagitta <= tol * (1 + 1e-9));
        sw_sg_polyline_free(&pl);
    }
    sw_sg_scene_free(scene);
}

/* Join vertices are the curves' first control points, bit for bit, and vertex 0 is the loop's. */
static void test_flatten_joins(void **state)
{
    (void)state;
    sw_sg_scene *scene = make_scene();
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    sw_sg_polyline pl;
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 1, 1e-3, 1u << 20, &pl, NULL), SW_OK);
    uint32_t found = 0;
    for (uint32_t k = 0; k < N_ARCS; k++) {
        sw_sg_curve c;
        sw_sg_scene_curve(scene, v->loops[1].first_curve + k, &c);
        const double u = c.cpw[0] / c.cpw[2], w = c.cpw[1] / c.cpw[2];
        for (uint32_t i = 0; i < pl.count; i++)
            if (pl.uv[2 * i] == u && pl.uv[2 * i + 1] == w) {
                found++;
                if (k == 0)
                    assert_int_equal(i, 0);
                break;
            }
    }
    assert_int_equal(found, N_ARCS);
    /* the closing vertex is not repeated */
    assert_false(pl.uv[0] == pl.uv[2 * (pl.count - 1)] && pl.uv[1] == pl.uv[2 * pl.count - 1]);
    sw_sg_polyline_free(&pl);
    /* the square's lines are flat at once: exactly its 4 corners */
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 0, 1e-9, 100, &pl, NULL), SW_OK);
    assert_int_equal(pl.count, 4);
    sw_sg_polyline_free(&pl);
    sw_status st = {0};
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 1, 1e-9, 50, &pl, &st), SW_ERR_LIMIT);
    assert_null(pl.uv);
    sw_sg_scene_free(scene);
}

static void test_classify(void **state)
{
    (void)state;
    sw_sg_scene *scene = make_scene();
    sw_sg_polyline pl[2];
    const double tol = 1e-6;
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 0, tol, 1u << 20, &pl[0], NULL), SW_OK);
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 1, tol, 1u << 20, &pl[1], NULL), SW_OK);
    uint64_t s = 12345;
    int checked = 0;
    for (int k = 0; k < 200000; k++) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        double u = -0.1 + 1.2 * (double)(s >> 11) * 0x1.0p-53;
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        double v = -0.1 + 1.2 * (double)(s >> 11) * 0x1.0p-53;
        double rc = hypot(u - CX, v - CY);
        double d_sq = fmin(fmin(fabs(u), fabs(1 - u)), fmin(fabs(v), fabs(1 - v)));
        if (fabs(rc - R) <= 2 * tol || d_sq <= 2 * tol)
            continue;
        int inside = u > 0 && u < 1 && v > 0 && v < 1 && rc > R;
        assert_int_equal(sw_sg_trim_classify(pl, 2, u, v), inside);
        checked++;
    }
    assert_true(checked > 199000);
    /* a vertex exactly on the ray's line counts once: the square's corner row v = 0 */
    assert_int_equal(sw_sg_trim_classify(pl, 1, 0.5, 0.0), 1);
    assert_int_equal(sw_sg_trim_classify(pl, 1, -0.5, 0.0), 0);
    sw_sg_polyline_free(&pl[0]);
    sw_sg_polyline_free(&pl[1]);
    sw_sg_scene_free(scene);
}

static void test_snap(void **state)
{
    (void)state;
    double arcs[N_ARCS][9];
    double *cpw[N_ARCS];
    const int32_t n[N_ARCS] = {3, 3, 3, 3};
    for (int k = 0; k < N_ARCS; k++) {
        quarter(k, arcs[k]);
        cpw[k] = arcs[k];
    }
    /* open gaps of up to 1e-5 (the end of arc 1, the start of arc 3, weights 1) */
    arcs[1][6] += 1e-5;
    arcs[3][1] -= 7e-6;
    double saved[N_ARCS][9];
    memcpy(saved, arcs, sizeof arcs);
    sw_status st = {0};
    assert_int_equal(sw_sg_trim_snap_loop(N_ARCS, cpw, n, 5e-6, "test loop", &st),
                     SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "test loop"));
    assert_memory_equal(saved, arcs, sizeof arcs); /* refused: unchanged */
    assert_int_equal(sw_sg_trim_snap_loop(N_ARCS, cpw, n, 2e-5, "test loop", &st), SW_OK);
    for (int k = 0; k < N_ARCS; k++) {
        const double *end = arcs[k] + 6, *start = arcs[(k + 1) % N_ARCS];
        assert_true(end[0] / end[2] == start[0] / start[2]);
        assert_true(end[1] / end[2] == start[1] / start[2]);
    }
    /* the snapped join is the midpoint of the gap */
    assert_true(fabs(arcs[2][0] - (saved[1][6] + saved[2][0]) / 2) < 1e-16);
    /* weighted ends keep their weights and share the Euclidean point */
    double rat[2][6] = {{0, 0, 2, 2 * 1.0, 2 * 0.5, 2}, {1.0 + 1e-7, 0.5, 1, 0, 0, 1}};
    for (int c = 0; c < 3; c++)
        rat[1][3 + c] = rat[0][c]; /* close the second join exactly */
    double *rp[2] = {rat[0], rat[1]};
    const int32_t rn[2] = {2, 2};
    assert_int_equal(sw_sg_trim_snap_loop(2, rp, rn, 1e-6, "rational", NULL), SW_OK);
    assert_true(rat[0][5] == 2 && rat[1][2] == 1);
    assert_true(fabs(rat[0][3] / rat[0][5] - rat[1][0] / rat[1][2]) < 1e-15);
}

/* Loop 0 of a planar face: a quadratic arc from A to B whose middle control point lies `bulge`
 * off the chord AB, closed by a line back, every coordinate times `scale` (a part scaled down as a
 * unit conversion does it). A and B are not dyadic, so subdivision rounds. */
static const double ARC_A[2] = {0.1, 0.2}, ARC_B[2] = {0.7, 0.55};

static void arc_normal(double n[2])
{
    const double dx = ARC_B[0] - ARC_A[0], dy = ARC_B[1] - ARC_A[1], l = hypot(dx, dy);
    n[0] = -dy / l;
    n[1] = dx / l;
}

static sw_sg_scene *make_bulge_scene(double bulge, double scale)
{
    sw_sg_builder *b = sw_sg_builder_create();
    assert_non_null(b);
    const double lk[4] = {0, 0, 1, 1}, qk[6] = {0, 0, 0, 1, 1, 1};
    double n[2];
    arc_normal(n);
    const double mid[2] = {0.5 * (ARC_A[0] + ARC_B[0]) + bulge * n[0],
                           0.5 * (ARC_A[1] + ARC_B[1]) + bulge * n[1]};
    const double arc[9] = {ARC_A[0] * scale, ARC_A[1] * scale, 1, mid[0] * scale, mid[1] * scale, 1,
                           ARC_B[0] * scale, ARC_B[1] * scale, 1};
    const double back[6] = {ARC_B[0] * scale, ARC_B[1] * scale, 1,
                            ARC_A[0] * scale, ARC_A[1] * scale, 1};
    uint32_t first = add_curve(b, 2, 3, qk, arc);
    add_curve(b, 1, 2, lk, back);
    sw_sg_loop_rec outer = {first, 2, SW_SG_LOOP_OUTER, 0};
    uint32_t l0 = sw_sg_builder_add_loop(b, &outer);
    const double net[16] = {0, 0, 0, 1, scale, 0, 0, 1, 0, scale, 0, 1, scale, scale, 0, 1};
    const double fk[4] = {0, 0, scale, scale};
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 1;
    f.n_u = f.n_v = 2;
    f.knots_u = sw_sg_builder_push_doubles(b, fk, 4);
    f.knots_v = sw_sg_builder_push_doubles(b, fk, 4);
    f.cpw = sw_sg_builder_push_doubles(b, net, 16);
    f.first_loop = l0;
    f.n_loops = 1;
    f.flags = SW_SG_FACE_TRIMMED;
    f.uv_box[1] = f.uv_box[3] = scale;
    uint32_t fi = sw_sg_builder_add_face(b, &f);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, fi, NULL, NULL, NULL);
    sw_sg_scene *scene = NULL;
    assert_int_equal(sw_sg_builder_finish(b, &scene, NULL), SW_OK);
    return scene;
}

/* The scaled-IGES hang: a tolerance below the rounding of the loop's own coordinates
 * (1e-20 of a loop at 0.7, or 1e-26 of the same loop scaled by 1e-6) is met only where rounding
 * happens to cancel, so the walk splits rounding noise down to the depth cap. With the floor the
 * arc is flattened at 64 ulps of its largest coordinate in a few vertices and the fallback is
 * counted. Planted fault (the floor removed in flatten_curve, as the code first had it): 295
 * vertices instead of 17, and this fails. */
static void test_flatten_below_rounding(void **state)
{
    (void)state;
    const double scales[2] = {1.0, 1e-6}, bulge = 1e-12;
    double n[2];
    arc_normal(n);
    for (int k = 0; k < 2; k++) {
        const double scale = scales[k];
        sw_sg_scene *scene = make_bulge_scene(bulge, scale);
        sw_sg_polyline pl;
        sw_status st = {0};
        assert_int_equal(sw_sg_trim_flatten_loop(scene, 0, 1e-20 * scale, 1u << 16, &pl, &st),
                         SW_OK);
        /* the arc's sagitta bulge / 2 at tolerance 64 eps * 0.7: a handful of pieces */
        printf("scale %g: %u vertices, %u curves below the floor, %u pieces depth-capped\n", scale,
               pl.count, pl.below_floor, pl.depth_capped);
        assert_true(pl.count >= 3 && pl.count <= 65);
        assert_int_equal(pl.below_floor, 2); /* both curves were asked below their floor */
        assert_int_equal(pl.depth_capped, 0);
        /* every vertex between the chord and the arc's apex, within rounding */
        for (uint32_t i = 0; i < pl.count; i++) {
            const double d = (pl.uv[2 * i] / scale - ARC_A[0]) * n[0] +
                             (pl.uv[2 * i + 1] / scale - ARC_A[1]) * n[1];
            assert_true(d >= -1e-15 && d <= 0.5 * bulge + 1e-15);
        }
        sw_sg_polyline_free(&pl);
        /* a requested tolerance above the floor is kept: no fallback counted */
        assert_int_equal(sw_sg_trim_flatten_loop(scene, 0, 1e-13 * scale, 1u << 16, &pl, &st),
                         SW_OK);
        assert_int_equal(pl.below_floor + pl.depth_capped, 0);
        sw_sg_polyline_free(&pl);
        sw_sg_scene_free(scene);
    }
}

/* A loop the vertex budget cannot hold at such a tolerance (the circle: ~1e7 vertices even at the
 * floor) ends with SW_ERR_LIMIT as soon as the budget is spent. Planted fault (the code before
 * no floor, and the walk going on after the budget was spent): 2^40 pieces per arc, and
 * this test runs into its timeout. */
static void test_flatten_budget_stops(void **state)
{
    (void)state;
    sw_sg_scene *scene = make_scene();
    sw_sg_polyline pl;
    sw_status st = {0};
    assert_int_equal(sw_sg_trim_flatten_loop(scene, 1, 1e-20, 1u << 12, &pl, &st), SW_ERR_LIMIT);
    assert_null(pl.uv);
    assert_int_equal(pl.count, 0);
    sw_sg_scene_free(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flatten_circle),
        cmocka_unit_test(test_flatten_joins),
        cmocka_unit_test(test_classify),
        cmocka_unit_test(test_snap),
        cmocka_unit_test(test_flatten_below_rounding),
        cmocka_unit_test(test_flatten_budget_stops),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

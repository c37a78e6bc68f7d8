/* SPDX-License-Identifier: MIT */
/* Validation rejects bad NURBS data with SW_ERR_INVALID_GEOMETRY (and accepts sound data):
 * decreasing, NaN and infinite knots, NaN / infinite / zero / negative weights, non-finite
 * coordinates, wrong counts and degrees, excessive knot multiplicity, an empty domain, missing
 * arrays. The result id is asserted; the message must name the object (`what`). */
#include "geom_test_util.h"
#include "sw_sg_scene.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

/* A valid bicubic 5 x 4 surface that each case copies and breaks. */
typedef struct fixture {
    double ku[9], kv[8], cpw[5 * 4 * 4];
    sw_sg_surface s;
} fixture;

static void fixture_init(fixture *f)
{
    const double ku[9] = {0, 0, 0, 0, 0.5, 1, 1, 1, 1};
    const double kv[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    memcpy(f->ku, ku, sizeof ku);
    memcpy(f->kv, kv, sizeof kv);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 5; i++) {
            double *pw = f->cpw + (j * 5 + i) * 4;
            const double w = 1.0 + 0.1 * (i + j);
            pw[0] = w * i;
            pw[1] = w * j;
            pw[2] = w * 0.25 * (i * j % 3);
            pw[3] = w;
        }
    f->s = (sw_sg_surface){.deg_u = 3,
                           .deg_v = 3,
                           .n_u = 5,
                           .n_v = 4,
                           .knots_u = f->ku,
                           .knots_v = f->kv,
                           .cpw = f->cpw};
}

static void expect_invalid(const fixture *f, const char *case_name)
{
    sw_status st = {0};
    const sw_result r = sw_sg_surface_validate(&f->s, "face 12", &st);
    printf("  %-28s -> %s: %s\n", case_name, sw_result_str(r), st.message);
    assert_int_equal(r, SW_ERR_INVALID_GEOMETRY);
    assert_int_equal(st.result, SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "face 12"));
    /* A NULL status is allowed and gives the same id. */
    assert_int_equal(sw_sg_surface_validate(&f->s, "face 12", NULL), SW_ERR_INVALID_GEOMETRY);
}

static void test_validate_accepts_sound_surface(void **state)
{
    (void)state;
    fixture f;
    fixture_init(&f);
    sw_status st = {SW_ERR_INTERNAL, "stale"};
    assert_int_equal(sw_sg_surface_validate(&f.s, "face 12", &st), SW_OK);
    assert_int_equal(st.result, SW_OK);
    assert_int_equal(sw_sg_surface_validate(&f.s, NULL, NULL), SW_OK);
    /* Unclamped ends are allowed (random surfaces in test_geom_refine also have interior knots
     * of multiplicity degree + 1). */
    const double ku[9] = {-3, -2, -1, 0, 0.5, 1, 2, 3, 4};
    memcpy(f.ku, ku, sizeof ku);
    assert_int_equal(sw_sg_surface_validate(&f.s, "face 12", &st), SW_OK);
}

static void test_validate_rejects_bad_knots(void **state)
{
    (void)state;
    fixture f;
    fixture_init(&f);
    f.ku[4] = -0.1; /* 0 0 0 0 -0.1 1 ... */
    expect_invalid(&f, "decreasing u knots");
    fixture_init(&f);
    f.kv[7] = 0.5;
    expect_invalid(&f, "decreasing v knots");
    fixture_init(&f);
    f.ku[4] = NAN;
    expect_invalid(&f, "NaN knot");
    fixture_init(&f);
    f.kv[7] = INFINITY;
    expect_invalid(&f, "infinite knot");
    fixture_init(&f);
    const double kv_empty[8] = {0, 1, 2, 5, 5, 6, 7, 8}; /* [knot 3, knot 4] = [5, 5] */
    memcpy(f.kv, kv_empty, sizeof kv_empty);
    expect_invalid(&f, "empty v domain");
    fixture_init(&f);
    const double ku5[9] = {0, 0, 0, 0, 0, 1, 1, 1, 1}; /* multiplicity 5 > degree + 1 */
    memcpy(f.ku, ku5, sizeof ku5);
    expect_invalid(&f, "multiplicity > degree + 1");
    fixture_init(&f);
    f.s.knots_u = NULL;
    expect_invalid(&f, "no u knots");
}

static void test_validate_rejects_bad_weights_and_points(void **state)
{
    (void)state;
    fixture f;
    const struct {
        int index, coord;
        double value;
        const char *name;
    } cases[] = {
        {7, 3, NAN, "NaN weight"},
        {7, 3, INFINITY, "infinite weight"},
        {0, 3, 0.0, "zero weight"},
        {19, 3, -1.0, "negative weight"},
        {3, 3, -0.0, "negative zero weight"},
        {11, 1, NAN, "NaN coordinate"},
        {12, 2, -INFINITY, "infinite coordinate"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        fixture_init(&f);
        f.cpw[cases[k].index * 4 + cases[k].coord] = cases[k].value;
        expect_invalid(&f, cases[k].name);
    }
    fixture_init(&f);
    f.s.cpw = NULL;
    expect_invalid(&f, "no control points");
}

static void test_validate_rejects_bad_counts(void **state)
{
    (void)state;
    fixture f;
    fixture_init(&f);
    f.s.deg_u = 0;
    expect_invalid(&f, "degree 0");
    fixture_init(&f);
    f.s.deg_v = SW_SG_MAX_DEGREE + 1;
    expect_invalid(&f, "degree above the maximum");
    fixture_init(&f);
    f.s.deg_u = -2;
    expect_invalid(&f, "negative degree");
    fixture_init(&f);
    f.s.n_v = 3;
    f.s.deg_v = 3; /* n < degree + 1 */
    expect_invalid(&f, "too few control points");
    fixture_init(&f);
    f.s.n_u = -5;
    expect_invalid(&f, "negative count");
    fixture_init(&f);
    f.s.n_u = INT32_MAX; /* would overflow n + degree + 1 */
    expect_invalid(&f, "count near INT32_MAX");
    assert_int_equal(sw_sg_surface_validate(NULL, "face 12", NULL), SW_ERR_INVALID_GEOMETRY);
}

static void test_validate_curves(void **state)
{
    (void)state;
    double knots[7] = {0, 0, 0, 0.5, 1, 1, 1};
    double cpw[4 * 3] = {0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    sw_sg_curve c = {.degree = 2, .n = 4, .dim = 3, .knots = knots, .cpw = cpw};
    sw_status st = {0};
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve 3 of face 12", &st), SW_OK);

    knots[3] = -1.0;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve 3 of face 12", &st),
                     SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "trim curve 3 of face 12"));
    knots[3] = 0.5;
    cpw[5] = NAN;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve", &st), SW_ERR_INVALID_GEOMETRY);
    cpw[5] = -2.0;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve", &st), SW_ERR_INVALID_GEOMETRY);
    cpw[5] = 1.0;
    cpw[9] = INFINITY;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve", &st), SW_ERR_INVALID_GEOMETRY);
    cpw[9] = 1.0;
    c.n = 2;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve", &st), SW_ERR_INVALID_GEOMETRY);
    c.n = 4;
    c.dim = 1;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve", &st), SW_ERR_INVALID_GEOMETRY);
    c.dim = 3;
    assert_int_equal(sw_sg_curve_validate(&c, NULL, &st), SW_OK);
    printf("  curve cases: decreasing knot, NaN / negative / infinite weight, too few points, "
           "dim 1 rejected\n");
}

/* Finite values whose products overflow the evaluation's range (the rule of
 * sw_sg_geom.h). A weight of 1e-300 or a coordinate of 1e308 passed validation and then refined
 * forever; each is now refused with SW_ERR_INVALID_GEOMETRY, the object and the control point.
 * Planted fault (the range checks dropped from bad_point): every case here passes validation. */
static void test_validate_rejects_overflowing_values(void **state)
{
    (void)state;
    fixture f;
    const struct {
        int index, coord;
        double value; /* Euclidean for coordinates */
        const char *name, *where;
    } cases[] = {
        {7, 3, 1e-300, "weight 1e-300", "control point (2, 1)"},
        {7, 3, 1e300, "weight 1e300", "control point (2, 1)"},
        {11, 0, 1e308, "coordinate 1e308", "control point (1, 2)"},
        {12, 2, -2e30, "coordinate -2e30", "control point (2, 2)"},
        {19, 3, 1e-16, "weight ratio 1e16", "factor"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        fixture_init(&f);
        double *pw = f.cpw + cases[k].index * 4;
        if (cases[k].coord == 3) { /* keep the Euclidean point */
            for (int c = 0; c < 3; c++)
                pw[c] *= cases[k].value / pw[3];
            pw[3] = cases[k].value;
        } else {
            pw[cases[k].coord] = cases[k].value * pw[3];
        }
        expect_invalid(&f, cases[k].name);
        sw_status st = {0};
        sw_sg_surface_validate(&f.s, "face 12", &st);
        assert_non_null(strstr(st.message, cases[k].where));
    }
    /* just inside the limits passes: weights 1e14 x apart, near 1e-100, coordinates of 9e29 */
    fixture_init(&f);
    for (int i = 0; i < 20; i++) {
        double *pw = f.cpw + i * 4;
        const double w = i % 2 ? 1e-100 : 1e-86;
        for (int c = 0; c < 3; c++)
            pw[c] = pw[c] / pw[3] * w;
        pw[3] = w;
    }
    f.cpw[5 * 4] = 9e29 * f.cpw[5 * 4 + 3];
    f.ku[0] = -1e30;
    assert_int_equal(sw_sg_surface_validate(&f.s, "face 12", NULL), SW_OK);
    f.ku[0] = -1.5e30;
    expect_invalid(&f, "knot -1.5e30");
    /* trim curves: the same rule */
    double knots[4] = {0, 0, 1, 1}, cpw[6] = {0, 0, 1, 1e-301, 1e-301, 1e-301};
    sw_sg_curve c = {.degree = 1, .n = 2, .dim = 3, .knots = knots, .cpw = cpw};
    sw_status st = {0};
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve 3", &st), SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "control point 1"));
    cpw[3] = cpw[4] = 1e35;
    cpw[5] = 1.0;
    assert_int_equal(sw_sg_curve_validate(&c, "trim curve 3", &st), SW_ERR_INVALID_GEOMETRY);
    /* a node transform of 1e308: the scene is refused at its validation, naming the node */
    sw_sg_builder *b = sw_sg_builder_create();
    assert_non_null(b);
    const double xf[12] = {1e308, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    sw_sg_builder_add_node(b, SW_SG_NODE_TRANSFORM, 0, 0, xf, NULL, NULL);
    sw_sg_scene *scene = NULL;
    assert_int_equal(sw_sg_builder_finish(b, &scene, &st), SW_ERR_INVALID_GEOMETRY);
    printf("  %-28s -> %s\n", "node transform 1e308", st.message);
    assert_non_null(strstr(st.message, "node 1"));
    assert_null(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_validate_accepts_sound_surface),
        cmocka_unit_test(test_validate_rejects_bad_knots),
        cmocka_unit_test(test_validate_rejects_bad_weights_and_points),
        cmocka_unit_test(test_validate_rejects_bad_counts),
        cmocka_unit_test(test_validate_curves),
        cmocka_unit_test(test_validate_rejects_overflowing_values),
    };
    return cmocka_run_group_tests_name("geom_validate", tests, NULL, NULL);
}

/* SPDX-License-Identifier: MIT */
/* The certified one-sided Hausdorff distance between triangle meshes (sw_lod_mesh_distance_bound,
 * modules/lodbuild/sw_lod_mesh_distance.h), which declares the static levels' ε_k, against
 * references that do not use it:
 *  - analytic: a triangle above a plane (the maximum at a corner), a triangle reaching from one
 *    small triangle to another 10 away (the maximum halfway), a flat triangle whose corners
 *    lie on a finely triangulated paraboloid (the maximum inside, where no corner or midpoint of
 *    the first splits falls), a mesh against itself (zero);
 *  - dense: a 60 x 60 barycentric lattice of every triangle, each point's exact distance to the
 *    mesh; the bound must lie above it and within the 5 % it certifies to (plus the lattice's
 *    spacing).
 *  - coplanar: a coarse square over a fine grid of it, with and without a hole in the grid.
 * What it catches: a bound that takes one corner's candidate for a piece whose other corners are
 * nearer other triangles (the paraboloid's value would fall below the lattice's), a piece left
 * out of the acceptance (an upper below the analytic maximum), a wrong Lipschitz fallback, a
 * lower above the truth.
 */
#include "sw_lod_mesh_distance.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

enum { GRID = 48 }; /* the paraboloid's grid: 2 x 48^2 triangles */

typedef struct mesh {
    double *pos;
    uint32_t *tri;
    uint32_t n_v, n_t;
} mesh;

static double paraboloid(double x, double y)
{
    return 0.5 * (x * x + y * y);
}

/* z = f(x, y) over [-1, 1]^2 (f = NULL: the plane z = 0), GRID x GRID squares split on a diagonal
 */
static mesh height_field(double (*f)(double, double))
{
    mesh m;
    m.n_v = (GRID + 1) * (GRID + 1);
    m.n_t = 2 * GRID * GRID;
    m.pos = malloc(3 * sizeof *m.pos * m.n_v);
    m.tri = malloc(3 * sizeof *m.tri * m.n_t);
    assert_non_null(m.pos);
    assert_non_null(m.tri);
    for (uint32_t j = 0; j <= GRID; ++j)
        for (uint32_t i = 0; i <= GRID; ++i) {
            double *p = m.pos + 3 * (j * (GRID + 1) + i);
            p[0] = -1.0 + 2.0 * i / GRID;
            p[1] = -1.0 + 2.0 * j / GRID;
            p[2] = f ? f(p[0], p[1]) : 0.0;
        }
    uint32_t *t = m.tri;
    for (uint32_t j = 0; j < GRID; ++j)
        for (uint32_t i = 0; i < GRID; ++i) {
            const uint32_t a = j * (GRID + 1) + i, b = a + 1, c = a + GRID + 1, d = c + 1;
            *t++ = a, *t++ = b, *t++ = d;
            *t++ = a, *t++ = d, *t++ = c;
        }
    return m;
}

static void mesh_free(mesh *m)
{
    free(m->pos);
    free(m->tri);
}

static sw_lod_mesh_distance *tree_of(const mesh *m)
{
    sw_lod_mesh_distance *d = NULL;
    sw_status st = {0};
    assert_int_equal(sw_lod_mesh_distance_create(m->pos, m->tri, m->n_t, &d, &st), SW_OK);
    return d;
}

/* The largest exact distance over a barycentric lattice of every triangle of a. */
static double lattice_max(const sw_lod_mesh_distance *d, const mesh *a, int n)
{
    double worst = 0.0;
    for (uint32_t t = 0; t < a->n_t; ++t) {
        const double *p0 = a->pos + 3 * a->tri[3 * t], *p1 = a->pos + 3 * a->tri[3 * t + 1],
                     *p2 = a->pos + 3 * a->tri[3 * t + 2];
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                const double u = (double)i / n, v = (double)j / n, w = 1.0 - u - v;
                double x[3];
                for (int k = 0; k < 3; ++k)
                    x[k] = w * p0[k] + u * p1[k] + v * p2[k];
                worst = fmax(worst, sw_lod_mesh_distance_query(d, x));
            }
    }
    return worst;
}

static sw_lod_mesh_bound bound_of(const sw_lod_mesh_distance *d, const mesh *a, double rel,
                                  double floor, int32_t depth)
{
    sw_lod_mesh_bound b;
    sw_status st = {0};
    assert_int_equal(
        sw_lod_mesh_distance_bound(d, a->pos, a->tri, a->n_t, rel, floor, depth, &b, &st), SW_OK);
    print_message("  lower %.9f upper %.9f, %llu pieces, %llu capped\n", b.lower, b.upper,
                  (unsigned long long)b.pieces, (unsigned long long)b.capped);
    return b;
}

/* The one-triangle mesh pos[0..8] against d: the bound above the dense lattice's maximum and
 * within the 5 % it certifies to; *dense gets that maximum. */
static sw_lod_mesh_bound triangle_against(const sw_lod_mesh_distance *d, double pos[9],
                                          double *dense)
{
    uint32_t tri[3] = {0, 1, 2};
    mesh a = {pos, tri, 3, 1};
    *dense = lattice_max(d, &a, 60);
    const sw_lod_mesh_bound b = bound_of(d, &a, 0.05, 1e-9, 12);
    print_message("  lattice %.9f\n", *dense);
    assert_true(b.lower <= *dense * (1.0 + 1e-9) + 1e-12);
    assert_true(b.upper >= *dense && b.upper <= 1.06 * *dense);
    return b;
}

/* A tilted triangle over the plane z = 0: the distance is its height, largest at a corner. */
static void test_triangle_over_plane(void **state)
{
    (void)state;
    mesh plane = height_field(NULL);
    double pos[9] = {-0.5, -0.5, 0.1, 0.6, -0.4, 0.3, 0.0, 0.7, 0.2};
    uint32_t tri[3] = {0, 1, 2};
    mesh a = {pos, tri, 3, 1};
    sw_lod_mesh_distance *d = tree_of(&plane);
    const sw_lod_mesh_bound b = bound_of(d, &a, 0.05, 1e-9, 12);
    assert_true(fabs(b.lower - 0.3) < 1e-12);
    assert_true(b.upper >= 0.3 && b.upper <= 0.3 * 1.05 + 1e-9);
    assert_int_equal(b.capped, 0);
    sw_lod_mesh_distance_free(d);
    mesh_free(&plane);
}

/* Two small triangles 10 apart, and a triangle with two corners on the first and one on the
 * second: its points halfway are 5 from both, its corners 0 from one of them. Its first two
 * corners' nearest triangle is not near the third: a certificate that skipped a corner would
 * accept the whole triangle with a bound of 0. */
static void test_far_corner(void **state)
{
    (void)state;
    double bpos[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 10, 0, 0, 11, 0, 0, 10, 1, 0};
    uint32_t btri[6] = {0, 1, 2, 3, 4, 5};
    mesh pair = {bpos, btri, 6, 2};
    double pos[9] = {0.2, 0.2, 0, 0.5, 0.2, 0, 10.2, 0.3, 0};
    sw_lod_mesh_distance *d = tree_of(&pair);
    double dense;
    triangle_against(d, pos, &dense);
    assert_true(dense > 4.5);
    sw_lod_mesh_distance_free(d);
}

/* A flat triangle with its corners on the paraboloid: inside it the paraboloid lies below, and the
 * distance peaks in the interior (about its incentre's height above the surface). */
static void test_interior_maximum(void **state)
{
    (void)state;
    mesh bowl = height_field(paraboloid);
    double pos[9] = {-0.75, -0.75, 0, 0.75, -0.5, 0, -0.25, 0.75, 0};
    for (int k = 0; k < 3; ++k)
        pos[3 * k + 2] = paraboloid(pos[3 * k], pos[3 * k + 1]);
    sw_lod_mesh_distance *d = tree_of(&bowl);
    double dense;
    triangle_against(d, pos, &dense);
    assert_true(dense > 0.1); /* the peak is inside, far above the corners' 0 */
    /* the same with a cap of one split: the fallback still bounds, and is counted */
    uint32_t tri[3] = {0, 1, 2};
    mesh a = {pos, tri, 3, 1};
    const sw_lod_mesh_bound c = bound_of(d, &a, 0.0, 1e-9, 1);
    assert_true(c.upper >= dense);
    assert_true(c.capped > 0);
    sw_lod_mesh_distance_free(d);
    mesh_free(&bowl);
}

/* Both directions between the paraboloid's fine mesh and a coarse one of its own vertices (as a
 * decimated level is): bounds above the lattice, within 5 % of it plus the lattice's spacing. */
static void test_coarse_against_fine(void **state)
{
    (void)state;
    mesh fine = height_field(paraboloid);
    /* every 8th grid line: a 6 x 6 grid of the same surface points */
    enum { C = GRID / 8 };
    double pos[3 * (C + 1) * (C + 1)];
    uint32_t tri[6 * C * C], *t = tri;
    for (uint32_t j = 0; j <= C; ++j)
        for (uint32_t i = 0; i <= C; ++i) {
            const double *src = fine.pos + 3 * (8 * j * (GRID + 1) + 8 * i);
            for (int k = 0; k < 3; ++k)
                pos[3 * (j * (C + 1) + i) + k] = src[k];
        }
    for (uint32_t j = 0; j < C; ++j)
        for (uint32_t i = 0; i < C; ++i) {
            const uint32_t a = j * (C + 1) + i, b = a + 1, c = a + C + 1, d = c + 1;
            *t++ = a, *t++ = b, *t++ = d;
            *t++ = a, *t++ = d, *t++ = c;
        }
    mesh coarse = {pos, tri, (C + 1) * (C + 1), 2 * C * C};
    sw_lod_mesh_distance *df = tree_of(&fine), *dc = tree_of(&coarse);
    const double to_fine = lattice_max(df, &coarse, 40), to_coarse = lattice_max(dc, &fine, 6);
    print_message("  lattice coarse->fine %.9f, fine->coarse %.9f\n", to_fine, to_coarse);
    const sw_lod_mesh_bound a = bound_of(df, &coarse, 0.05, 1e-9, 12);
    const sw_lod_mesh_bound b = bound_of(dc, &fine, 0.05, 1e-9, 12);
    assert_true(a.upper >= to_fine && a.upper <= 1.06 * to_fine);
    assert_true(b.upper >= to_coarse && b.upper <= 1.06 * to_coarse + 1e-3);
    /* a mesh against itself: certified down to the floor (a corner's nearest triangle is one of
     * those around it, so pieces near the mesh's edges are split until they fit the floor) */
    const sw_lod_mesh_bound s = bound_of(df, &fine, 0.05, 1e-4, 12);
    assert_true(s.lower < 1e-12 && s.upper <= 1e-4);
    sw_lod_mesh_distance_free(df);
    sw_lod_mesh_distance_free(dc);
    mesh_free(&fine);
}

/* The plane z = 0's grid with the squares of [-h, h]^2 taken out (h a multiple of the grid's
 * step): a window in a wall. */
static mesh plane_with_hole(double h)
{
    mesh m = height_field(NULL);
    uint32_t kept = 0;
    for (uint32_t t = 0; t < m.n_t; ++t) {
        double c[2] = {0.0, 0.0};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 2; ++a)
                c[a] += m.pos[3 * m.tri[3 * t + k] + a] / 3.0;
        if (fabs(c[0]) < h && fabs(c[1]) < h)
            continue;
        for (int k = 0; k < 3; ++k)
            m.tri[3 * kept + k] = m.tri[3 * t + k];
        kept++;
    }
    m.n_t = kept;
    return m;
}

/* Coplanar meshes (a wall and its decimated level): a coarse square over the fine grid of the
 * same square is within rounding of it everywhere, certified without splitting it (the planar
 * certificate: over the union of the fine triangles the distance is the heights'); a coarse
 * square over a fine grid with a hole is as far from it as the hole's centre from its rim, which
 * the bound must not miss. Certifying a piece inside the plane's union without checking the
 * union's boundary (the hole's rim) gives 0 there; fails. */
static void test_coplanar(void **state)
{
    (void)state;
    double pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}; /* the square, two triangles */
    uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    mesh square = {pos, tri, 4, 2};
    mesh fine = height_field(NULL);
    sw_lod_mesh_distance *df = tree_of(&fine);
    const sw_lod_mesh_bound flat = bound_of(df, &square, 0.05, 1e-9, 12);
    assert_true(flat.upper <= 1e-9);
    assert_int_equal(flat.pieces, 2);
    sw_lod_mesh_distance_free(df);
    mesh_free(&fine);
    /* the hole [-0.25, 0.25]^2 (the grid's step is 1/24): its centre is 0.25 from the rim */
    mesh holed = plane_with_hole(0.25);
    sw_lod_mesh_distance *dh = tree_of(&holed);
    const double dense = lattice_max(dh, &square, 60);
    const sw_lod_mesh_bound b = bound_of(dh, &square, 0.05, 1e-9, 12);
    print_message("  holed: lattice %.9f\n", dense);
    assert_true(dense >= 0.2499 && dense <= 0.25 + 1e-12);
    assert_true(b.upper >= 0.25 - 1e-12 && b.upper <= 1.06 * 0.25);
    /* the fine wall against the square: inside it everywhere (the rim's pieces too) */
    sw_lod_mesh_distance *ds = tree_of(&square);
    const sw_lod_mesh_bound back = bound_of(ds, &holed, 0.05, 1e-9, 12);
    assert_true(back.upper <= 1e-9);
    assert_int_equal(back.pieces, holed.n_t);
    sw_lod_mesh_distance_free(ds);
    sw_lod_mesh_distance_free(dh);
    mesh_free(&holed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_over_plane),
        cmocka_unit_test(test_far_corner),
        cmocka_unit_test(test_interior_maximum),
        cmocka_unit_test(test_coarse_against_fine),
        cmocka_unit_test(test_coplanar),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

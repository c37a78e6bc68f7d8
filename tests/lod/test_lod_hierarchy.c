/* SPDX-License-Identifier: MIT */
/* The per-surface bicubic hierarchy (lod/hierarchy/sw_lod_hierarchy.h, Guthe et al. 2005 §6):
 *  - structure: children split their parent's rectangle exactly, leaves tile the domain (or the
 *    requested uv box), leaves meet the tolerance, errors never decrease towards the root;
 *  - every representable node's error bounds the distance between the exact NURBS surface
 *    (sw_sg_surface_eval, the scenegraph kernel) and the node's bicubic over its rectangle,
 *    measured densely with a local search — for nodes spanning several Bézier patches too;
 *  - the derivative constants give the same segment counts as sw_lod_filip_segments and the
 *    trim-texture resolution of §5.3;
 *  - a crease (C0 knot) is never bridged by one bicubic.
 */
#include "sw_lod_hierarchy.h"
#include "sw_lod_sampling.h"

#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

static uint64_t rng = 0x9E3779B97F4A7C15ull;

static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1.0p-53;
}

/* A 10 x 10 rational surface of degree (p, q) with uniform clamped knots; knots holds 2 * 20. */
static sw_sg_surface random_surface(int32_t p, int32_t q, double *knots, double *cpw)
{
    const int32_t n = 10;
    for (int dir = 0; dir < 2; ++dir) {
        const int32_t d = dir ? q : p;
        double *k = knots + 20 * dir;
        for (int32_t i = 0; i < n + d + 1; ++i)
            k[i] = i <= d ? 0.0 : i >= n ? 1.0 : (double)(i - d) / (n - d);
    }
    for (int32_t j = 0; j < n; ++j)
        for (int32_t i = 0; i < n; ++i) {
            double *c = cpw + (j * n + i) * 4, w = 0.5 + 1.5 * rnd();
            c[0] = w * (10.0 * i + rnd());
            c[1] = w * (10.0 * j + rnd());
            c[2] = w * (8.0 * sin(0.7 * i) * cos(0.5 * j) + rnd());
            c[3] = w;
        }
    return (sw_sg_surface){p, q, n, n, knots, knots + 20, cpw};
}

typedef struct probe {
    const sw_sg_surface *s;
    const sw_lod_hnode *n;
} probe;

static double probe_dist(const probe *pr, double x, double y)
{
    const double *r = pr->n->rect;
    double a[3], b[3];
    sw_sg_surface_eval(pr->s, r[0] + x * (r[1] - r[0]), r[2] + y * (r[3] - r[2]), a);
    sw_sg_bezier_patch bp = {3, 3, 0, 0, 0.0, 1.0, 0.0, 1.0, (double *)pr->n->cpw};
    sw_sg_bezier_patch_eval(&bp, x, y, b);
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Dense grid, then a pattern search around the worst sample. */
static double measure(const probe *pr)
{
    const int g = 16;
    double bx = 0, by = 0, best = -1;
    for (int j = 0; j <= g; ++j)
        for (int i = 0; i <= g; ++i) {
            double d = probe_dist(pr, (double)i / g, (double)j / g);
            if (d > best)
                best = d, bx = (double)i / g, by = (double)j / g;
        }
    for (double h = 0.5 / g; h > 1e-8;) {
        double nb = best, nx = bx, ny = by;
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
                double x = fmin(1, fmax(0, bx + di * h)), y = fmin(1, fmax(0, by + dj * h));
                double d = probe_dist(pr, x, y);
                if (d > nb)
                    nb = d, nx = x, ny = y;
            }
        if (nb > best)
            best = nb, bx = nx, by = ny;
        else
            h *= 0.5;
    }
    return best;
}

typedef struct summary {
    int nodes_checked, violations, not_representable;
    double worst_ratio, min_ratio_root;
} summary;

/* Structure checks over the whole tree; bound checks on every `stride`-th representable node. */
static void check_hierarchy(const sw_sg_surface *s, const sw_lod_hierarchy *h, const double dom[4],
                            int stride, summary *sm)
{
    assert_true(h->n_nodes >= 1);
    const sw_lod_hnode *root = &h->nodes[h->root];
    assert_int_equal(root->parent, -1);
    for (int k = 0; k < 4; ++k)
        assert_true(fabs(root->rect[k] - dom[k]) < 1e-12);
    double leaf_area = 0.0;
    for (int32_t i = 0; i < h->n_nodes; ++i) {
        const sw_lod_hnode *n = &h->nodes[i];
        if (n->child[0] < 0) {
            assert_int_equal(n->child[1], -1);
            assert_true(n->flags & SW_LOD_HNODE_REPRESENTABLE);
            assert_true(n->error <= h->leaf_tolerance || h->leaves_over_tolerance > 0);
            leaf_area += (n->rect[1] - n->rect[0]) * (n->rect[3] - n->rect[2]);
        } else {
            const sw_lod_hnode *a = &h->nodes[n->child[0]], *b = &h->nodes[n->child[1]];
            const int k = 2 * n->split_dir, o = 2 - k;
            assert_true(a->parent == i && b->parent == i);
            assert_true(a->rect[k] == n->rect[k] && a->rect[k + 1] == b->rect[k] &&
                        b->rect[k + 1] == n->rect[k + 1]);
            assert_true(a->rect[o] == n->rect[o] && b->rect[o + 1] == n->rect[o + 1]);
            assert_true(n->error >= a->error && n->error >= b->error);
        }
        if (!sw_lod_hnode_cpw_ptr(n)) {
            ++sm->not_representable;
            assert_true(isinf(n->error));
            continue;
        }
        for (int k = 0; k < 16; ++k)
            assert_true(n->cpw[k * 4 + 3] > 0.0);
        if (i % stride && i != h->root)
            continue;
        probe pr = {s, n};
        const double m = measure(&pr), slack = 1e-12 * (fabs(n->box[3]) + fabs(n->box[4]) + 100);
        ++sm->nodes_checked;
        if (!(m <= n->error + slack)) {
            ++sm->violations;
            print_message("node %d: measured %.17g > bound %.17g\n", (int)i, m, n->error);
        }
        if (n->error > 0)
            sm->worst_ratio = fmax(sm->worst_ratio, m / n->error);
    }
    const double dom_area = (dom[1] - dom[0]) * (dom[3] - dom[2]);
    assert_true(fabs(leaf_area - dom_area) < 1e-12 * dom_area);
}

static void test_random_surfaces(void **state)
{
    (void)state;
    double knots[40], cpw[400];
    for (int32_t d = 3; d <= 7; d += 2) {
        sw_sg_surface s = random_surface(d, d, knots, cpw);
        sw_lod_hierarchy *h = NULL;
        sw_lod_hierarchy_desc desc = {0};
        desc.leaf_tolerance = 0.05;
        assert_int_equal(sw_lod_hierarchy_build(&s, &desc, &h, NULL), SW_OK);
        summary sm = {0, 0, 0, 0.0, 0.0};
        const double dom[4] = {0, 1, 0, 1};
        check_hierarchy(&s, h, dom, 3, &sm);
        print_message("degree %d: %d nodes, %d patches, %d leaves, root error %.4g, %d checked, %d "
                      "violations, %d not representable, best measured/bound %.3f\n",
                      (int)d, (int)h->n_nodes, (int)h->n_patches, (int)h->n_leaves,
                      h->nodes[h->root].error, sm.nodes_checked, sm.violations,
                      sm.not_representable, sm.worst_ratio);
        assert_int_equal(sm.violations, 0);
        assert_int_equal(h->leaves_over_tolerance, 0);
        /* derivative constants reproduce the Filip segment counts and the §5.3 texels */
        for (int32_t i = 0; i < h->n_nodes; i += 7) {
            const sw_lod_hnode *n = &h->nodes[i];
            if (!sw_lod_hnode_cpw_ptr(n))
                continue;
            sw_lod_patch_bounds pb;
            sw_lod_rational_bezier_bounds(3, 3, n->cpw, &pb);
            for (double eps = 1e-4; eps < 10; eps *= 7.3) {
                assert_int_equal(sw_lod_hnode_segments(n, 0, 1 / sqrt(eps), 1 << 20),
                                 sw_lod_filip_segments(pb.d2[0], pb.d2[1], 1.0, eps, 1 << 20));
                assert_int_equal(sw_lod_hnode_segments(n, 1, 1 / sqrt(eps), 1 << 20),
                                 sw_lod_filip_segments(pb.d2[2], pb.d2[1], 1.0, eps, 1 << 20));
                double tex = sw_lod_trim_texels(1.0, pb.d1[0], 1.0, eps);
                assert_true(fabs(sw_lod_hnode_texels(n, 0, 1 / eps, 1 << 30) - ceil(tex)) <= 1);
            }
        }
        sw_lod_hierarchy_free(h);
    }
}

static void test_uv_box(void **state)
{
    (void)state;
    double knots[40], cpw[400];
    sw_sg_surface s = random_surface(5, 4, knots, cpw);
    sw_lod_hierarchy_desc desc = {0};
    desc.leaf_tolerance = 0.05;
    desc.use_box = 1;
    const double box[4] = {0.23, 0.61, 0.4, 0.95};
    memcpy(desc.uv_box, box, sizeof box);
    sw_lod_hierarchy *h = NULL;
    assert_int_equal(sw_lod_hierarchy_build(&s, &desc, &h, NULL), SW_OK);
    summary sm = {0, 0, 0, 0.0, 0.0};
    check_hierarchy(&s, h, box, 2, &sm);
    print_message("uv box: %d patches (of 30), %d nodes checked, %d violations\n",
                  (int)h->n_patches, sm.nodes_checked, sm.violations);
    assert_true(h->n_patches < 30);
    assert_int_equal(sm.violations, 0);
    sw_lod_hierarchy_free(h);
}

static void test_crease_not_bridged(void **state)
{
    (void)state;
    /* degree 2 x 1, knot 0.5 of multiplicity 2 in u: a roof z = -|x - 1| */
    static const double ku[8] = {0, 0, 0, 0.5, 0.5, 1, 1, 1}, kv[4] = {0, 0, 1, 1};
    double cpw[5 * 2 * 4];
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 5; ++i) {
            double *c = cpw + (j * 5 + i) * 4, x = 0.5 * i;
            c[0] = x, c[1] = j, c[2] = -fabs(x - 1.0), c[3] = 1.0;
        }
    sw_sg_surface s = {2, 1, 5, 2, ku, kv, cpw};
    sw_lod_hierarchy *h = NULL;
    assert_int_equal(sw_lod_hierarchy_build(&s, NULL, &h, NULL), SW_OK);
    assert_int_equal(h->n_patches, 2);
    const sw_lod_hnode *root = &h->nodes[h->root];
    assert_null(sw_lod_hnode_cpw_ptr(root));
    assert_true(isinf(root->error));
    assert_non_null(sw_lod_hnode_cpw_ptr(&h->nodes[root->child[0]]));
    assert_non_null(sw_lod_hnode_cpw_ptr(&h->nodes[root->child[1]]));
    assert_true(h->nodes[root->child[0]].error < 1e-9);
    sw_lod_hierarchy_free(h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_surfaces),
        cmocka_unit_test(test_uv_box),
        cmocka_unit_test(test_crease_not_bridged),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

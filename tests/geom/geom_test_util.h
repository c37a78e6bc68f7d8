/* SPDX-License-Identifier: MIT */
/* Shared helpers of the geometry-kernel tests: a seeded generator and random rational B-spline
 * surfaces with clamped or unclamped knot vectors and repeated interior knots. */
#ifndef GEOM_TEST_UTIL_H
#define GEOM_TEST_UTIL_H

#include "sw_sg_geom.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct gt_rng {
    uint64_t s;
} gt_rng;

/* splitmix64: small, seedable, good enough for test inputs. */
static inline uint64_t gt_next(gt_rng *r)
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline double gt_uniform(gt_rng *r, double lo, double hi)
{
    return lo + (hi - lo) * (double)(gt_next(r) >> 11) * 0x1.0p-53;
}

static inline int gt_int(gt_rng *r, int lo, int hi) /* inclusive */
{
    return lo + (int)(gt_next(r) % (uint64_t)(hi - lo + 1));
}

/* The seed: SW_TEST_SEED from the environment, else a fixed default; printed by the tests. */
static inline uint64_t gt_seed(void)
{
    const char *e = getenv("SW_TEST_SEED");
    return e ? strtoull(e, NULL, 0) : 20261107ull;
}

static int gt_cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A random knot vector of n + p + 1 knots: clamped or not at each end, interior knots of random
 * multiplicity 1..p (sometimes p + 1), domain [a, a + len] with random a and len. */
static inline void gt_random_knots(gt_rng *r, int p, int n, double *knots)
{
    const double a = gt_uniform(r, -10.0, 10.0), len = gt_uniform(r, 0.1, 10.0);
    const int m = n + p + 1;
    int k = 0;
    const int clamp0 = gt_int(r, 0, 3) != 0, clamp1 = gt_int(r, 0, 3) != 0;
    for (int i = 0; i < p; i++)
        knots[k++] = clamp0 ? a : a - len * gt_uniform(r, 0.01, 1.0);
    knots[k++] = a;
    int left = n - p - 1; /* interior knots */
    while (left > 0) {
        const double t = a + len * gt_uniform(r, 0.02, 0.98);
        int mult = gt_int(r, 1, p);
        if (gt_int(r, 0, 9) == 0)
            mult = p + 1;
        if (mult > left)
            mult = left;
        for (int i = 0; i < mult; i++)
            knots[k++] = t;
        left -= mult;
    }
    knots[k++] = a + len;
    for (int i = 0; i < p; i++)
        knots[k++] = clamp1 ? a + len : a + len + len * gt_uniform(r, 0.01, 1.0);
    (void)m;
    qsort(knots, (size_t)k, sizeof(double), gt_cmp_double);
}

/* A random rational surface owning its arrays. */
typedef struct gt_surface {
    sw_sg_surface s;
    double *ku, *kv, *cpw;
} gt_surface;

static inline void gt_surface_make(gt_rng *r, int p, int q, int n_u, int n_v, gt_surface *g)
{
    g->ku = malloc(sizeof(double) * (size_t)(n_u + p + 1));
    g->kv = malloc(sizeof(double) * (size_t)(n_v + q + 1));
    g->cpw = malloc(sizeof(double) * 4 * (size_t)n_u * (size_t)n_v);
    if (!g->ku || !g->kv || !g->cpw)
        abort();
    gt_random_knots(r, p, n_u, g->ku);
    gt_random_knots(r, q, n_v, g->kv);
    const double scale = pow(10.0, gt_uniform(r, -2.0, 3.0));
    for (int i = 0; i < n_u * n_v; i++) {
        const double w = gt_uniform(r, 0.2, 5.0);
        for (int c = 0; c < 3; c++)
            g->cpw[i * 4 + c] = w * scale * gt_uniform(r, -1.0, 1.0);
        g->cpw[i * 4 + 3] = w;
    }
    g->s = (sw_sg_surface){.deg_u = p,
                           .deg_v = q,
                           .n_u = n_u,
                           .n_v = n_v,
                           .knots_u = g->ku,
                           .knots_v = g->kv,
                           .cpw = g->cpw};
}

static inline void gt_surface_free(gt_surface *g)
{
    free(g->ku);
    free(g->kv);
    free(g->cpw);
    memset(g, 0, sizeof *g);
}

static inline void gt_domain(const sw_sg_surface *s, double *u0, double *u1, double *v0, double *v1)
{
    sw_sg_knots_domain(s->knots_u, s->deg_u, s->n_u, u0, u1);
    sw_sg_knots_domain(s->knots_v, s->deg_v, s->n_v, v0, v1);
}

static inline double gt_dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

static inline double gt_norm3(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* Axis-aligned box of points, for the "relative to the bbox diagonal" tolerances. */
typedef struct gt_box {
    double lo[3], hi[3];
} gt_box;

static inline void gt_box_init(gt_box *b)
{
    for (int c = 0; c < 3; c++) {
        b->lo[c] = INFINITY;
        b->hi[c] = -INFINITY;
    }
}

static inline void gt_box_add(gt_box *b, const double p[3])
{
    for (int c = 0; c < 3; c++) {
        b->lo[c] = fmin(b->lo[c], p[c]);
        b->hi[c] = fmax(b->hi[c], p[c]);
    }
}

static inline double gt_box_diag(const gt_box *b)
{
    double d[3] = {b->hi[0] - b->lo[0], b->hi[1] - b->lo[1], b->hi[2] - b->lo[2]};
    return gt_norm3(d);
}

#endif

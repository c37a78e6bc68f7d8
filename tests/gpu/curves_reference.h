/* SPDX-License-Identifier: MIT */
/* tests/gpu: exact area coverage of a closed polyline per pixel, in double precision — the
 * reference of the outline tests (test_gpu_curves, test_gpu_curves_placed).
 *
 * For each pixel square S the area of the polygon inside S by Green's theorem over the outline
 * clamped to S: A = sum over edges of integral (clamp(x) - x0) d clamp(y), exact for straight edges
 * (the clamp is a retraction onto S homotopic to the identity outside S's interior, so winding
 * numbers inside S are kept). Callers flatten their curves finely enough (1e-3 px) first. */
#ifndef SW_TESTS_CURVES_REFERENCE_H
#define SW_TESTS_CURVES_REFERENCE_H

#include "sw_sg_geom.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A clamped 2D rational B-spline (homogeneous, dim 3; degree p, n <= 64 control points) as its
 * Bézier pieces by full knot insertion (sw_sg_curve_insert_knot): emit(ctx, piece, p) for each,
 * the piece's p + 1 homogeneous control points. */
static inline void ref_curve_pieces(int p, int n, const double *knots_in, const double *cpw_in,
                             void (*emit)(void *ctx, const double *h, int p), void *ctx)
{
    double knots[256], cpw[3 * 256], k2[256], c2[3 * 256];
    memcpy(knots, knots_in, sizeof(double) * (n + p + 1));
    memcpy(cpw, cpw_in, sizeof(double) * 3 * n);
    for (int i = p + 1; i < n;) {
        double t = knots[i];
        int mult = 0;
        while (i + mult < n && knots[i + mult] == t)
            mult++;
        if (mult < p) {
            sw_sg_curve g = {p, n, 3, knots, cpw};
            sw_sg_curve_insert_knot(&g, t, p - mult, k2, c2);
            n += p - mult;
            memcpy(knots, k2, sizeof(double) * (n + p + 1));
            memcpy(cpw, c2, sizeof(double) * 3 * n);
        }
        i += p;
        while (i < n && knots[i] == t)
            i++;
    }
    for (int k = 0; k + p < n; k += p)
        emit(ctx, cpw + 3 * k, p);
}

typedef struct ref_poly {
    double (*p)[2];
    size_t n, cap;
} ref_poly;

static inline void ref_poly_add(ref_poly *pl, const double q[2])
{
    if (pl->n == pl->cap) {
        pl->cap = pl->cap ? 2 * pl->cap : 1024;
        pl->p = realloc(pl->p, pl->cap * sizeof *pl->p);
        if (!pl->p)
            abort();
    }
    pl->p[pl->n][0] = q[0];
    pl->p[pl->n][1] = q[1];
    pl->n++;
}

/* integral of (clamp(x, i, i+1) - i) dy along a->b (y already within one row) */
static inline double ref_seg_cell(const double a[2], const double b[2], double i)
{
    double ts[4] = {0, 1, 0, 0};
    int nt = 2;
    double dx = b[0] - a[0];
    if (dx != 0) {
        for (int k = 0; k < 2; ++k) {
            double t = (i + k - a[0]) / dx;
            if (t > 0 && t < 1)
                ts[nt++] = t;
        }
    }
    for (int x = 1; x < nt; ++x) /* sort */
        for (int y = x; y > 0 && ts[y] < ts[y - 1]; --y) {
            double t = ts[y];
            ts[y] = ts[y - 1];
            ts[y - 1] = t;
        }
    double sum = 0;
    for (int k = 0; k + 1 < nt; ++k) {
        double p0[2] = {a[0] + ts[k] * dx, a[1] + ts[k] * (b[1] - a[1])};
        double p1[2] = {a[0] + ts[k + 1] * dx, a[1] + ts[k + 1] * (b[1] - a[1])};
        double g0 = fmin(fmax(p0[0], i), i + 1) - i, g1 = fmin(fmax(p1[0], i), i + 1) - i;
        sum += 0.5 * (g0 + g1) * (p1[1] - p0[1]);
    }
    return sum;
}

/* Adds the winding-weighted area of the closed polyline in each pixel of a w x h image, times
 * `sign`, to cov (row-major, y up). */
static inline void ref_area_accumulate(const ref_poly *pl, double sign, int w, int h, double *cov)
{
    double *row_cover = calloc((size_t)h * (size_t)(w + 1), sizeof *row_cover);
    if (!row_cover)
        abort();
    for (size_t k = 0; k < pl->n; ++k) {
        const double *a = pl->p[k], *b = pl->p[(k + 1) % pl->n];
        double ylo = fmin(a[1], b[1]), yhi = fmax(a[1], b[1]);
        if (yhi <= 0 || ylo >= h || a[1] == b[1])
            continue;
        int j0 = (int)floor(fmax(ylo, 0)), j1 = (int)floor(fmin(yhi, h - 1e-9));
        for (int j = j0; j <= j1 && j < h; ++j) {
            /* the part of a->b with y in [j, j+1] */
            double t0 = (j - a[1]) / (b[1] - a[1]), t1 = (j + 1 - a[1]) / (b[1] - a[1]);
            if (t0 > t1) {
                double t = t0;
                t0 = t1;
                t1 = t;
            }
            t0 = fmax(t0, 0);
            t1 = fmin(t1, 1);
            if (t1 <= t0)
                continue;
            double p[2] = {a[0] + t0 * (b[0] - a[0]), a[1] + t0 * (b[1] - a[1])};
            double q[2] = {a[0] + t1 * (b[0] - a[0]), a[1] + t1 * (b[1] - a[1])};
            double dy = q[1] - p[1];
            double xlo = fmin(p[0], q[0]), xhi = fmax(p[0], q[0]);
            int i0 = (int)floor(xlo), i1 = (int)floor(xhi);
            /* pixels entirely left of the part: clamp(x) - i = 1 */
            int full = i0 < 0 ? 0 : i0 > w ? w : i0;
            row_cover[(size_t)j * (w + 1)] += sign * dy;
            row_cover[(size_t)j * (w + 1) + full] -= sign * dy;
            for (int i = i0 < 0 ? 0 : i0; i <= i1 && i < w; ++i)
                cov[j * w + i] += sign * ref_seg_cell(p, q, i);
        }
    }
    for (int j = 0; j < h; ++j) {
        double acc = 0;
        for (int i = 0; i < w; ++i) {
            acc += row_cover[(size_t)j * (w + 1) + i];
            cov[j * w + i] += acc;
        }
    }
    free(row_cover);
}

/* The homogeneous Bézier piece h (degree p <= 31, 3 numbers a point) halved at t = 1/2 (de
 * Casteljau): l and r take p + 1 points each. */
static inline void ref_split_half(const double *h, int p, double *l, double *r)
{
    double t[3 * 32];
    memcpy(t, h, sizeof(double) * 3 * (size_t)(p + 1));
    for (int c = 0; c < 3; ++c) {
        l[c] = t[c];
        r[3 * p + c] = t[3 * p + c];
    }
    for (int lev = 1; lev <= p; ++lev) {
        for (int i = 0; i <= p - lev; ++i)
            for (int c = 0; c < 3; ++c)
                t[3 * i + c] = 0.5 * (t[3 * i + c] + t[3 * (i + 1) + c]);
        for (int c = 0; c < 3; ++c) {
            l[3 * lev + c] = t[c];
            r[3 * (p - lev) + c] = t[3 * (p - lev) + c];
        }
    }
}

/* h: a homogeneous Bézier piece (degree p <= 31) already in pixel space, halved until its control
 * points lie within 1e-3 px of its chord (the convex hull property then puts the curve that close
 * to the chord): appends the end point of each chord. */
static inline void ref_flatten_bezier(const double *h, int p, ref_poly *pl, int depth)
{
    double a[2] = {h[0] / h[2], h[1] / h[2]},
           e[2] = {h[3 * p] / h[3 * p + 2], h[3 * p + 1] / h[3 * p + 2]};
    double d[2] = {e[0] - a[0], e[1] - a[1]}, len2 = d[0] * d[0] + d[1] * d[1], worst = 0;
    for (int i = 1; i < p; ++i) {
        double q[2] = {h[3 * i] / h[3 * i + 2] - a[0], h[3 * i + 1] / h[3 * i + 2] - a[1]};
        double s = len2 > 0 ? (q[0] * d[0] + q[1] * d[1]) / len2 : 0;
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        worst = fmax(worst, hypot(q[0] - s * d[0], q[1] - s * d[1]));
    }
    if (worst > 1e-3 && depth < 60) {
        double l[3 * 32], r[3 * 32];
        ref_split_half(h, p, l, r);
        ref_flatten_bezier(l, p, pl, depth + 1);
        ref_flatten_bezier(r, p, pl, depth + 1);
        return;
    }
    ref_poly_add(pl, e);
}

#endif

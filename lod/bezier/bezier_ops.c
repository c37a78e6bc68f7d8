/* SPDX-License-Identifier: MIT */
/* Rational Bézier nets in homogeneous form: de Casteljau evaluation, subdivision and restriction
 * to a sub-rectangle, exact degree elevation, products of Bernstein polynomials (Farin, Curves and
 * Surfaces for CAGD, ch. 5-6; used by Guthe et al. 2005 §6.1-§6.2 and by error_bound.c).
 *
 * Every operation works line by line along one direction: a "line" is the deg+1 coefficients that
 * differ only in the index of that direction, `stride` doubles apart.
 */
#include "sw_lod_bezier.h"

#include <assert.h>
#include <string.h>

static void check_net(int32_t deg_u, int32_t deg_v, int32_t dim)
{
    assert(deg_u >= 0 && deg_u <= SW_LOD_BEZ_MAX_DEGREE);
    assert(deg_v >= 0 && deg_v <= SW_LOD_BEZ_MAX_DEGREE);
    assert(dim >= 1 && dim <= SW_LOD_BEZ_MAX_DIM);
    (void)deg_u;
    (void)deg_v;
    (void)dim;
}

size_t sw_lod_bez_count(int32_t deg_u, int32_t deg_v, int32_t dim)
{
    return (size_t)(deg_u + 1) * (size_t)(deg_v + 1) * (size_t)dim;
}

void sw_lod_binomial_row(int32_t n, double *row)
{
    assert(n >= 0 && n <= 2 * SW_LOD_BEZ_MAX_DEGREE);
    row[0] = 1.0;
    for (int32_t k = 1; k <= n; ++k)
        row[k] = row[k - 1] * (double)(n - k + 1) / (double)k;
}

/* The lines of a net along `dir`: how many, where each starts, and the stride inside one. */
typedef struct lines {
    int32_t deg, count;
    size_t stride, line_step; /* doubles between consecutive coefficients / first coefficients */
} lines;

static lines lines_of(int32_t deg_u, int32_t deg_v, int32_t dim, int dir)
{
    lines l;
    if (dir == 0) {
        l.deg = deg_u;
        l.count = deg_v + 1;
        l.stride = (size_t)dim;
        l.line_step = (size_t)(deg_u + 1) * (size_t)dim;
    } else {
        l.deg = deg_v;
        l.count = deg_u + 1;
        l.stride = (size_t)(deg_u + 1) * (size_t)dim;
        l.line_step = (size_t)dim;
    }
    return l;
}

/* In place: the line becomes its part over [0, t] (the first point of every de Casteljau level). */
static void line_left(double *p, int32_t n, size_t stride, int32_t dim, double t)
{
    const double u = 1.0 - t;
    for (int32_t r = 1; r <= n; ++r)
        for (int32_t i = n; i >= r; --i)
            for (int32_t k = 0; k < dim; ++k)
                p[(size_t)i * stride + (size_t)k] = u * p[(size_t)(i - 1) * stride + (size_t)k] +
                                                    t * p[(size_t)i * stride + (size_t)k];
}

/* In place: the line becomes its part over [t, 1] (the last point of every level). */
static void line_right(double *p, int32_t n, size_t stride, int32_t dim, double t)
{
    const double u = 1.0 - t;
    for (int32_t r = 1; r <= n; ++r)
        for (int32_t i = 0; i <= n - r; ++i)
            for (int32_t k = 0; k < dim; ++k)
                p[(size_t)i * stride + (size_t)k] = u * p[(size_t)i * stride + (size_t)k] +
                                                    t * p[(size_t)(i + 1) * stride + (size_t)k];
}

/* In place: the line restricted to [a, b] of [0, 1], choosing the order of the two cuts so that
 * the second parameter is never computed by dividing by a tiny interval. */
static void line_restrict(double *p, int32_t n, size_t stride, int32_t dim, double a, double b)
{
    if (a <= 0.0 && b >= 1.0)
        return;
    if (b >= 1.0 - a) {
        if (b < 1.0)
            line_left(p, n, stride, dim, b);
        if (a > 0.0)
            line_right(p, n, stride, dim, a / b);
    } else {
        if (a > 0.0)
            line_right(p, n, stride, dim, a);
        if (b < 1.0)
            line_left(p, n, stride, dim, (b - a) / (1.0 - a));
    }
}

void sw_lod_bez_eval(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, double s,
                     double t, double *out)
{
    check_net(deg_u, deg_v, dim);
    double row[(SW_LOD_BEZ_MAX_DEGREE + 1) * SW_LOD_BEZ_MAX_DIM];
    double col[(SW_LOD_BEZ_MAX_DEGREE + 1) * SW_LOD_BEZ_MAX_DIM];
    const size_t nrow = (size_t)(deg_u + 1) * (size_t)dim;
    for (int32_t j = 0; j <= deg_v; ++j) {
        memcpy(row, cpw + (size_t)j * nrow, nrow * sizeof *row);
        line_right(row, deg_u, (size_t)dim, dim, s); /* row[0] = value at s */
        memcpy(col + (size_t)j * (size_t)dim, row, (size_t)dim * sizeof *row);
    }
    line_right(col, deg_v, (size_t)dim, dim, t);
    memcpy(out, col, (size_t)dim * sizeof *out);
}

void sw_lod_bez_eval_euclid(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, double s,
                            double t, double *out)
{
    double h[SW_LOD_BEZ_MAX_DIM];
    sw_lod_bez_eval(deg_u, deg_v, dim, cpw, s, t, h);
    for (int32_t k = 0; k + 1 < dim; ++k)
        out[k] = h[k] / h[dim - 1];
}

void sw_lod_bez_subdivide(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, int dir,
                          double s, double *left, double *right)
{
    check_net(deg_u, deg_v, dim);
    const size_t n = sw_lod_bez_count(deg_u, deg_v, dim);
    const lines l = lines_of(deg_u, deg_v, dim, dir);
    if (left) {
        memcpy(left, cpw, n * sizeof *left);
        for (int32_t k = 0; k < l.count; ++k)
            line_left(left + (size_t)k * l.line_step, l.deg, l.stride, dim, s);
    }
    if (right) {
        memcpy(right, cpw, n * sizeof *right);
        for (int32_t k = 0; k < l.count; ++k)
            line_right(right + (size_t)k * l.line_step, l.deg, l.stride, dim, s);
    }
}

void sw_lod_bez_restrict(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw,
                         const double rect[4], double *out)
{
    check_net(deg_u, deg_v, dim);
    assert(rect[0] <= rect[1] && rect[2] <= rect[3]);
    if (out != cpw)
        memcpy(out, cpw, sw_lod_bez_count(deg_u, deg_v, dim) * sizeof *out);
    for (int dir = 0; dir < 2; ++dir) {
        const lines l = lines_of(deg_u, deg_v, dim, dir);
        for (int32_t k = 0; k < l.count; ++k)
            line_restrict(out + (size_t)k * l.line_step, l.deg, l.stride, dim, rect[2 * dir],
                          rect[2 * dir + 1]);
    }
}

/* Elevates every line along `dir` from degree p to p + r: c_k = sum_i C(p,i) C(r,k-i) / C(p+r,k)
 * P_i. src and dst have their own layouts (degrees differ along dir). */
static void elevate_dir(int32_t dim, int32_t su, int32_t sv, const double *src, int dir, int32_t r,
                        double *dst)
{
    const int32_t du = dir == 0 ? su + r : su, dv = dir == 0 ? sv : sv + r;
    const lines ls = lines_of(su, sv, dim, dir), ld = lines_of(du, dv, dim, dir);
    const int32_t p = ls.deg;
    double bp[SW_LOD_BEZ_MAX_DEGREE + 1], br[SW_LOD_BEZ_MAX_DEGREE + 1];
    double bn[SW_LOD_BEZ_MAX_DEGREE + 1];
    sw_lod_binomial_row(p, bp);
    sw_lod_binomial_row(r, br);
    sw_lod_binomial_row(p + r, bn);
    for (int32_t line = 0; line < ls.count; ++line) {
        const double *s = src + (size_t)line * ls.line_step;
        double *d = dst + (size_t)line * ld.line_step;
        for (int32_t k = 0; k <= p + r; ++k) {
            double acc[SW_LOD_BEZ_MAX_DIM] = {0.0, 0.0, 0.0, 0.0};
            const int32_t lo = k - r > 0 ? k - r : 0, hi = k < p ? k : p;
            for (int32_t i = lo; i <= hi; ++i) {
                const double f = bp[i] * br[k - i] / bn[k];
                for (int32_t c = 0; c < dim; ++c)
                    acc[c] += f * s[(size_t)i * ls.stride + (size_t)c];
            }
            for (int32_t c = 0; c < dim; ++c)
                d[(size_t)k * ld.stride + (size_t)c] = acc[c];
        }
    }
}

/* In place along v: rows (contiguous, `row_len` doubles) 0..p become rows 0..p+r. Output row k
 * reads input rows max(0, k-r)..min(k, p) and input row i is read only by outputs i..i+r, so
 * writing the outputs from the last row down never overwrites a row still to be read. */
static void elevate_rows_in_place(double *net, size_t row_len, int32_t p, int32_t r)
{
    double bp[SW_LOD_BEZ_MAX_DEGREE + 1], br[SW_LOD_BEZ_MAX_DEGREE + 1];
    double bn[SW_LOD_BEZ_MAX_DEGREE + 1];
    double acc[(SW_LOD_BEZ_MAX_DEGREE + 1) * SW_LOD_BEZ_MAX_DIM];
    assert(row_len <= sizeof acc / sizeof acc[0]);
    sw_lod_binomial_row(p, bp);
    sw_lod_binomial_row(r, br);
    sw_lod_binomial_row(p + r, bn);
    for (int32_t k = p + r; k >= 0; --k) {
        memset(acc, 0, row_len * sizeof *acc);
        const int32_t lo = k - r > 0 ? k - r : 0, hi = k < p ? k : p;
        for (int32_t i = lo; i <= hi; ++i) {
            const double f = bp[i] * br[k - i] / bn[k];
            const double *src = net + (size_t)i * row_len;
            for (size_t c = 0; c < row_len; ++c)
                acc[c] += f * src[c];
        }
        memcpy(net + (size_t)k * row_len, acc, row_len * sizeof *acc);
    }
}

void sw_lod_bez_elevate(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, int32_t new_u,
                        int32_t new_v, double *out)
{
    check_net(deg_u, deg_v, dim);
    check_net(new_u, new_v, dim);
    assert(new_u >= deg_u && new_v >= deg_v);
    elevate_dir(dim, deg_u, deg_v, cpw, 0, new_u - deg_u, out);
    elevate_rows_in_place(out, (size_t)(new_u + 1) * (size_t)dim, deg_v, new_v - deg_v);
}

void sw_lod_bez_mul_add(int32_t dim, int32_t au, int32_t av, const double *a, int32_t bu,
                        int32_t bv, const double *b, double scale, double *out)
{
    check_net(au + bu, av + bv, dim);
    sw_lod_bez_product_weights w;
    sw_lod_bez_product_weights_init(&w, au, av, bu, bv);
    const size_t ou = (size_t)(au + bu + 1);
    for (int32_t j2 = 0; j2 <= bv; ++j2)
        for (int32_t i2 = 0; i2 <= bu; ++i2) {
            const double bc = b[(size_t)j2 * (size_t)(bu + 1) + (size_t)i2] * scale;
            if (bc == 0.0)
                continue;
            for (int32_t j1 = 0; j1 <= av; ++j1)
                for (int32_t i1 = 0; i1 <= au; ++i1) {
                    const double f = bc * sw_lod_bez_product_weight(&w, i1, j1, i2, j2);
                    const double *ac =
                        a + ((size_t)j1 * (size_t)(au + 1) + (size_t)i1) * (size_t)dim;
                    double *o = out + ((size_t)(j1 + j2) * ou + (size_t)(i1 + i2)) * (size_t)dim;
                    for (int32_t k = 0; k < dim; ++k)
                        o[k] += f * ac[k];
                }
        }
}

void sw_lod_bez_product_weights_init(sw_lod_bez_product_weights *w, int32_t au, int32_t av,
                                     int32_t bu, int32_t bv)
{
    sw_lod_binomial_row(au, w->au);
    sw_lod_binomial_row(av, w->av);
    sw_lod_binomial_row(bu, w->bu);
    sw_lod_binomial_row(bv, w->bv);
    sw_lod_binomial_row(au + bu, w->ou);
    sw_lod_binomial_row(av + bv, w->ov);
}

void sw_lod_bez_component(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw,
                          int32_t comp, double *out)
{
    const size_t n = (size_t)(deg_u + 1) * (size_t)(deg_v + 1);
    for (size_t k = 0; k < n; ++k)
        out[k] = cpw[k * (size_t)dim + (size_t)comp];
}

/* SPDX-License-Identifier: MIT */
/* Pairwise simplification of two adjacent rational bicubics into one, Guthe et al. 2005 §6.2: the
 * inverse of subdivision. The two children cover [0, s] and [s, 1] of the result along one
 * direction, s = Δt1 / (Δt1 + Δt2), so that subdividing the result at s keeps the children's knot
 * intervals. Each line of the result is fitted like §6.1 (degree_reduce.c, sw__lod_g1_fit) with
 * γ = the cubic subdivision matrix at s (8 x 4: the left half's 4 points, then the right half's)
 * in place of the elevation matrix; the nominal λ that reproduces the children's end derivatives
 * are 1/s and 1/(1-s). The error is bounded, as the paper says, by subdividing the result at s —
 * but with the rigorous rational bound of error_bound.c on each half instead of control-point
 * distances.
 */
#include "sw_lod_reduce.h"

#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <string.h>

/* gamma[i*4 + j]: weight of N_j in point i of [left half (i = 0..3), right half (i = 4..7)]. */
static void subdivision_matrix(double s, double gamma[32])
{
    static const double b[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    memset(gamma, 0, 32 * sizeof *gamma);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j <= i; ++j)
            gamma[i * 4 + j] = b[i][j] * pow(s, j) * pow(1.0 - s, i - j);
    for (int i = 0; i < 4; ++i)
        for (int j = i; j < 4; ++j)
            gamma[(4 + i) * 4 + j] = b[3 - i][j - i] * pow(s, j - i) * pow(1.0 - s, 3 - j);
}

/* Offset of point i of line l of a bicubic along dir. */
static size_t at(int dir, int l, int i)
{
    return dir ? ((size_t)i * 4 + (size_t)l) * 4 : ((size_t)l * 4 + (size_t)i) * 4;
}

static const double *line_point(const double *net, int dir, int l, int i)
{
    return net + at(dir, l, i);
}

sw_result sw_lod_simplify_pair(const double c_lo[64], const double c_hi[64], int dir, double s,
                               const sw_lod_error_desc *err, sw_lod_simplify_result *out,
                               sw_status *status)
{
    assert(dir == 0 || dir == 1);
    assert(s > 0.0 && s < 1.0);
    double targets[4 * 8 * 4], ends[4 * 4 * 4], fitted[4 * 4 * 4], gamma[32];
    for (int l = 0; l < 4; ++l) {
        double *t = targets + l * 32, *e = ends + l * 16;
        for (int i = 0; i < 4; ++i) {
            memcpy(t + i * 4, line_point(c_lo, dir, l, i), 4 * sizeof *t);
            memcpy(t + (4 + i) * 4, line_point(c_hi, dir, l, i), 4 * sizeof *t);
        }
        for (int k = 0; k < 4; ++k) {
            e[k] = t[k];
            e[4 + k] = t[4 + k] - t[k];
            e[8 + k] = t[28 + k];
            e[12 + k] = t[24 + k] - t[28 + k];
        }
    }
    subdivision_matrix(s, gamma);
    const double nominal[2] = {1.0 / s, 1.0 / (1.0 - s)};
    memset(&out->info, 0, sizeof out->info);
    uint32_t clamped = 0;
    sw__lod_g1_fit(4, 8, 4, targets, gamma, ends, nominal, fitted, out->info.lambda[dir], &clamped);
    out->info.clamped = clamped << (2 * dir);
    for (int l = 0; l < 4; ++l)
        for (int i = 0; i < 4; ++i)
            memcpy(out->cpw + at(dir, l, i), fitted + (l * 4 + i) * 4, 4 * sizeof *fitted);

    double halves[2][64];
    sw_lod_bez_subdivide(3, 3, 4, out->cpw, dir, s, halves[0], halves[1]);
    for (int h = 0; h < 2; ++h) {
        sw_lod_error_result er;
        sw_result res =
            sw_lod_error_bound(4, 3, 3, h ? c_hi : c_lo, 3, 3, halves[h], err, &er, status);
        if (res != SW_OK)
            return res;
        out->error[h] = er.bound;
    }
    sw__status_ok(status);
    return SW_OK;
}

static void euclid_diff(const double *a, const double *b, double d[3])
{
    for (int k = 0; k < 3; ++k)
        d[k] = a[k] / a[3] - b[k] / b[3];
}

/* Offset of point i of line l along dir in a (du, dv) net. */
static size_t net_at(int32_t du, int dir, int32_t l, int32_t i)
{
    return dir ? ((size_t)i * (size_t)(du + 1) + (size_t)l) * 4
               : ((size_t)l * (size_t)(du + 1) + (size_t)i) * 4;
}

double sw_lod_crease_angle(int32_t du_lo, int32_t dv_lo, const double *lo, int32_t du_hi,
                           int32_t dv_hi, const double *hi, int dir)
{
    const int32_t n_lo = dir ? dv_lo : du_lo, lines = dir ? du_lo + 1 : dv_lo + 1;
    assert((dir ? du_hi : dv_hi) + 1 == lines);
    (void)dv_hi;
    double worst = 0.0;
    for (int32_t l = 0; l < lines; ++l) {
        double a[3], b[3];
        euclid_diff(lo + net_at(du_lo, dir, l, n_lo), lo + net_at(du_lo, dir, l, n_lo - 1), a);
        euclid_diff(hi + net_at(du_hi, dir, l, 1), hi + net_at(du_hi, dir, l, 0), b);
        const double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        if (!(na > 0.0) || !(nb > 0.0))
            continue;
        double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2],
               cz = a[0] * b[1] - a[1] * b[0];
        double ang =
            atan2(sqrt(cx * cx + cy * cy + cz * cz), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
        worst = fmax(worst, ang);
    }
    return worst;
}

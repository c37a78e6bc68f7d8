/* SPDX-License-Identifier: MIT */
/* G1-constrained degree reduction of rational Bézier patches and curves to (bi)cubics, Guthe et
 * al. 2005 §6.1, and leaf subdivision until a rigorous error bound (error_bound.c) meets a
 * tolerance (§6, the blue subtrees of Fig. 7).
 *
 * The fit. For a line of control points P_0..P_n (homogeneous), the cubic is
 *     P~0 = P0,  P~1 = P0 + λ0 (P1 - P0),  P~2 = Pn + λ1 (P_{n-1} - Pn),  P~3 = Pn,
 * which keeps the end points and, for λ > 0 and positive weights, the end tangent directions
 * (C'(0) = n w1/w0 (p1 - p0) and C~'(0) = 3 λ0 w1/w0 (p1 - p0): same direction). With γ the
 * elevation matrix from degree 3 to n, the residual after elevation is
 *     r_i = a_i - λ0 b_i - λ1 c_i,   a_i = P_i - (γ_i0 + γ_i1) P0 - (γ_i2 + γ_i3) Pn,
 *     b_i = γ_i1 (P1 - P0),          c_i = γ_i2 (P_{n-1} - Pn),
 * and sum |r_i|^2 is least for (the paper's closed form)
 *     λ0 = (ab cc - ac bc) / (bb cc - bc^2),   λ1 = (ac bb - ab bc) / (bb cc - bc^2).
 * Our choices where the paper is silent:
 * (1) one λ pair for all lines of a direction (the sums run over every line): the cross-boundary
 *     derivative along a whole edge is then scaled by one positive factor in the first direction;
 * (2) the homogeneous metric: points centred at the targets' box centre c and the weight scaled
 *     by the box radius R, |(x - c w, R w)|, so neither the part's position nor units change λ;
 * (3) clamps: λ >= 0.05 nominal (n/3 for reduction, the Hermite value) against tangent flips,
 *     and where w1 < w0, λ0 <= 0.9 w0 / (w0 - w1) so that w~1 >= 0.1 w0 > 0 (the paper's limit
 *     w0 / (w0 - w1) would give w~1 = 0);
 * (4) a singular system (degenerate end tangents) falls back to the nominal value.
 * The error is NOT the paper's ε_c but the rigorous bound of error_bound.c, computed between the
 * original and the final bicubic (not per direction: u then v would add two errors).
 */
#include "sw_lod_reduce.h"
#include "sw_hooks.h"

#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAXN = SW_SG_MAX_DEGREE + 1 };

/* ---- the G1 least-squares fit ------------------------------------------------------------------
 */
typedef struct metric {
    double c[3], r;
    int32_t dim;
} metric;

static metric metric_of(int32_t count, int32_t dim, const double *pts)
{
    metric m = {{0.0, 0.0, 0.0}, 0.0, dim};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t k = 0; k < count; ++k) {
        const double *p = pts + (size_t)k * (size_t)dim;
        for (int32_t a = 0; a + 1 < dim; ++a) {
            lo[a] = fmin(lo[a], p[a] / p[dim - 1]);
            hi[a] = fmax(hi[a], p[a] / p[dim - 1]);
        }
    }
    double r2 = 0.0;
    for (int32_t a = 0; a + 1 < dim; ++a) {
        m.c[a] = 0.5 * (lo[a] + hi[a]);
        r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    m.r = r2 > 0.0 && isfinite(r2) ? sqrt(r2) : 1.0;
    return m;
}

/* The homogeneous vector x in the fit's metric. */
static void to_metric(const metric *m, const double *x, double *y)
{
    const int32_t w = m->dim - 1;
    for (int32_t a = 0; a < w; ++a)
        y[a] = x[a] - m->c[a] * x[w];
    y[w] = m->r * x[w];
}

static double dot(int32_t dim, const double *a, const double *b)
{
    double s = 0.0;
    for (int32_t k = 0; k < dim; ++k)
        s += a[k] * b[k];
    return s;
}

/* Normal equations of the fit, summed over every line and target. */
typedef struct normal_eq {
    double ab, ac, bb, bc, cc;
} normal_eq;

static void accumulate_line(normal_eq *q, const metric *mt, int32_t m, int32_t dim, const double *t,
                            const double *gamma, const double *ends)
{
    const double *S = ends, *d0 = ends + dim, *E = ends + 2 * dim, *d1 = ends + 3 * dim;
    double md0[SW_LOD_BEZ_MAX_DIM], md1[SW_LOD_BEZ_MAX_DIM];
    to_metric(mt, d0, md0);
    to_metric(mt, d1, md1);
    for (int32_t i = 0; i < m; ++i) {
        const double *g = gamma + 4 * i;
        double a[SW_LOD_BEZ_MAX_DIM], ma[SW_LOD_BEZ_MAX_DIM], b[SW_LOD_BEZ_MAX_DIM],
            c[SW_LOD_BEZ_MAX_DIM];
        for (int32_t k = 0; k < dim; ++k) {
            a[k] = t[(size_t)i * (size_t)dim + (size_t)k] - (g[0] + g[1]) * S[k] -
                   (g[2] + g[3]) * E[k];
            b[k] = g[1] * md0[k];
            c[k] = g[2] * md1[k];
        }
        to_metric(mt, a, ma);
        q->ab += dot(dim, ma, b);
        q->ac += dot(dim, ma, c);
        q->bb += dot(dim, b, b);
        q->bc += dot(dim, b, c);
        q->cc += dot(dim, c, c);
    }
}

static void solve_lambda(const normal_eq *q, const double nominal[2], double lambda[2])
{
    const double det = q->bb * q->cc - q->bc * q->bc;
    lambda[0] = nominal[0];
    lambda[1] = nominal[1];
    if (det > 1e-12 * q->bb * q->cc && det > 0.0) {
        lambda[0] = (q->ab * q->cc - q->ac * q->bc) / det;
        lambda[1] = (q->ac * q->bb - q->ab * q->bc) / det;
    } else if (q->bb > 0.0 && !(q->cc > 0.0)) {
        lambda[0] = q->ab / q->bb;
    } else if (q->cc > 0.0 && !(q->bb > 0.0)) {
        lambda[1] = q->ac / q->cc;
    }
    for (int e = 0; e < 2; ++e)
        if (!isfinite(lambda[e]))
            lambda[e] = nominal[e];
}

/* Clamp of one end: λ >= 0.05 nominal; weights S_w + λ d_w >= 0.1 S_w on every line. */
static double clamp_end(double lambda, double nominal, int32_t n_lines, int32_t dim,
                        const double *ends, int end, uint32_t *clamped, uint32_t bit)
{
    double lo = 0.05 * nominal, hi = INFINITY;
    for (int32_t l = 0; l < n_lines; ++l) {
        const double *e = ends + (size_t)l * 4 * (size_t)dim + (size_t)(2 * end) * (size_t)dim;
        const double w = e[dim - 1], dw = e[2 * dim - 1];
        if (dw < 0.0)
            hi = fmin(hi, 0.9 * w / -dw);
    }
    double v = lambda;
    if (v < lo)
        v = lo;
    if (v > hi)
        v = hi;
    if (v != lambda)
        *clamped |= bit;
    return v;
}

void sw__lod_g1_fit(int32_t n_lines, int32_t m, int32_t dim, const double *targets,
                    const double *gamma, const double *ends, const double nominal[2], double *out,
                    double lambda[2], uint32_t *clamped)
{
    assert(dim >= 2 && dim <= SW_LOD_BEZ_MAX_DIM);
    const metric mt = metric_of(n_lines * m, dim, targets);
    normal_eq q = {0.0, 0.0, 0.0, 0.0, 0.0};
    for (int32_t l = 0; l < n_lines; ++l)
        accumulate_line(&q, &mt, m, dim, targets + (size_t)l * (size_t)m * (size_t)dim, gamma,
                        ends + (size_t)l * 4 * (size_t)dim);
    solve_lambda(&q, nominal, lambda);
    *clamped = 0;
    lambda[0] = clamp_end(lambda[0], nominal[0], n_lines, dim, ends, 0, clamped, 1u);
    lambda[1] = clamp_end(lambda[1], nominal[1], n_lines, dim, ends, 1, clamped, 2u);
    for (int32_t l = 0; l < n_lines; ++l) {
        const double *e = ends + (size_t)l * 4 * (size_t)dim;
        double *o = out + (size_t)l * 4 * (size_t)dim;
        for (int32_t k = 0; k < dim; ++k) {
            o[k] = e[k];
            o[dim + k] = e[k] + lambda[0] * e[dim + k];
            o[2 * dim + k] = e[2 * dim + k] + lambda[1] * e[3 * dim + k];
            o[3 * dim + k] = e[2 * dim + k];
        }
    }
}

/* ---- reduction of one direction ------------------------------------------------------------- */
/* gamma[i*4 + j]: weight of the cubic's P~_j in the degree-n elevation's point i. */
static void elevation_matrix(int32_t n, double *gamma)
{
    double b3[4], bn3[MAXN], bn[MAXN];
    sw_lod_binomial_row(3, b3);
    sw_lod_binomial_row(n - 3, bn3);
    sw_lod_binomial_row(n, bn);
    for (int32_t i = 0; i <= n; ++i)
        for (int32_t j = 0; j < 4; ++j)
            gamma[i * 4 + j] = (i - j >= 0 && i - j <= n - 3) ? b3[j] * bn3[i - j] / bn[i] : 0.0;
}

/* Reduces (or elevates) every line of a (deg_u, deg_v) net along `dir` to degree 3. `out` gets
 * the (3, deg_v) or (deg_u, 3) net. */
static void reduce_dir(int32_t deg_u, int32_t deg_v, int32_t dim, const double *cpw, int dir,
                       double *out, sw_lod_reduce_info *info)
{
    const int32_t n = dir ? deg_v : deg_u, n_lines = dir ? deg_u + 1 : deg_v + 1;
    if (n <= 3) {
        sw_lod_bez_elevate(deg_u, deg_v, dim, cpw, dir ? deg_u : 3, dir ? 3 : deg_v, out);
        info->elevated |= 1u << dir;
        info->lambda[dir][0] = info->lambda[dir][1] = 0.0;
        return;
    }
    const size_t stride = dir ? (size_t)(deg_u + 1) * (size_t)dim : (size_t)dim;
    const size_t line_step = dir ? (size_t)dim : (size_t)(deg_u + 1) * (size_t)dim;
    double targets[MAXN * MAXN * SW_LOD_BEZ_MAX_DIM], ends[MAXN * 4 * SW_LOD_BEZ_MAX_DIM];
    double fitted[MAXN * 4 * SW_LOD_BEZ_MAX_DIM], gamma[MAXN * 4];
    for (int32_t l = 0; l < n_lines; ++l) {
        const double *line = cpw + (size_t)l * line_step;
        double *t = targets + (size_t)l * (size_t)(n + 1) * (size_t)dim;
        double *e = ends + (size_t)l * 4 * (size_t)dim;
        for (int32_t i = 0; i <= n; ++i)
            memcpy(t + (size_t)i * (size_t)dim, line + (size_t)i * stride, (size_t)dim * sizeof *t);
        for (int32_t k = 0; k < dim; ++k) {
            e[k] = t[k];
            e[dim + k] = t[dim + k] - t[k];
            e[2 * dim + k] = t[(size_t)n * (size_t)dim + (size_t)k];
            e[3 * dim + k] = t[(size_t)(n - 1) * (size_t)dim + (size_t)k] - e[2 * dim + k];
        }
    }
    elevation_matrix(n, gamma);
    const double nominal[2] = {n / 3.0, n / 3.0};
    uint32_t clamped = 0;
    sw__lod_g1_fit(n_lines, n + 1, dim, targets, gamma, ends, nominal, fitted, info->lambda[dir],
                   &clamped);
    info->clamped |= clamped << (2 * dir);
    const size_t out_stride = dir ? (size_t)(deg_u + 1) * (size_t)dim : (size_t)dim;
    const size_t out_step = dir ? (size_t)dim : 4 * (size_t)dim;
    for (int32_t l = 0; l < n_lines; ++l)
        for (int32_t i = 0; i < 4; ++i)
            memcpy(out + (size_t)l * out_step + (size_t)i * out_stride,
                   fitted + ((size_t)l * 4 + (size_t)i) * (size_t)dim, (size_t)dim * sizeof *out);
}

void sw_lod_reduce_bicubic(int32_t deg_u, int32_t deg_v, const double *cpw, double out[64],
                           sw_lod_reduce_info *info)
{
    assert(deg_u >= 1 && deg_u <= SW_SG_MAX_DEGREE && deg_v >= 1 && deg_v <= SW_SG_MAX_DEGREE);
    sw_lod_reduce_info local;
    sw_lod_reduce_info *inf = info ? info : &local;
    memset(inf, 0, sizeof *inf);
    double mid[4 * MAXN * 4];
    reduce_dir(deg_u, deg_v, 4, cpw, 0, mid, inf);
    reduce_dir(3, deg_v, 4, mid, 1, out, inf);
}

void sw_lod_reduce_cubic_curve(int32_t deg, int32_t dim, const double *cpw, double *out,
                               sw_lod_reduce_info *info)
{
    assert(deg >= 1 && deg <= SW_SG_MAX_DEGREE && dim >= 2 && dim <= SW_LOD_BEZ_MAX_DIM);
    sw_lod_reduce_info local;
    sw_lod_reduce_info *inf = info ? info : &local;
    memset(inf, 0, sizeof *inf);
    reduce_dir(deg, 0, dim, cpw, 0, out, inf);
}

/* ---- leaf subdivision ------------------------------------------------------------------------ */
/* Largest 4th difference along `dir` in the fit's metric: what a cubic cannot follow. */
static double fourth_difference(int32_t deg_u, int32_t deg_v, const double *cpw, int dir)
{
    const int32_t n = dir ? deg_v : deg_u, n_lines = dir ? deg_u + 1 : deg_v + 1;
    if (n < 4)
        return 0.0;
    const metric mt = metric_of((deg_u + 1) * (deg_v + 1), 4, cpw);
    const size_t stride = dir ? (size_t)(deg_u + 1) * 4 : 4;
    const size_t line_step = dir ? 4 : (size_t)(deg_u + 1) * 4;
    static const double c4[5] = {1.0, -4.0, 6.0, -4.0, 1.0};
    double worst = 0.0;
    for (int32_t l = 0; l < n_lines; ++l)
        for (int32_t i = 0; i + 4 <= n; ++i) {
            double d[4] = {0.0, 0.0, 0.0, 0.0}, md[4];
            for (int32_t r = 0; r < 5; ++r)
                for (int32_t k = 0; k < 4; ++k)
                    d[k] +=
                        c4[r] * cpw[(size_t)l * line_step + (size_t)(i + r) * stride + (size_t)k];
            to_metric(&mt, d, md);
            worst = fmax(worst, sqrt(dot(4, md, md)));
        }
    return worst;
}

typedef struct tree_walk {
    int32_t deg_u, deg_v;
    const sw_lod_reduce_desc *desc;
    int32_t max_depth;
    sw_lod_reduce_visit_fn visit;
    void *ctx;
    sw_status *status;
} tree_walk;

static sw_result tree_rec(const tree_walk *w, const double *piece, const double rect[4],
                          int32_t depth, int32_t parent)
{
    sw_lod_reduce_node node = {depth,
                               parent,
                               1,
                               0,
                               {rect[0], rect[1], rect[2], rect[3]},
                               NULL,
                               0.0,
                               {{{0.0, 0.0}, {0.0, 0.0}}, 0, 0}};
    double bic[64];
    sw_lod_reduce_bicubic(w->deg_u, w->deg_v, piece, bic, &node.info);
    sw_lod_error_result er;
    sw_result res = sw_lod_error_bound(4, w->deg_u, w->deg_v, piece, 3, 3, bic, &w->desc->error,
                                       &er, w->status);
    if (res != SW_OK)
        return res;
    node.cpw = bic;
    node.error = er.bound;
    node.leaf = !(er.bound > w->desc->tolerance) || depth >= w->max_depth;
    node.split_dir = fourth_difference(w->deg_u, w->deg_v, piece, 1) >
                     fourth_difference(w->deg_u, w->deg_v, piece, 0);
    const int32_t handle = w->visit(w->ctx, &node);
    if (handle < 0)
        return sw__fail(w->status, SW_ERR_OUT_OF_MEMORY, "degree reduction: visitor stopped");
    if (node.leaf)
        return SW_OK;
    const size_t n = sw_lod_bez_count(w->deg_u, w->deg_v, 4);
    double *halves = sw__malloc(2 * n * sizeof *halves);
    if (!halves)
        return sw__fail(w->status, SW_ERR_OUT_OF_MEMORY, "degree reduction: %zu doubles", 2 * n);
    sw_lod_bez_subdivide(w->deg_u, w->deg_v, 4, piece, node.split_dir, 0.5, halves, halves + n);
    const int k = 2 * node.split_dir;
    const double mid = 0.5 * (rect[k] + rect[k + 1]);
    for (int h = 0; h < 2 && res == SW_OK; ++h) {
        double r[4] = {rect[0], rect[1], rect[2], rect[3]};
        r[k + (h ? 0 : 1)] = mid;
        res = tree_rec(w, halves + (size_t)h * n, r, depth + 1, handle);
    }
    sw__free(halves);
    return res;
}

sw_result sw_lod_reduce_tree(int32_t deg_u, int32_t deg_v, const double *cpw,
                             const sw_lod_reduce_desc *desc, sw_lod_reduce_visit_fn visit,
                             void *ctx, sw_status *status)
{
    assert(desc && visit && desc->tolerance > 0.0);
    const tree_walk w = {deg_u, deg_v, desc,  desc->max_depth > 0 ? desc->max_depth : 12,
                         visit, ctx,   status};
    const double whole[4] = {0.0, 1.0, 0.0, 1.0};
    sw_result res = tree_rec(&w, cpw, whole, 0, -1);
    if (res == SW_OK)
        sw__status_ok(status);
    return res;
}

typedef struct leaf_ctx {
    sw_lod_leaf_set *set;
    double tolerance;
} leaf_ctx;

static int32_t collect_leaf(void *ctx, const sw_lod_reduce_node *node)
{
    leaf_ctx *c = ctx;
    sw_lod_leaf_set *s = c->set;
    if (!node->leaf)
        return 0;
    if (s->count == s->cap) {
        int32_t cap = s->cap ? 2 * s->cap : 8;
        sw_lod_bicubic_leaf *grown = sw__realloc(s->leaves, (size_t)cap * sizeof *grown);
        if (!grown)
            return -1;
        s->leaves = grown;
        s->cap = cap;
    }
    sw_lod_bicubic_leaf *leaf = &s->leaves[s->count++];
    memcpy(leaf->rect, node->rect, sizeof leaf->rect);
    memcpy(leaf->cpw, node->cpw, sizeof leaf->cpw);
    leaf->error = node->error;
    if (node->error > c->tolerance)
        ++s->over_tolerance;
    return 0;
}

sw_result sw_lod_reduce_leaves(int32_t deg_u, int32_t deg_v, const double *cpw,
                               const sw_lod_reduce_desc *desc, sw_lod_leaf_set *out,
                               sw_status *status)
{
    memset(out, 0, sizeof *out);
    leaf_ctx c = {out, desc->tolerance};
    return sw_lod_reduce_tree(deg_u, deg_v, cpw, desc, collect_leaf, &c, status);
}

void sw_lod_leaf_set_free(sw_lod_leaf_set *set)
{
    if (!set)
        return;
    sw__free(set->leaves);
    memset(set, 0, sizeof *set);
}

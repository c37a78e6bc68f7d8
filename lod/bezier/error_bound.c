/* SPDX-License-Identifier: MIT */
/* A rigorous bound of |A/wA - B/wB| between two rational Bézier nets, for the approximation errors
 * of Guthe et al. 2005: degree reduction (§6.1), pairwise simplification (§6.2) and trim curves
 * approximated by rational cubics (§4.1).
 *
 * Why the paper's ε_c is not a bound. §6.1 takes ε_c = max_i |p_i - p~_i| over the projected
 * control points of the original and of the elevated approximation. That bounds the distance only
 * when both curves have the same weights: then A/w - B/w = sum w_i B_i (p_i - p~_i) / sum w_i B_i,
 * a convex combination of the differences. Once the weights differ, the two points are different
 * rational combinations: two quarter circles with identical projected control points and the
 * weights (1, 1/sqrt2, 1) and (1, 1, 1) have ε_c = 0 but differ by 0.07 of the radius. The G1
 * reduction changes weights (w~_1 = w_0 + λ0 (w_1 - w_0)), so ε_c can be far below the real error.
 * And reducing in u, then in v, measures two errors: each step's ε_c compares against its own
 * input, so the total is at best their sum (triangle inequality), not the larger one.
 *
 * What we bound instead, directly between the original and the final approximation. With
 * D = A_xyz wB - B_xyz wA and W = wA wB (products of Bernstein polynomials stay in the Bernstein
 * basis of the summed degrees, sw_lod_bez_mul_add):
 *     A/wA - B/wB = D / W,   D = sum_k D_k B_k,   W = sum_k W_k B_k,
 *     W_k > 0 (products of positive weights have positive coefficients),
 *     |D| <= sum |D_k| B_k = sum (|D_k| / W_k) W_k B_k <= max_k (|D_k| / W_k) W,
 * hence |A/wA - B/wB| <= max_k |D_k| / W_k (the rational convex hull property; it is also
 * <= max |D_k| / min W_k, the form of Guthe §5.1). The bound is exact at the four corners and
 * converges quadratically to the true maximum when the domain is subdivided, so we run a branch and
 * bound: sub-rectangles (D and W restricted by de Casteljau) are kept in a max-heap of their
 * bounds, the largest is split 2x2 (2 for curves), the attained distances at the pieces' corners
 * give a lower bound `found`, and pieces whose bound cannot exceed it are dropped. The result is
 * max over the remaining pieces, which is >= the supremum.
 *
 * Numerics: both nets are translated to the centre of their control points first (D is
 * translation-invariant: (A - c wA) wB - (B - c wB) wA = D), so far-from-origin CAD coordinates do
 * not cancel; a rounding allowance of 16 (P + Q + 2) ulps of the nets' size (radius + distance of
 * the centre from the origin), scaled by the weights' spread, is added to the bound.
 */
#include "sw_lod_error.h"
#include "sw_hooks.h"

#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct piece {
    double ub;
    double rect[4];
} piece;

typedef struct heap {
    piece *v;
    int32_t n;
} heap;

static void heap_push(heap *h, piece p)
{
    int32_t i = h->n++;
    while (i > 0) {
        int32_t parent = (i - 1) / 2;
        if (h->v[parent].ub >= p.ub)
            break;
        h->v[i] = h->v[parent];
        i = parent;
    }
    h->v[i] = p;
}

static piece heap_pop(heap *h)
{
    piece top = h->v[0], last = h->v[--h->n];
    int32_t i = 0;
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && h->v[c + 1].ub > h->v[c].ub)
            ++c;
        if (h->v[c].ub <= last.ub)
            break;
        h->v[i] = h->v[c];
        i = c;
    }
    if (h->n > 0)
        h->v[i] = last;
    return top;
}

/* Centre and radius of the projected control points of both nets, and the weights' spread. */
typedef struct frame {
    double c[3], radius, wratio;
} frame;

static void net_extent(int32_t dim, size_t n, const double *cpw, double lo[3], double hi[3],
                       double *wmin, double *wmax)
{
    for (size_t k = 0; k < n; ++k) {
        const double *p = cpw + k * (size_t)dim, w = p[dim - 1];
        for (int32_t a = 0; a + 1 < dim; ++a) {
            lo[a] = fmin(lo[a], p[a] / w);
            hi[a] = fmax(hi[a], p[a] / w);
        }
        *wmin = fmin(*wmin, w);
        *wmax = fmax(*wmax, w);
    }
}

static frame frame_of(int32_t dim, size_t na, const double *a, size_t nb, const double *b)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double wmin_a = INFINITY, wmax_a = 0.0, wmin_b = INFINITY, wmax_b = 0.0;
    net_extent(dim, na, a, lo, hi, &wmin_a, &wmax_a);
    net_extent(dim, nb, b, lo, hi, &wmin_b, &wmax_b);
    frame f = {{0.0, 0.0, 0.0}, 0.0, 1.0};
    double r2 = 0.0;
    for (int32_t k = 0; k + 1 < dim; ++k) {
        f.c[k] = 0.5 * (lo[k] + hi[k]);
        r2 += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    f.radius = sqrt(r2);
    f.wratio = (wmax_a * wmax_b) / (wmin_a * wmin_b);
    return f;
}

static void centre_net(int32_t dim, size_t n, const double *src, const frame *f, double *dst)
{
    for (size_t k = 0; k < n; ++k) {
        const double *p = src + k * (size_t)dim;
        double *q = dst + k * (size_t)dim;
        for (int32_t a = 0; a + 1 < dim; ++a)
            q[a] = p[a] - f->c[a] * p[dim - 1];
        q[dim - 1] = p[dim - 1];
    }
}

/* The piece's bound max_k |D_k| / W_k (+INF when a W_k is not positive) and the largest distance
 * attained at its four corners (where a Bézier net interpolates its corner coefficients). */
static double piece_bound(int32_t dim, int32_t P, int32_t Q, const double *e, double *corner_max)
{
    double ub = 0.0;
    const size_t n = (size_t)(P + 1) * (size_t)(Q + 1);
    for (size_t k = 0; k < n; ++k) {
        const double *x = e + k * (size_t)dim, w = x[dim - 1];
        double d2 = 0.0;
        for (int32_t a = 0; a + 1 < dim; ++a)
            d2 += x[a] * x[a];
        if (!(w > 0.0))
            return INFINITY;
        ub = fmax(ub, sqrt(d2) / w);
    }
    const size_t corners[4] = {0, (size_t)P, (size_t)Q * (size_t)(P + 1), n - 1};
    for (int c = 0; c < 4; ++c) {
        const double *x = e + corners[c] * (size_t)dim;
        double d2 = 0.0;
        for (int32_t a = 0; a + 1 < dim; ++a)
            d2 += x[a] * x[a];
        *corner_max = fmax(*corner_max, sqrt(d2) / x[dim - 1]);
    }
    return ub;
}

/* E = (A_xyz wB - B_xyz wA, wA wB) of degrees (pa + pb, qa + qb); tmp holds as many doubles. */
static void difference_net(int32_t dim, int32_t pa, int32_t qa, const double *a, int32_t pb,
                           int32_t qb, const double *b, double *wa, double *wb, double *tmp,
                           double *e)
{
    const int32_t P = pa + pb, Q = qa + qb;
    const size_t n = (size_t)(P + 1) * (size_t)(Q + 1);
    sw_lod_bez_component(pa, qa, dim, a, dim - 1, wa);
    sw_lod_bez_component(pb, qb, dim, b, dim - 1, wb);
    memset(e, 0, n * (size_t)dim * sizeof *e);
    memset(tmp, 0, n * (size_t)dim * sizeof *tmp);
    sw_lod_bez_mul_add(dim, pa, qa, a, pb, qb, wb, 1.0, e);
    sw_lod_bez_mul_add(dim, pb, qb, b, pa, qa, wa, 1.0, tmp);
    for (size_t k = 0; k < n; ++k)
        for (int32_t c = 0; c + 1 < dim; ++c)
            e[k * (size_t)dim + (size_t)c] -= tmp[k * (size_t)dim + (size_t)c];
}

typedef struct search {
    int32_t dim, P, Q;
    const double *root;
    double *work;
    double found, dropped, rel_tol, noise;
    heap h;
    int32_t pieces;
} search;

/* Restricts the difference net to `rect`, bounds it and keeps it unless it cannot matter. */
static void consider(search *s, const double rect[4])
{
    sw_lod_bez_restrict(s->P, s->Q, s->dim, s->root, rect, s->work);
    double ub = piece_bound(s->dim, s->P, s->Q, s->work, &s->found);
    ++s->pieces;
    piece p = {ub, {rect[0], rect[1], rect[2], rect[3]}};
    if (ub <= s->found * (1.0 + s->rel_tol) + s->noise)
        s->dropped = fmax(s->dropped, ub); /* cannot raise the answer by more than the tolerance */
    else
        heap_push(&s->h, p);
}

static double run_search(search *s, int32_t max_pieces)
{
    const double whole[4] = {0.0, 1.0, 0.0, 1.0};
    consider(s, whole);
    while (s->h.n > 0) {
        const piece top = s->h.v[0];
        if (top.ub <= s->found * (1.0 + s->rel_tol) + s->noise || s->pieces + 4 > max_pieces)
            break;
        heap_pop(&s->h);
        const double um = 0.5 * (top.rect[0] + top.rect[1]), vm = 0.5 * (top.rect[2] + top.rect[3]);
        const int split_v = s->Q > 0 ? 1 : 0;
        for (int j = 0; j <= split_v; ++j)
            for (int i = 0; i < 2; ++i) {
                double r[4] = {i ? um : top.rect[0], i ? top.rect[1] : um, top.rect[2],
                               top.rect[3]};
                if (split_v) {
                    r[2] = j ? vm : top.rect[2];
                    r[3] = j ? top.rect[3] : vm;
                }
                consider(s, r);
            }
    }
    double bound = fmax(s->found, s->dropped);
    if (s->h.n > 0)
        bound = fmax(bound, s->h.v[0].ub);
    return bound;
}

sw_result sw_lod_error_bound(int32_t dim, int32_t pa, int32_t qa, const double *a, int32_t pb,
                             int32_t qb, const double *b, const sw_lod_error_desc *desc,
                             sw_lod_error_result *out, sw_status *status)
{
    assert(dim >= 2 && dim <= SW_LOD_BEZ_MAX_DIM);
    const sw_lod_error_desc d = desc ? *desc : (sw_lod_error_desc){0.0, 0};
    const int32_t max_pieces = d.max_pieces > 0 ? d.max_pieces : 256;
    const int32_t P = pa + pb, Q = qa + qb;
    const size_t na = sw_lod_bez_count(pa, qa, dim), nb = sw_lod_bez_count(pb, qb, dim);
    const size_t ne = sw_lod_bez_count(P, Q, dim);
    const size_t heap_cap = 4 * (size_t)max_pieces + 8;
    double *mem = sw__malloc((na + nb + 3 * ne + (na + nb) / (size_t)dim) * sizeof *mem);
    piece *hv = sw__malloc(heap_cap * sizeof *hv);
    if (!mem || !hv) {
        sw__free(mem);
        sw__free(hv);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "error bound: %zu coefficients", ne);
    }
    double *ca = mem, *cb = ca + na, *e = cb + nb, *tmp = e + ne, *work = tmp + ne;
    double *wa = work + ne, *wb = wa + na / (size_t)dim;

    const frame f = frame_of(dim, na / (size_t)dim, a, nb / (size_t)dim, b);
    centre_net(dim, na / (size_t)dim, a, &f, ca);
    centre_net(dim, nb / (size_t)dim, b, &f, cb);
    difference_net(dim, pa, qa, ca, pb, qb, cb, wa, wb, tmp, e);

    search s = {dim, P, Q, e, work, 0.0, 0.0, d.rel_tol > 0.0 ? d.rel_tol : 0.02, 0.0, {hv, 0}, 0};
    /* rounding, over W_k >= wmin^2: the translation rounds each coordinate once, by a few ulps
     * of |c| w (2 |c| + R of each centred point, into each of D's two products: 8 |c|); every
     * later coefficient is a convex combination of products of the centred nets
     * (|.| <= R wA wB), a few ulps per step of the product and of each de Casteljau level. The
     * distance from the origin is not multiplied by the steps: it made the allowance of a face
     * 2e4 from the origin and 0.01 across 1e-9, more than the tolerance of a close view, and
     * its hierarchy refined to the node cap. */
    const double cn = sqrt(f.c[0] * f.c[0] + f.c[1] * f.c[1] + f.c[2] * f.c[2]);
    s.noise = DBL_EPSILON * f.wratio * (16.0 * (double)(P + Q + 2) * f.radius + 8.0 * cn);
    double bound = run_search(&s, max_pieces);
    out->bound = isfinite(bound) ? bound + s.noise : INFINITY;
    out->found = s.found;
    out->pieces = s.pieces;
    sw__free(mem);
    sw__free(hv);
    sw__status_ok(status);
    return SW_OK;
}

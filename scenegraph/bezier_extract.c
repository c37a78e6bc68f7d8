/* SPDX-License-Identifier: MIT */
/* Extraction of the rational Bézier patches of a NURBS surface (Guthe et al. 2005 §3: the GPU
 * pipeline starts from exactly these patches, each then trimmed by its own trim texture, §4).
 *
 * Raising every interior knot to full multiplicity (The NURBS Book A5.6) makes the control points
 * of each knot span's Bézier segment equal to the blossom of the span's local control points at
 * (a^(p-i), b^i), [a, b] being the span. This file evaluates those blossoms directly, span by span,
 * with de Boor's triangle (the same convex combinations Boehm insertion performs), so a patch
 * costs O(p^3) per row and only the patches a trim box needs are ever computed.
 */
#include "sw_sg_geom.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define SW__P1 (SW_SG_MAX_DEGREE + 1)

/* Bézier points of span [knots[k], knots[k+1]] of a degree-p B-spline whose p+1 local homogeneous
 * points (4 doubles each) start at `pts` with a stride of `stride` doubles. */
static void span_to_bezier(const double *knots, int32_t p, int32_t k, const double *pts,
                           size_t stride, double *out, size_t out_stride)
{
    const double a = knots[k], b = knots[k + 1];
    double d[SW__P1][4];
    for (int32_t i = 0; i <= p; i++) {
        for (int32_t r = 0; r <= p; r++)
            memcpy(d[r], pts + (size_t)r * stride, sizeof d[r]);
        /* Blossom arguments: p - i copies of a, then i copies of b (their order is free). */
        for (int32_t l = 1; l <= p; l++) {
            const double x = l <= p - i ? a : b;
            for (int32_t r = p; r >= l; r--) {
                const int32_t j = k - p + r;
                const double alpha = (x - knots[j]) / (knots[j + p + 1 - l] - knots[j]);
                for (int c = 0; c < 4; c++)
                    d[r][c] = (1.0 - alpha) * d[r - 1][c] + alpha * d[r][c];
            }
        }
        memcpy(out + (size_t)i * out_stride, d[p], sizeof d[p]);
    }
}

/* Fills patch->cpw for the spans ku (in u) and kv (in v). */
static void extract_patch(const sw_sg_surface *s, int32_t ku, int32_t kv, sw_sg_bezier_patch *patch)
{
    const int32_t p = s->deg_u, q = s->deg_v;
    const size_t row = (size_t)(p + 1) * 4;
    for (int32_t j = 0; j <= q; j++) {
        const double *src = s->cpw + ((size_t)(kv - q + j) * (size_t)s->n_u + (size_t)(ku - p)) * 4;
        span_to_bezier(s->knots_u, p, ku, src, 4, patch->cpw + (size_t)j * row, 4);
    }
    double col[SW__P1 * 4];
    for (int32_t i = 0; i <= p; i++) {
        double *c0 = patch->cpw + (size_t)i * 4;
        for (int32_t j = 0; j <= q; j++)
            memcpy(col + j * 4, c0 + (size_t)j * row, sizeof(double) * 4);
        span_to_bezier(s->knots_v, q, kv, col, 4, c0, row);
    }
}

/* Next non-empty span after `k` (start with k = degree - 1), or n when there is none. */
static int32_t next_span(const double *knots, int32_t n, int32_t k)
{
    for (k++; k < n; k++)
        if (knots[k] < knots[k + 1])
            break;
    return k;
}

/* Whether span [a, b] meets the box side [lo, hi]: with positive length when the box has some,
 * so patches that only touch the box along a knot line are skipped. */
static int span_meets(double a, double b, double lo, double hi)
{
    if (lo < hi)
        return a < hi && b > lo;
    return a <= hi && b >= lo;
}

/* Counts the selected spans of one direction. */
static int32_t count_selected(const double *knots, int32_t deg, int32_t n, double lo, double hi)
{
    int32_t count = 0;
    for (int32_t k = next_span(knots, n, deg - 1); k < n; k = next_span(knots, n, k))
        count += span_meets(knots[k], knots[k + 1], lo, hi);
    return count;
}

size_t sw_sg_surface_bezier_storage_bound(const sw_sg_surface *s)
{
    assert(s);
    const size_t su = (size_t)sw_sg_knots_segment_count(s->knots_u, s->deg_u, s->n_u);
    const size_t sv = (size_t)sw_sg_knots_segment_count(s->knots_v, s->deg_v, s->n_v);
    return su * sv * (size_t)(s->deg_u + 1) * (size_t)(s->deg_v + 1) * 4;
}

sw_result sw_sg_surface_extract_bezier_in(const sw_sg_surface *s, double u0, double u1, double v0,
                                          double v1, sw_sg_bezier_set *out, sw_status *status)
{
    assert(s && out);
    assert(s->deg_u >= 1 && s->deg_u <= SW_SG_MAX_DEGREE);
    assert(s->deg_v >= 1 && s->deg_v <= SW_SG_MAX_DEGREE);
    memset(out, 0, sizeof *out);
    const int32_t p = s->deg_u, q = s->deg_v;
    const int32_t nu = count_selected(s->knots_u, p, s->n_u, u0, u1);
    const int32_t nv = count_selected(s->knots_v, q, s->n_v, v0, v1);
    if (nu == 0 || nv == 0) {
        sw__status_ok(status);
        return SW_OK;
    }
    const size_t count = (size_t)nu * (size_t)nv;
    const size_t per = (size_t)(p + 1) * (size_t)(q + 1) * 4;
    if (count > SIZE_MAX / sizeof(sw_sg_bezier_patch) || count > SIZE_MAX / sizeof(double) / per)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "Bézier extraction: %d x %d patches", (int)nu,
                        (int)nv);
    out->patches = sw__calloc(count, sizeof *out->patches);
    out->storage = sw__malloc(count * per * sizeof(double));
    if (!out->patches || !out->storage) {
        sw_sg_bezier_set_free(out);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY,
                        "Bézier extraction: cannot allocate %zu patches of degree %d x %d", count,
                        (int)p, (int)q);
    }
    out->n_u = nu;
    out->n_v = nv;

    int32_t b = 0, seg_v = 0;
    for (int32_t kv = next_span(s->knots_v, s->n_v, q - 1); kv < s->n_v;
         kv = next_span(s->knots_v, s->n_v, kv), seg_v++) {
        if (!span_meets(s->knots_v[kv], s->knots_v[kv + 1], v0, v1))
            continue;
        int32_t a = 0, seg_u = 0;
        for (int32_t ku = next_span(s->knots_u, s->n_u, p - 1); ku < s->n_u;
             ku = next_span(s->knots_u, s->n_u, ku), seg_u++) {
            if (!span_meets(s->knots_u[ku], s->knots_u[ku + 1], u0, u1))
                continue;
            const size_t idx = (size_t)b * (size_t)nu + (size_t)a;
            sw_sg_bezier_patch *patch = &out->patches[idx];
            patch->deg_u = p;
            patch->deg_v = q;
            patch->seg_u = seg_u;
            patch->seg_v = seg_v;
            patch->u0 = s->knots_u[ku];
            patch->u1 = s->knots_u[ku + 1];
            patch->v0 = s->knots_v[kv];
            patch->v1 = s->knots_v[kv + 1];
            patch->cpw = out->storage + idx * per;
            extract_patch(s, ku, kv, patch);
            a++;
        }
        b++;
    }
    assert(b == nv);
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_sg_surface_extract_bezier(const sw_sg_surface *s, sw_sg_bezier_set *out,
                                       sw_status *status)
{
    return sw_sg_surface_extract_bezier_in(s, -INFINITY, INFINITY, -INFINITY, INFINITY, out,
                                           status);
}

void sw_sg_bezier_set_free(sw_sg_bezier_set *set)
{
    if (!set)
        return;
    sw__free(set->patches);
    sw__free(set->storage);
    memset(set, 0, sizeof *set);
}

/* de Casteljau on n+1 homogeneous points (4 doubles each, in place). */
static void casteljau(double (*pts)[4], int32_t n, double t)
{
    for (int32_t l = 1; l <= n; l++)
        for (int32_t i = 0; i <= n - l; i++)
            for (int c = 0; c < 4; c++)
                pts[i][c] = (1.0 - t) * pts[i][c] + t * pts[i + 1][c];
}

void sw_sg_bezier_patch_eval(const sw_sg_bezier_patch *p, double s, double t, double out[3])
{
    assert(p && p->cpw && p->deg_u <= SW_SG_MAX_DEGREE && p->deg_v <= SW_SG_MAX_DEGREE);
    double row[SW__P1][4], col[SW__P1][4];
    const int32_t nu = p->deg_u, nv = p->deg_v;
    for (int32_t j = 0; j <= nv; j++) {
        memcpy(row, p->cpw + (size_t)j * (size_t)(nu + 1) * 4,
               sizeof(double) * 4 * (size_t)(nu + 1));
        casteljau(row, nu, s);
        memcpy(col[j], row[0], sizeof col[j]);
    }
    casteljau(col, nv, t);
    for (int c = 0; c < 3; c++)
        out[c] = col[0][c] / col[0][3];
}

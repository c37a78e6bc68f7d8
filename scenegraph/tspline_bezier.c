/* SPDX-License-Identifier: MIT */
/* Bézier extraction of T-splines and their hand-over to the scene as faces.
 *
 * Guthe et al. 2005 §3 converts T-splines to piecewise rational Bézier form with the local knot
 * insertion of Sederberg et al. 2004 before the bicubic pipeline. Here each region of the
 * Krishnamurthy & Yasui decomposition (tspline.c) becomes one rational bicubic patch: every
 * influencing blending function is refined by Boehm insertion of the region's edges into its
 * local knot vectors (sw__tspline_bernstein), and its tensor-product Bernstein coefficients, times
 * w_i (P_i, 1), are summed into the patch's homogeneous control points.
 */
#include "sw_sg_tspline.h"
#include "sw_hooks.h"
#include "sw_sg_tspline_internal.h"
#include "sw_status_util.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

static uint32_t index_of(const double *b, uint32_t n, double x)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (b[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static void region_patch(const sw_sg_tspline_view *v, const sw_sg_tspline_region *g, double *cpw)
{
    memset(cpw, 0, sizeof(double) * 64);
    for (uint32_t k = 0; k < g->count; k++) {
        const uint32_t i = v->region_points[g->first + k];
        const double *p = v->cpw + (size_t)i * 4;
        double bu[4], bv[4];
        sw__tspline_bernstein(v->knots_u + (size_t)i * 5, g->u0, g->u1, bu);
        sw__tspline_bernstein(v->knots_v + (size_t)i * 5, g->v0, g->v1, bv);
        for (int l = 0; l < 4; l++)
            for (int j = 0; j < 4; j++)
                for (int c = 0; c < 4; c++)
                    cpw[(l * 4 + j) * 4 + c] += bu[j] * bv[l] * p[c];
    }
}

sw_result sw_sg_tspline_extract_bezier(const sw_sg_tspline *ts, sw_sg_tspline_bezier *out,
                                       sw_status *status)
{
    assert(ts && out);
    memset(out, 0, sizeof *out);
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    sw_sg_bezier_patch *patches = sw__malloc(sizeof *patches * v->n_regions);
    double *storage = sw__malloc(sizeof(double) * 64 * v->n_regions);
    if (!patches || !storage) {
        sw__free(patches);
        sw__free(storage);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "T-spline Bézier extraction: out of memory");
    }
    for (uint32_t r = 0; r < v->n_regions; r++) {
        const sw_sg_tspline_region *g = &v->regions[r];
        sw_sg_bezier_patch *p = &patches[r];
        p->deg_u = p->deg_v = 3;
        p->seg_u = (int32_t)index_of(v->bu, v->n_bu, g->u0);
        p->seg_v = (int32_t)index_of(v->bv, v->n_bv, g->v0);
        p->u0 = g->u0, p->u1 = g->u1, p->v0 = g->v0, p->v1 = g->v1;
        p->cpw = storage + (size_t)r * 64;
        region_patch(v, g, p->cpw);
        for (int j = 0; j < 16; j++) {
            const double w = p->cpw[j * 4 + 3];
            if (!(w > 0.0)) {
                sw__free(patches);
                sw__free(storage);
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "T-spline region %u: Bézier weight %d is %g, not positive", r, j,
                                w);
            }
        }
    }
    out->n_patches = v->n_regions;
    out->patches = patches;
    out->storage = storage;
    sw__status_ok(status);
    return SW_OK;
}

void sw_sg_tspline_bezier_free(sw_sg_tspline_bezier *bz)
{
    if (!bz)
        return;
    sw__free(bz->patches);
    sw__free(bz->storage);
    memset(bz, 0, sizeof *bz);
}

/* ---- scene ------------------------------------------------------------------------------------
 */

/* Face of one patch, with knot vectors [u0 x4, u1 x4] and [v0 x4, v1 x4]; SW_SG_NONE on failure. */
static uint32_t add_face(sw_sg_builder *b, const sw_sg_bezier_patch *p)
{
    const double ku[8] = {p->u0, p->u0, p->u0, p->u0, p->u1, p->u1, p->u1, p->u1};
    const double kv[8] = {p->v0, p->v0, p->v0, p->v0, p->v1, p->v1, p->v1, p->v1};
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 3;
    f.n_u = f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, ku, 8);
    f.knots_v = sw_sg_builder_push_doubles(b, kv, 8);
    f.cpw = sw_sg_builder_push_doubles(b, p->cpw, 64);
    if (f.knots_u == UINT64_MAX || f.knots_v == UINT64_MAX || f.cpw == UINT64_MAX)
        return SW_SG_NONE;
    f.kind = SW_SG_KIND_TSPLINE;
    f.uv_box[0] = p->u0, f.uv_box[1] = p->u1, f.uv_box[2] = p->v0, f.uv_box[3] = p->v1;
    return sw_sg_builder_add_face(b, &f);
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Regions that share a cell edge become adjacent faces (for super-surface clustering). */
static sw_result add_adjacency(sw_sg_builder *b, const sw_sg_tspline_view *v, uint32_t face0)
{
    const uint32_t nuc = v->n_bu - 1, nvc = v->n_bv - 1;
    uint64_t *pairs = sw__malloc(sizeof(uint64_t) * ((size_t)nuc * nvc * 2 + 1));
    if (!pairs)
        return SW_ERR_OUT_OF_MEMORY;
    size_t n = 0;
    for (uint32_t bb = 0; bb < nvc; bb++) {
        for (uint32_t a = 0; a < nuc; a++) {
            const uint32_t r = v->cell_region[(size_t)bb * nuc + a];
            const uint32_t nb[2] = {a + 1 < nuc ? v->cell_region[(size_t)bb * nuc + a + 1] : r,
                                    bb + 1 < nvc ? v->cell_region[(size_t)(bb + 1) * nuc + a] : r};
            for (int k = 0; k < 2; k++)
                if (nb[k] != r)
                    pairs[n++] = r < nb[k] ? (uint64_t)r << 32 | nb[k] : (uint64_t)nb[k] << 32 | r;
        }
    }
    qsort(pairs, n, sizeof *pairs, cmp_u64);
    sw_result res = SW_OK;
    for (size_t k = 0; k < n && res == SW_OK; k++) {
        if (k && pairs[k] == pairs[k - 1])
            continue;
        if (sw_sg_builder_add_adjacency(b, face0 + (uint32_t)(pairs[k] >> 32),
                                        face0 + (uint32_t)pairs[k]) == SW_SG_NONE)
            res = SW_ERR_OUT_OF_MEMORY;
    }
    sw__free(pairs);
    return res;
}

sw_result sw_sg_tspline_add_to_builder(sw_sg_builder *b, const sw_sg_tspline *ts, uint32_t parent,
                                       const double xform[12], const float color[4],
                                       const char *name, uint32_t *node_out, sw_status *status)
{
    assert(b && ts);
    sw_sg_tspline_bezier bz;
    sw_result r = sw_sg_tspline_extract_bezier(ts, &bz, status);
    if (r != SW_OK)
        return r;
    const sw_sg_node_kind kind = xform ? SW_SG_NODE_TRANSFORM : SW_SG_NODE_GROUP;
    const uint32_t group = sw_sg_builder_add_node(b, kind, parent, 0, xform, color, name);
    const uint32_t face0 = sw_sg_builder_face_count(b);
    for (uint32_t k = 0; k < bz.n_patches && group != SW_SG_NONE && r == SW_OK; k++) {
        const uint32_t f = add_face(b, &bz.patches[k]);
        if (f == SW_SG_NONE ||
            sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, group, f, NULL, NULL, NULL) == SW_SG_NONE)
            r = SW_ERR_OUT_OF_MEMORY;
    }
    if (group == SW_SG_NONE)
        r = SW_ERR_OUT_OF_MEMORY;
    if (r == SW_OK)
        r = add_adjacency(b, sw_sg_tspline_view_ptr(ts), face0);
    sw_sg_tspline_bezier_free(&bz);
    if (r != SW_OK)
        return sw__fail(status, r, "T-spline %s: out of memory adding faces", name ? name : "");
    if (node_out)
        *node_out = group;
    sw__status_ok(status);
    return SW_OK;
}

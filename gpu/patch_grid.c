/* SPDX-License-Identifier: MIT */
/* CPU grid tessellation of a face occurrence's rational Bézier patches (Guthe et al. 2005 §4.2's
 * grids, evaluated on the CPU in double in this slice; densities from the Filip bound, §5.2,
 * chosen by the caller). Every patch column has one u-density and every row one v-density, so
 * neighbouring grids meet vertex to vertex; the shared edge vertices are evaluated once and reused
 * by index, so a face's grids have no T-junctions and no cracks, without §7.1's line strips.
 * Positions leave in float relative to the eye (ARCHITECTURE.md: precision).
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sw__gpu_mesh_free(sw__gpu_mesh *m)
{
    sw__free(m->v);
    sw__free(m->idx);
    memset(m, 0, sizeof *m);
}

sw_result sw__gpu_mesh_reserve(sw__gpu_mesh *m, size_t more_v, size_t more_idx, sw_status *status)
{
    if (m->n_v + more_v > UINT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "frame needs more than 2^32 grid vertices");
    if (!sw__grow((void **)&m->v, &m->cap_v, m->n_v + more_v, sizeof *m->v) ||
        !sw__grow((void **)&m->idx, &m->cap_idx, m->n_idx + more_idx, sizeof *m->idx))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid buffers: out of memory");
    return SW_OK;
}

/* Bernstein basis of degree p at s and its derivative (de Casteljau-style recurrence). */
static void bernstein(int32_t p, double s, double *b, double *db)
{
    double t[SW_SG_MAX_DEGREE + 1];
    t[0] = 1.0;
    for (int32_t r = 1; r < p; ++r) { /* degree p - 1 */
        t[r] = s * t[r - 1];
        for (int32_t i = r - 1; i > 0; --i)
            t[i] = (1.0 - s) * t[i] + s * t[i - 1];
        t[0] *= 1.0 - s;
    }
    for (int32_t i = 0; i <= p; ++i) {
        double lo = i > 0 ? t[i - 1] : 0.0, hi = i < p ? t[i] : 0.0;
        db[i] = p * (lo - hi);
        b[i] = (1.0 - s) * hi + s * lo;
    }
}

/* Homogeneous value and first partials of a patch at (s, t): h[0..3], h[4..7] d/ds, h[8..11] d/dt.
 */
static void eval_h1(const sw__gpu_patch *pt, double s, double t, double h[12])
{
    double bu[SW_SG_MAX_DEGREE + 1], dbu[SW_SG_MAX_DEGREE + 1];
    double bv[SW_SG_MAX_DEGREE + 1], dbv[SW_SG_MAX_DEGREE + 1];
    bernstein(pt->deg_u, s, bu, dbu);
    bernstein(pt->deg_v, t, bv, dbv);
    memset(h, 0, 12 * sizeof *h);
    for (int32_t j = 0; j <= pt->deg_v; ++j) {
        for (int32_t i = 0; i <= pt->deg_u; ++i) {
            const double *c = pt->cpw + ((size_t)j * (size_t)(pt->deg_u + 1) + (size_t)i) * 4;
            for (int k = 0; k < 4; ++k) {
                h[k] += bu[i] * bv[j] * c[k];
                h[4 + k] += dbu[i] * bv[j] * c[k];
                h[8 + k] += bu[i] * dbv[j] * c[k];
            }
        }
    }
}

/* Normal direction (S_s x S_t scaled by w^4 > 0) from the homogeneous form; 0 if degenerate. */
static double normal_from_h(const double h[12], double n[3])
{
    double ds[3], dt[3];
    sw_sg_h1_tangents(h, ds, dt, n);
    double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double ls = sqrt(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2]);
    double lt = sqrt(dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2]);
    return ln > 1e-12 * ls * lt ? ln : 0.0;
}

static void write_vertex(const sw__gpu_patch *pt, double s, double t, const double h[12],
                         double sign, const double uv_box[4], sw__gpu_vertex *out)
{
    double n[3];
    if (normal_from_h(h, n) == 0.0) {
        /* A collapsed edge (pole) has no normal: take it just inside the patch instead. */
        double hh[12];
        eval_h1(pt, s + 1e-4 * (0.5 - s), t + 1e-4 * (0.5 - t), hh);
        normal_from_h(hh, n);
    }
    for (int k = 0; k < 3; ++k) {
        out->pos[k] = (float)(h[k] / h[3]);
        out->nrm[k] = (float)(sign * n[k]);
    }
    double nl = sqrt((double)out->nrm[0] * out->nrm[0] + (double)out->nrm[1] * out->nrm[1] +
                     (double)out->nrm[2] * out->nrm[2]);
    if (nl > 0.0 && isfinite(nl))
        for (int k = 0; k < 3; ++k)
            out->nrm[k] = (float)(out->nrm[k] / nl);
    double u = pt->u0 + s * (pt->u1 - pt->u0), v = pt->v0 + t * (pt->v1 - pt->v0);
    out->st[0] = (float)((u - uv_box[0]) / (uv_box[1] - uv_box[0]));
    out->st[1] = (float)((v - uv_box[2]) / (uv_box[3] - uv_box[2]));
}

static double sample_at(double a, double b, int32_t k, int32_t n)
{
    return k == n ? b : a + (b - a) * (double)k / (double)n;
}

/* Fills idx (nu+1)(nv+1) for patch pt: shared edge vertices from the left / bottom neighbours'
 * index arrays, the rest evaluated and appended. */
static void patch_vertices(const sw__gpu_patch *pt, const uint32_t *left, int32_t left_nu,
                           const uint32_t *below, int32_t below_nv, double sign,
                           const double uv_box[4], sw__gpu_mesh *mesh, uint32_t *idx)
{
    int32_t nu = pt->nu, nv = pt->nv, stride = nu + 1;
    for (int32_t l = 0; l <= nv; ++l) {
        double t = sample_at(pt->t0, pt->t1, l, nv);
        for (int32_t k = 0; k <= nu; ++k) {
            uint32_t *dst = &idx[(size_t)l * (size_t)stride + (size_t)k];
            if (k == 0 && left) {
                *dst = left[(size_t)l * (size_t)(left_nu + 1) + (size_t)left_nu];
                continue;
            }
            if (l == 0 && below) {
                *dst = below[(size_t)below_nv * (size_t)stride + (size_t)k];
                continue;
            }
            double s = sample_at(pt->s0, pt->s1, k, nu), h[12];
            eval_h1(pt, s, t, h);
            write_vertex(pt, s, t, h, sign, uv_box, &mesh->v[mesh->n_v]);
            *dst = (uint32_t)mesh->n_v++;
        }
    }
}

static void patch_triangles(const sw__gpu_patch *pt, const uint32_t *idx, sw__gpu_mesh *mesh)
{
    int32_t stride = pt->nu + 1;
    uint32_t *o = mesh->idx + mesh->n_idx;
    for (int32_t l = 0; l < pt->nv; ++l) {
        for (int32_t k = 0; k < pt->nu; ++k) {
            const uint32_t *c = idx + (size_t)l * (size_t)stride + (size_t)k;
            uint32_t a = c[0], b = c[1], d = c[stride], e = c[stride + 1];
            o[0] = a, o[1] = b, o[2] = e, o[3] = a, o[4] = e, o[5] = d;
            o += 6;
        }
    }
    mesh->n_idx = (size_t)(o - mesh->idx);
}

sw_result sw__gpu_tessellate_face(const sw__gpu_patch *patches, int32_t n_cols, int32_t n_rows,
                                  double normal_sign, const double uv_box[4], sw__gpu_mesh *mesh,
                                  sw_status *status)
{
    size_t n = (size_t)n_cols * (size_t)n_rows, need_v = 0, need_i = 0;
    for (size_t p = 0; p < n; ++p) {
        if (!patches[p].visible)
            continue;
        need_v += (size_t)(patches[p].nu + 1) * (size_t)(patches[p].nv + 1);
        need_i += (size_t)patches[p].nu * (size_t)patches[p].nv * 6;
    }
    sw_result r = sw__gpu_mesh_reserve(mesh, need_v, need_i, status);
    if (r != SW_OK)
        return r;
    uint32_t **idx = sw__calloc(n ? n : 1, sizeof *idx);
    if (!idx)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid indices: out of memory");
    for (int32_t b = 0; b < n_rows && r == SW_OK; ++b) {
        for (int32_t a = 0; a < n_cols; ++a) {
            size_t p = (size_t)b * (size_t)n_cols + (size_t)a;
            const sw__gpu_patch *pt = &patches[p];
            if (!pt->visible)
                continue;
            idx[p] = sw__malloc((size_t)(pt->nu + 1) * (size_t)(pt->nv + 1) * sizeof **idx);
            if (!idx[p]) {
                r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid indices: out of memory");
                break;
            }
            const uint32_t *left = a > 0 ? idx[p - 1] : NULL;
            const uint32_t *below = b > 0 ? idx[p - (size_t)n_cols] : NULL;
            int32_t left_nu = left ? patches[p - 1].nu : 0;
            int32_t below_nv = below ? patches[p - (size_t)n_cols].nv : 0;
            patch_vertices(pt, left, left_nu, below, below_nv, normal_sign, uv_box, mesh, idx[p]);
            patch_triangles(pt, idx[p], mesh);
        }
    }
    for (size_t p = 0; p < n; ++p)
        sw__free(idx[p]);
    sw__free(idx);
    return r;
}

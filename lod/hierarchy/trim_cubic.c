/* SPDX-License-Identifier: MIT */
/* Trim curves approximated by rational cubic Bézier pieces with a rigorous error bound, Guthe et
 * al. 2005 §4.1 ("similarly to the bi-cubic approximation of the surfaces we approximate the
 * trimming curves with rational cubic Bézier curves"): Bézier segments by knot insertion, each
 * reduced by the §6.1 fit (degree_reduce.c; a curve is a net with deg_v = 0) or elevated exactly
 * when its degree is <= 3, and halved until the bound of error_bound.c meets the tolerance.
 */
#include "sw_lod_reduce.h"
#include "sw_hooks.h"

#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <stdlib.h>
#include <string.h>

/* Raises every knot of the domain to multiplicity >= degree, one distinct value at a time. */
static sw_result refine_to_bezier(const sw_sg_curve *c, double **knots_io, double **cpw_io,
                                  int32_t *n_io, sw_status *status)
{
    double t0, t1;
    sw_sg_knots_domain(c->knots, c->degree, c->n, &t0, &t1);
    const int32_t p = c->degree, dim = c->dim;
    for (int32_t k = 0; k < *n_io + p + 1;) {
        const double *kn = *knots_io;
        const double t = kn[k];
        int32_t mult = 1;
        while (k + mult < *n_io + p + 1 && kn[k + mult] == t)
            ++mult;
        if (t < t0 || t > t1 || mult >= p) {
            k += mult;
            continue;
        }
        const int32_t times = p - mult, n = *n_io;
        double *nk = sw__malloc((size_t)(n + p + 1 + times) * sizeof *nk);
        double *nc = sw__malloc((size_t)(n + times) * (size_t)dim * sizeof *nc);
        if (!nk || !nc) {
            sw__free(nk);
            sw__free(nc);
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim curve: knot insertion");
        }
        const sw_sg_curve cur = {p, n, dim, *knots_io, *cpw_io};
        sw_sg_curve_insert_knot(&cur, t, times, nk, nc);
        sw__free(*knots_io);
        sw__free(*cpw_io);
        *knots_io = nk;
        *cpw_io = nc;
        *n_io = n + times;
        k += mult + times;
    }
    return SW_OK;
}

sw_result sw_lod_curve_bezier_segments(const sw_sg_curve *c, double **cpw_out, double **breaks_out,
                                       int32_t *n_seg, sw_status *status)
{
    const int32_t p = c->degree, dim = c->dim;
    int32_t n = c->n;
    double *kn = sw__malloc((size_t)(n + p + 1) * sizeof *kn);
    double *cp = sw__malloc((size_t)n * (size_t)dim * sizeof *cp);
    *cpw_out = NULL;
    *breaks_out = NULL;
    *n_seg = 0;
    if (!kn || !cp) {
        sw__free(kn);
        sw__free(cp);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim curve: %d control points", (int)n);
    }
    memcpy(kn, c->knots, (size_t)(n + p + 1) * sizeof *kn);
    memcpy(cp, c->cpw, (size_t)n * (size_t)dim * sizeof *cp);
    sw_result res = refine_to_bezier(c, &kn, &cp, &n, status);
    double *seg = NULL, *brk = NULL;
    if (res == SW_OK) {
        seg = sw__malloc((size_t)n * (size_t)(p + 1) * (size_t)dim * sizeof *seg);
        brk = sw__malloc((size_t)(n + 1) * sizeof *brk);
        if (!seg || !brk)
            res = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim curve: segments");
    }
    int32_t count = 0;
    for (int32_t k = p; res == SW_OK && k < n; ++k) {
        if (!(kn[k] < kn[k + 1]))
            continue;
        memcpy(seg + (size_t)count * (size_t)(p + 1) * (size_t)dim,
               cp + (size_t)(k - p) * (size_t)dim, (size_t)(p + 1) * (size_t)dim * sizeof *seg);
        brk[count] = kn[k];
        brk[count + 1] = kn[k + 1];
        ++count;
    }
    sw__free(kn);
    sw__free(cp);
    if (res != SW_OK) {
        sw__free(seg);
        sw__free(brk);
        return res;
    }
    *cpw_out = seg;
    *breaks_out = brk;
    *n_seg = count;
    sw__status_ok(status);
    return SW_OK;
}

static sw_result push_piece(sw_lod_cubic_set *s, const sw_lod_cubic_piece *p, sw_status *status)
{
    if (s->count == s->cap) {
        int32_t cap = s->cap ? 2 * s->cap : 16;
        sw_lod_cubic_piece *grown = sw__realloc(s->pieces, (size_t)cap * sizeof *grown);
        if (!grown)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim curve: %d pieces", (int)cap);
        s->pieces = grown;
        s->cap = cap;
    }
    s->pieces[s->count++] = *p;
    return SW_OK;
}

/* One Bézier segment over [t0, t1] of the source: reduce, bound, halve while needed. */
static sw_result approx_segment(int32_t deg, const double *cpw, double t0, double t1, int32_t depth,
                                const sw_lod_reduce_desc *desc, int32_t max_depth,
                                sw_lod_cubic_set *out, sw_status *status)
{
    sw_lod_cubic_piece pc = {t0, t1, {0.0}, 0.0};
    sw_lod_reduce_cubic_curve(deg, 3, cpw, pc.cpw, NULL);
    sw_lod_error_result er;
    sw_result res = sw_lod_error_bound(3, deg, 0, cpw, 3, 0, pc.cpw, &desc->error, &er, status);
    if (res != SW_OK)
        return res;
    pc.error = er.bound;
    if (!(er.bound > desc->tolerance) || depth >= max_depth) {
        if (er.bound > desc->tolerance)
            ++out->over_tolerance;
        return push_piece(out, &pc, status);
    }
    double halves[2 * (SW_SG_MAX_DEGREE + 1) * 3];
    const size_t n = (size_t)(deg + 1) * 3;
    sw_lod_bez_subdivide(deg, 0, 3, cpw, 0, 0.5, halves, halves + n);
    const double tm = 0.5 * (t0 + t1);
    res = approx_segment(deg, halves, t0, tm, depth + 1, desc, max_depth, out, status);
    if (res == SW_OK)
        res = approx_segment(deg, halves + n, tm, t1, depth + 1, desc, max_depth, out, status);
    return res;
}

sw_result sw_lod_trim_curve_to_cubics(const sw_sg_curve *c, const sw_lod_reduce_desc *desc,
                                      sw_lod_cubic_set *out, sw_status *status)
{
    memset(out, 0, sizeof *out);
    if (c->dim != 3)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "trim curve: dimension %d, expected 3",
                        (int)c->dim);
    double *seg, *brk;
    int32_t n_seg;
    sw_result res = sw_lod_curve_bezier_segments(c, &seg, &brk, &n_seg, status);
    if (res != SW_OK)
        return res;
    const int32_t max_depth = desc->max_depth > 0 ? desc->max_depth : 12;
    const size_t stride = (size_t)(c->degree + 1) * 3;
    for (int32_t k = 0; k < n_seg && res == SW_OK; ++k)
        res = approx_segment(c->degree, seg + (size_t)k * stride, brk[k], brk[k + 1], 0, desc,
                             max_depth, out, status);
    sw__free(seg);
    sw__free(brk);
    if (res == SW_OK)
        sw__status_ok(status);
    return res;
}

void sw_lod_cubic_set_free(sw_lod_cubic_set *set)
{
    if (!set)
        return;
    sw__free(set->pieces);
    memset(set, 0, sizeof *set);
}

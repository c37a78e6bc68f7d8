/* SPDX-License-Identifier: MIT */
/* T-spline surfaces: creation from point-based data, Krishnamurthy & Yasui's region
 * decomposition ("T-splines evaluation": the domain is cut wherever any blending function has a
 * knot line, each region keeps the list of control points that influence it, and a parameter finds
 * its region by binary search), and evaluation, both direct (every point; Sederberg et al. 2003
 * eq. 1) and through the regions.
 *
 * Regions are built on the grid of all distinct knot values inside the domain: a cell edge is
 * "covered" when it lies on a knot line segment of some blending function (its five lines in u
 * over its support in v, and vice versa). Cells are merged into rectangles across uncovered edges
 * only, so each blending function is a single polynomial on every region, which is what makes one
 * rational bicubic Bézier patch per region exact (tspline_bezier.c).
 */
#include "sw_sg_tspline.h"
#include "sw_hooks.h"
#include "sw_status_util.h"
#include "sw_sg_tspline_internal.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sw_sg_tspline {
    sw_sg_tspline_view v;
    double *cpw, *ku, *kv, *bu, *bv;
    uint32_t *cell_region, *region_points;
    sw_sg_tspline_region *regions;
};

/* ---- basis functions ------------------------------------------------------------------------ */

double sw_sg_tspline_basis(const double k[5], double t, int closed_right)
{
    double n[4];
    for (int j = 0; j < 4; j++) {
        const int in = closed_right ? (k[j] < t && t <= k[j + 1]) : (k[j] <= t && t < k[j + 1]);
        n[j] = in ? 1.0 : 0.0;
    }
    /* Cox-de Boor on the five local knots; 0/0 terms of repeated knots are zero. */
    for (int p = 1; p <= 3; p++) {
        for (int j = 0; j + p <= 3; j++) {
            const double dl = k[j + p] - k[j], dr = k[j + p + 1] - k[j + 1];
            const double left = dl > 0.0 ? (t - k[j]) / dl * n[j] : 0.0;
            const double right = dr > 0.0 ? (k[j + p + 1] - t) / dr * n[j + 1] : 0.0;
            n[j] = left + right;
        }
    }
    return n[0];
}

static int multiplicity(const double *k, int m, double t)
{
    int s = 0;
    for (int j = 0; j < m; j++)
        s += k[j] == t;
    return s;
}

/* Bernstein coefficients on [a, b] (inside [k0, k4], a < b, no knot strictly inside) of the cubic
 * B-spline on k[0..4] (Sederberg et al. 2004 §3: refine the blending function by Boehm insertion
 * of a and b to multiplicity 3; the four coefficients between them are its Bézier form). */
void sw__tspline_bernstein(const double k[5], double a, double b, double out[4])
{
    /* Pad to a clamped knot vector: N = the L-th basis function with coefficients e_L. */
    const int L = 4 - multiplicity(k, 5, k[0]), R = 4 - multiplicity(k, 5, k[4]);
    double kn[3][17], c[3][13];
    int m = 0;
    for (int j = 0; j < L; j++)
        kn[0][m++] = k[0];
    for (int j = 0; j < 5; j++)
        kn[0][m++] = k[j];
    for (int j = 0; j < R; j++)
        kn[0][m++] = k[4];
    int n = m - 4;
    for (int j = 0; j < n; j++)
        c[0][j] = j == L ? 1.0 : 0.0;

    int cur = 0;
    const double ends[2] = {a, b};
    for (int e = 0; e < 2; e++) {
        const double x = ends[e];
        const int times = 3 - multiplicity(kn[cur], m, x);
        if (x <= k[0] || x >= k[4] || times <= 0)
            continue;
        const sw_sg_curve crv = {3, n, 1, kn[cur], c[cur]};
        sw_sg_curve_insert_knot(&crv, x, times, kn[cur + 1], c[cur + 1]);
        cur++;
        m += times;
        n += times;
    }
    /* The span [a, b): last knot index r with kn[r] <= a; its points r-3..r are the Bézier ones. */
    int r = 3;
    while (r + 1 < n && kn[cur][r + 1] <= a)
        r++;
    for (int i = 0; i < 4; i++)
        out[i] = c[cur][r - 3 + i];
}

/* ---- lookups ----------------------------------------------------------------------------------
 */

/* First index with b[i] >= x in sorted b[0..n-1] (n if none). */
static uint32_t lower_bound(const double *b, uint32_t n, double x)
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

/* Cell of x: b[a] <= x < b[a+1], the last cell closed (x already clamped). */
static uint32_t find_cell(const double *b, uint32_t n, double x)
{
    uint32_t lo = 0,
             hi = n - 1; /* invariant: b[lo] <= x, and x < b[hi] or hi is the last cell end */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (x < b[mid])
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

static double clampd(double x, double lo, double hi)
{
    if (!(x > lo)) /* NaN goes to the lower end too */
        return lo;
    return x < hi ? x : hi;
}

/* Cells [*c0, *c1) of the sorted boundaries b[0..n-1] inside the interval [k0, k4]. */
static void support_cells(const double *b, uint32_t n, double k0, double k4, uint32_t *c0,
                          uint32_t *c1)
{
    *c0 = lower_bound(b, n, k0);
    uint32_t e = lower_bound(b, n, k4);
    if (e == n || b[e] > k4)
        e = e ? e - 1 : 0; /* k4 beyond the domain or between boundaries: last boundary below */
    *c1 = e > *c0 ? e : *c0;
}

/* ---- creation ---------------------------------------------------------------------------------
 */

static sw_result check_point(const sw_sg_tspline_desc *d, uint32_t i, const char *what,
                             sw_status *status)
{
    const double *p = d->cpw + (size_t)i * 4;
    for (int c = 0; c < 4; c++)
        if (!isfinite(p[c]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: point %u: non-finite coordinate",
                            what, i);
    if (!(p[3] > 0.0))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: point %u: weight %g is not positive",
                        what, i, p[3]);
    const double *ks[2] = {d->knots_u + (size_t)i * 5, d->knots_v + (size_t)i * 5};
    for (int dir = 0; dir < 2; dir++) {
        for (int j = 0; j < 5; j++)
            if (!isfinite(ks[dir][j]) || (j && ks[dir][j] < ks[dir][j - 1]))
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "%s: point %u: knot %d in %c is not finite or decreases", what, i,
                                j, "uv"[dir]);
        if (!(ks[dir][0] < ks[dir][4]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: point %u: empty support in %c (all five knots equal)", what, i,
                            "uv"[dir]);
    }
    return SW_OK;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorted distinct knot values strictly inside (lo, hi), plus lo and hi. */
static double *boundaries(const double *knots, uint32_t n_points, double lo, double hi,
                          uint32_t *count)
{
    double *b = sw__malloc(sizeof(double) * ((size_t)n_points * 5 + 2));
    if (!b)
        return NULL;
    size_t m = 0;
    b[m++] = lo;
    b[m++] = hi;
    for (size_t j = 0; j < (size_t)n_points * 5; j++)
        if (knots[j] > lo && knots[j] < hi)
            b[m++] = knots[j];
    qsort(b, m, sizeof(double), cmp_double);
    size_t u = 1;
    for (size_t j = 1; j < m; j++)
        if (b[j] != b[u - 1])
            b[u++] = b[j];
    *count = (uint32_t)u;
    return b;
}

/* Marks the cell edges that lie on a knot line of some blending function. vcov[a * nvc + b]:
 * edge at u = bu[a] of cell row b; hcov[b * nuc + a]: edge at v = bv[b] of cell column a. */
static void mark_knot_lines(const sw_sg_tspline *ts, unsigned char *vcov, unsigned char *hcov)
{
    const sw_sg_tspline_view *v = &ts->v;
    const uint32_t nuc = v->n_bu - 1, nvc = v->n_bv - 1;
    for (uint32_t i = 0; i < v->n_points; i++) {
        const double *ku = v->knots_u + (size_t)i * 5, *kv = v->knots_v + (size_t)i * 5;
        uint32_t a0, a1, b0, b1;
        support_cells(v->bu, v->n_bu, ku[0], ku[4], &a0, &a1);
        support_cells(v->bv, v->n_bv, kv[0], kv[4], &b0, &b1);
        if (a0 == a1 || b0 == b1)
            continue;
        for (int j = 0; j < 5; j++) {
            if (ku[j] > v->domain[0] && ku[j] < v->domain[1]) {
                const uint32_t a = lower_bound(v->bu, v->n_bu, ku[j]);
                for (uint32_t b = b0; b < b1; b++)
                    vcov[(size_t)a * nvc + b] = 1;
            }
            if (kv[j] > v->domain[2] && kv[j] < v->domain[3]) {
                const uint32_t b = lower_bound(v->bv, v->n_bv, kv[j]);
                for (uint32_t a = a0; a < a1; a++)
                    hcov[(size_t)b * nuc + a] = 1;
            }
        }
    }
}

/* Merges cells into rectangles: runs along u between covered edges, stacked in v while the run
 * below has the same extent and the edge between them is uncovered. */
static sw_result merge_cells(sw_sg_tspline *ts, const unsigned char *vcov,
                             const unsigned char *hcov)
{
    const uint32_t nuc = ts->v.n_bu - 1, nvc = ts->v.n_bv - 1;
    uint32_t n = 0, cap = 64;
    sw_sg_tspline_region *rg = sw__malloc(sizeof *rg * cap);
    if (!rg)
        return SW_ERR_OUT_OF_MEMORY;
    for (uint32_t b = 0; b < nvc; b++) {
        for (uint32_t a = 0; a < nuc;) {
            uint32_t a1 = a + 1;
            while (a1 < nuc && !vcov[(size_t)a1 * nvc + b])
                a1++;
            uint32_t r = UINT32_MAX;
            if (b > 0) {
                const uint32_t below = ts->cell_region[(size_t)(b - 1) * nuc + a];
                const sw_sg_tspline_region *q = &rg[below];
                int open = q->u0 == ts->v.bu[a] && q->u1 == ts->v.bu[a1] && q->v1 == ts->v.bv[b];
                for (uint32_t c = a; open && c < a1; c++)
                    open = !hcov[(size_t)b * nuc + c];
                if (open)
                    r = below;
            }
            if (r == UINT32_MAX) {
                if (n == cap) {
                    cap *= 2;
                    sw_sg_tspline_region *g = sw__realloc(rg, sizeof *rg * cap);
                    if (!g) {
                        sw__free(rg);
                        return SW_ERR_OUT_OF_MEMORY;
                    }
                    rg = g;
                }
                r = n++;
                rg[r] = (sw_sg_tspline_region){ts->v.bu[a], ts->v.bu[a1], ts->v.bv[b], 0, 0, 0};
            }
            rg[r].v1 = ts->v.bv[b + 1];
            for (uint32_t c = a; c < a1; c++)
                ts->cell_region[(size_t)b * nuc + c] = r;
            a = a1;
        }
    }
    ts->regions = rg;
    ts->v.regions = rg;
    ts->v.n_regions = n;
    return SW_OK;
}

/* Region point lists (CSR): pass 0 counts, pass 1 fills; `stamp` dedupes a point's regions. */
static sw_result list_region_points(sw_sg_tspline *ts, uint64_t total)
{
    sw_sg_tspline_view *v = &ts->v;
    const uint32_t nuc = v->n_bu - 1;
    uint32_t *stamp = sw__malloc(sizeof(uint32_t) * v->n_regions);
    ts->region_points = sw__malloc(sizeof(uint32_t) * (total ? total : 1));
    if (!stamp || !ts->region_points) {
        sw__free(stamp);
        return SW_ERR_OUT_OF_MEMORY;
    }
    for (int pass = 0; pass < 2; pass++) {
        memset(stamp, 0xff, sizeof(uint32_t) * v->n_regions);
        for (uint32_t i = 0; i < v->n_points; i++) {
            uint32_t a0, a1, b0, b1;
            support_cells(v->bu, v->n_bu, v->knots_u[(size_t)i * 5], v->knots_u[(size_t)i * 5 + 4],
                          &a0, &a1);
            support_cells(v->bv, v->n_bv, v->knots_v[(size_t)i * 5], v->knots_v[(size_t)i * 5 + 4],
                          &b0, &b1);
            for (uint32_t b = b0; b < b1; b++) {
                for (uint32_t a = a0; a < a1; a++) {
                    const uint32_t r = ts->cell_region[(size_t)b * nuc + a];
                    if (stamp[r] == i)
                        continue;
                    stamp[r] = i;
                    if (pass == 0)
                        ts->regions[r].count++;
                    else
                        ts->region_points[ts->regions[r].first + ts->regions[r].count++] = i;
                }
            }
        }
        if (pass == 0) {
            uint32_t first = 0;
            for (uint32_t r = 0; r < v->n_regions; r++) {
                ts->regions[r].first = first;
                first += ts->regions[r].count;
                ts->regions[r].count = 0;
            }
        }
    }
    sw__free(stamp);
    v->region_points = ts->region_points;
    return SW_OK;
}

/* Every region must have a denominator sum w_i B_i > 0 everywhere: all Bernstein coefficients of
 * the weight positive (they are >= min w_i where the blending functions sum to one). And the
 * region's Bézier patch is a face of the scene: it must pass the scene's own check
 * (sw_sg_surface_validate), so that a file the scene would refuse is refused naming the file
 * (points and weights within range blend into 1e17 weights and 1e98 coordinates where knots
 * nearly meet). */
static sw_result check_regions(const sw_sg_tspline *ts, const char *what, sw_status *status)
{
    static const double bezier_knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    const sw_sg_tspline_view *v = &ts->v;
    for (uint32_t r = 0; r < v->n_regions; r++) {
        const sw_sg_tspline_region *g = &v->regions[r];
        double cpw[64] = {0};
        for (uint32_t k = 0; k < g->count; k++) {
            const uint32_t i = v->region_points[g->first + k];
            double bu[4], bv[4];
            sw__tspline_bernstein(v->knots_u + (size_t)i * 5, g->u0, g->u1, bu);
            sw__tspline_bernstein(v->knots_v + (size_t)i * 5, g->v0, g->v1, bv);
            for (int l = 0; l < 4; l++)
                for (int j = 0; j < 4; j++)
                    for (int c = 0; c < 4; c++)
                        cpw[(l * 4 + j) * 4 + c] += v->cpw[(size_t)i * 4 + c] * bu[j] * bv[l];
        }
        for (int j = 0; j < 16; j++)
            if (!(cpw[j * 4 + 3] > 0.0))
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "%s: region [%g, %g] x [%g, %g]: the blending functions vanish "
                                "(%u influencing points); the T-mesh does not cover the domain",
                                what, g->u0, g->u1, g->v0, g->v1, g->count);
        char region[160];
        snprintf(region, sizeof region, "%s: region [%g, %g] x [%g, %g]", what, g->u0, g->u1, g->v0,
                 g->v1);
        const sw_sg_surface patch = {3, 3, 4, 4, bezier_knots, bezier_knots, cpw};
        const sw_result res = sw_sg_surface_validate(&patch, region, status);
        if (res != SW_OK)
            return res;
    }
    return SW_OK;
}

static sw_result check_desc(const sw_sg_tspline_desc *d, const char *what, sw_status *status)
{
    if (d->n_points == 0)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: no control points", what);
    if (d->n_points > SW_SG_TSPLINE_MAX_POINTS)
        return sw__fail(status, SW_ERR_LIMIT, "%s: %u control points (at most %u)", what,
                        d->n_points, SW_SG_TSPLINE_MAX_POINTS);
    const double *dm = d->domain;
    for (int c = 0; c < 4; c++)
        if (!isfinite(dm[c]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: non-finite domain", what);
    if (!(dm[0] < dm[1]) || !(dm[2] < dm[3]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: empty domain [%g, %g] x [%g, %g]",
                        what, dm[0], dm[1], dm[2], dm[3]);
    for (uint32_t i = 0; i < d->n_points; i++) {
        sw_result r = check_point(d, i, what, status);
        if (r != SW_OK)
            return r;
    }
    return SW_OK;
}

static sw_result copy_desc(sw_sg_tspline *ts, const sw_sg_tspline_desc *d)
{
    const size_t n = d->n_points;
    ts->cpw = sw__malloc(sizeof(double) * n * 4);
    ts->ku = sw__malloc(sizeof(double) * n * 5);
    ts->kv = sw__malloc(sizeof(double) * n * 5);
    if (!ts->cpw || !ts->ku || !ts->kv)
        return SW_ERR_OUT_OF_MEMORY;
    memcpy(ts->cpw, d->cpw, sizeof(double) * n * 4);
    memcpy(ts->ku, d->knots_u, sizeof(double) * n * 5);
    memcpy(ts->kv, d->knots_v, sizeof(double) * n * 5);
    ts->v.n_points = d->n_points;
    ts->v.cpw = ts->cpw, ts->v.knots_u = ts->ku, ts->v.knots_v = ts->kv;
    memcpy(ts->v.domain, d->domain, sizeof ts->v.domain);
    return SW_OK;
}

/* Sum over points of the cells their supports cover, stopping past the limit. */
static uint64_t support_cell_total(const sw_sg_tspline *ts)
{
    const sw_sg_tspline_view *v = &ts->v;
    uint64_t total = 0;
    for (uint32_t i = 0; i < v->n_points && total <= SW_SG_TSPLINE_MAX_SUPPORT_CELLS; i++) {
        uint32_t a0, a1, b0, b1;
        support_cells(v->bu, v->n_bu, v->knots_u[(size_t)i * 5], v->knots_u[(size_t)i * 5 + 4], &a0,
                      &a1);
        support_cells(v->bv, v->n_bv, v->knots_v[(size_t)i * 5], v->knots_v[(size_t)i * 5 + 4], &b0,
                      &b1);
        total += (uint64_t)(a1 - a0) * (b1 - b0);
    }
    return total;
}

static sw_result build_regions(sw_sg_tspline *ts, const char *what, sw_status *status)
{
    sw_sg_tspline_view *v = &ts->v;
    ts->bu = boundaries(ts->ku, v->n_points, v->domain[0], v->domain[1], &v->n_bu);
    ts->bv = boundaries(ts->kv, v->n_points, v->domain[2], v->domain[3], &v->n_bv);
    if (!ts->bu || !ts->bv)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    v->bu = ts->bu, v->bv = ts->bv;
    const uint64_t cells = (uint64_t)(v->n_bu - 1) * (v->n_bv - 1);
    if (cells > SW_SG_TSPLINE_MAX_CELLS)
        return sw__fail(status, SW_ERR_LIMIT, "%s: %llu knot grid cells (at most %u)", what,
                        (unsigned long long)cells, SW_SG_TSPLINE_MAX_CELLS);
    const uint64_t total = support_cell_total(ts);
    if (total > SW_SG_TSPLINE_MAX_SUPPORT_CELLS)
        return sw__fail(status, SW_ERR_LIMIT, "%s: supports cover more than %u cells", what,
                        SW_SG_TSPLINE_MAX_SUPPORT_CELLS);
    unsigned char *vcov = sw__calloc((size_t)v->n_bu * (v->n_bv - 1), 1);
    unsigned char *hcov = sw__calloc((size_t)v->n_bv * (v->n_bu - 1), 1);
    ts->cell_region = sw__malloc(sizeof(uint32_t) * cells);
    sw_result r = vcov && hcov && ts->cell_region ? SW_OK : SW_ERR_OUT_OF_MEMORY;
    if (r == SW_OK) {
        v->cell_region = ts->cell_region;
        mark_knot_lines(ts, vcov, hcov);
        r = merge_cells(ts, vcov, hcov);
    }
    sw__free(vcov);
    sw__free(hcov);
    if (r == SW_OK)
        r = list_region_points(ts, total);
    if (r != SW_OK)
        return sw__fail(status, r, "%s: out of memory", what);
    return check_regions(ts, what, status);
}

sw_result sw_sg_tspline_create(const sw_sg_tspline_desc *desc, const char *what,
                               sw_sg_tspline **out, sw_status *status)
{
    assert(desc && out);
    *out = NULL;
    if (!what)
        what = "T-spline";
    sw_result r = check_desc(desc, what, status);
    if (r != SW_OK)
        return r;
    sw_sg_tspline *ts = sw__calloc(1, sizeof *ts);
    if (!ts || copy_desc(ts, desc) != SW_OK) {
        sw_sg_tspline_free(ts);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    }
    r = build_regions(ts, what, status);
    if (r != SW_OK) {
        sw_sg_tspline_free(ts);
        return r;
    }
    *out = ts;
    sw__status_ok(status);
    return SW_OK;
}

void sw_sg_tspline_free(sw_sg_tspline *ts)
{
    if (!ts)
        return;
    sw__free(ts->cpw);
    sw__free(ts->ku);
    sw__free(ts->kv);
    sw__free(ts->bu);
    sw__free(ts->bv);
    sw__free(ts->cell_region);
    sw__free(ts->region_points);
    sw__free(ts->regions);
    sw__free(ts);
}

const sw_sg_tspline_view *sw_sg_tspline_view_ptr(const sw_sg_tspline *ts)
{
    assert(ts);
    return &ts->v;
}

/* ---- evaluation -------------------------------------------------------------------------------
 */

double sw_sg_tspline_blend(const sw_sg_tspline *ts, uint32_t i, double u, double v)
{
    assert(ts && i < ts->v.n_points);
    const double *d = ts->v.domain;
    return sw_sg_tspline_basis(ts->v.knots_u + (size_t)i * 5, u, u >= d[1]) *
           sw_sg_tspline_basis(ts->v.knots_v + (size_t)i * 5, v, v >= d[3]);
}

/* Adds w_i B_i (P_i, 1) of point i to acc. */
static void accumulate(const sw_sg_tspline *ts, uint32_t i, double u, double v, int cu, int cv,
                       double acc[4])
{
    const double bu = sw_sg_tspline_basis(ts->v.knots_u + (size_t)i * 5, u, cu);
    if (bu == 0.0)
        return;
    const double b = bu * sw_sg_tspline_basis(ts->v.knots_v + (size_t)i * 5, v, cv);
    const double *p = ts->v.cpw + (size_t)i * 4;
    for (int c = 0; c < 4; c++)
        acc[c] += b * p[c];
}

static void project(const double acc[4], double p[3])
{
    for (int c = 0; c < 3; c++)
        p[c] = acc[c] / acc[3];
}

void sw_sg_tspline_eval_direct(const sw_sg_tspline *ts, double u, double v, double p[3])
{
    assert(ts && p);
    const double *d = ts->v.domain;
    u = clampd(u, d[0], d[1]);
    v = clampd(v, d[2], d[3]);
    double acc[4] = {0, 0, 0, 0};
    for (uint32_t i = 0; i < ts->v.n_points; i++)
        accumulate(ts, i, u, v, u >= d[1], v >= d[3], acc);
    project(acc, p);
}

uint32_t sw_sg_tspline_find_region(const sw_sg_tspline *ts, double u, double v)
{
    assert(ts);
    const sw_sg_tspline_view *w = &ts->v;
    u = clampd(u, w->domain[0], w->domain[1]);
    v = clampd(v, w->domain[2], w->domain[3]);
    const uint32_t a = find_cell(w->bu, w->n_bu, u), b = find_cell(w->bv, w->n_bv, v);
    return w->cell_region[(size_t)b * (w->n_bu - 1) + a];
}

void sw_sg_tspline_eval(const sw_sg_tspline *ts, double u, double v, double p[3])
{
    assert(ts && p);
    const sw_sg_tspline_view *w = &ts->v;
    u = clampd(u, w->domain[0], w->domain[1]);
    v = clampd(v, w->domain[2], w->domain[3]);
    const sw_sg_tspline_region *g = &w->regions[sw_sg_tspline_find_region(ts, u, v)];
    double acc[4] = {0, 0, 0, 0};
    for (uint32_t k = 0; k < g->count; k++)
        accumulate(ts, w->region_points[g->first + k], u, v, u >= w->domain[1], v >= w->domain[3],
                   acc);
    project(acc, p);
}

/* SPDX-License-Identifier: MIT */
/* Static LODs of a super-surface, Kumar et al. 1997 §4.1-§4.3: the adaptive trimmed tessellation
 * (level 0) and the chain of levels, simplified by modules/lodbuild/static_lod_openmesh.cpp and
 * each declared with a certified ε_k (declare_level). The faces' domains (cells, scalings,
 * flattened loops) are static_lod_domain.c's; static_lod_measure.c samples the distances the tests
 * check ε_k with.
 *
 * Level 0 within δ, and why it holds. δ is split: δ_tri = 3/4 δ for the triangles against the
 * surface over their own (u, v) triangles, δ_trim = 1/4 δ for the trim loops.
 *  - Triangles. A triangle T of the mesh lies in one patch (knot lines are constraints). With
 *    M_ss, M_st, M_tt bounds of |S_ss|, |S_st|, |S_tt| over the patch (local parameters,
 *    sw_lod_rational_bezier_bounds), every second directional derivative along a unit (d_s, d_t)
 *    obeys |S_dd| <= M_ss d_s^2 + 2 M_st |d_s d_t| + M_tt d_t^2 <= A^2 d_s^2 + B^2 d_t^2 with
 *    A^2 = M_ss + k M_st, B^2 = M_tt + M_st / k for any k > 0 (2|xy| <= k x^2 + y^2 / k). In the
 *    scaled coordinates (A s, B t) the Hessian is bounded by 1 in every direction, and Waldron's
 *    bound for linear interpolation on a simplex (SIAM J. Numer. Anal. 35, 1998) gives
 *    |S - L| <= R^2 / 2 with R the radius of the smallest disc containing T in those coordinates
 *    (applied to <S - L, e> for the unit e along the error at its maximum). k = sqrt(M_ss / M_tt)
 *    minimises the cell area. Kumar's §4.1 bound (l1^2 M1 + 2 l1 l2 M2 + l2^2 M3) / 8 holds for
 *    triangles with legs along the axes only; Waldron's holds for the arbitrary triangles a
 *    constrained triangulation makes.
 *  - Trim loops. Flattened so that every chord is within tol = δ_trim / G of the curve in (u, v)
 *    (sw_sg_trim_flatten_loop), where G bounds |S_u du + S_v dv| per unit (du, dv) over the
 *    selected patches. The exact trimmed domain and the polygon's differ by tol at most, so their
 *    images differ by δ_trim at most, both ways.
 * Interior points form a grid per cell (a patch, or a half, quarter or eighth of one where the
 * quarters' bounds are much tighter) whose triangles meet 0.6 δ_tri; triangles along the loops
 * that still exceed δ_tri are refined at the centre of their smallest enclosing disc (Kumar inserts
 * the point of maximal |F_uv|, §4.1 step 2; any interior point reduces R). The triangulation runs
 * in the face's scaled coordinates, so that Delaunay's round triangles are round in the bound's
 * metric.
 *
 * Where the paper is loose: §4.1 obtains M1..M3 by solving polynomial systems (elimination
 * theory); we use the rigorous but coarser control-net bounds of lod/bezier/sampling.c over each
 * patch. §4.3 says trimming curves "are treated like boundary curves" without saying how finely
 * they are sampled; ours are sampled for δ_trim in object space.
 */
#include "sw_clock.h"
#include "sw_lod_static_internal.h"
#include "sw_hooks.h"
#include "sw_lod_supersurface.h"

#include "sw_lod_bezier.h"
#include "sw_lod_mesh_distance.h"
#include "sw_lod_sampling.h"
#include "sw_lod_static_decimate.h"
#include "sw_lod_trim_mesh.h"
#include "sw_sg_geom.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum {
    TAG_GRID = 0u,
    TAG_TRIM = 1u,
    TAG_CORNER = 2u, /* a border vertex simplification must keep (a join of trim curves, a turn
                        of the super-surface's patch border) */
    TAG_REFINE = 4u,
};

#define STATIC_MAX_ROUNDS 48 /* refinement passes */

/* ---- level 0: the adaptive tessellation ------------------------------------------------------ */

/* A growing mesh in the chain's layout plus a per-vertex corner flag. */
typedef struct mesh_buf {
    double *pos, *uv;
    float *nrm;
    uint32_t *face;
    uint8_t *corner;
    uint32_t n_v, cap_v;
    uint32_t *tri;
    uint32_t n_t, cap_t;
} mesh_buf;

static void mesh_buf_free(mesh_buf *m)
{
    sw__free(m->pos), sw__free(m->uv), sw__free(m->nrm), sw__free(m->face), sw__free(m->corner),
        sw__free(m->tri);
    memset(m, 0, sizeof *m);
}

/* sw__grow for the builder's 32-bit counts (a capacity past 2^32 - 1 is noted as 2^32 - 1). */
static int grow(void **p, uint32_t *cap, uint32_t need, size_t elem)
{
    size_t c = *cap;
    if (!sw__grow(p, &c, need, elem))
        return 0;
    *cap = c > UINT32_MAX ? UINT32_MAX : (uint32_t)c;
    return 1;
}

static int mesh_reserve(mesh_buf *m, uint32_t nv, uint32_t nt)
{
    if (nv > m->cap_v) {
        uint32_t c = m->cap_v, c2 = m->cap_v, c3 = m->cap_v, c4 = m->cap_v, c5 = m->cap_v;
        if (!grow((void **)&m->pos, &c, nv, 3 * sizeof(double)) ||
            !grow((void **)&m->uv, &c2, nv, 2 * sizeof(double)) ||
            !grow((void **)&m->nrm, &c3, nv, 3 * sizeof(float)) ||
            !grow((void **)&m->face, &c4, nv, sizeof(uint32_t)) ||
            !grow((void **)&m->corner, &c5, nv, 1))
            return 0;
        m->cap_v = c;
    }
    return grow((void **)&m->tri, &m->cap_t, nt, 3 * sizeof(uint32_t));
}

/* Point buffer of CDT input. */
typedef struct pts {
    double *uv;
    uint32_t *tag, *id;
    uint32_t n, cap;
} pts;

static void pts_free(pts *p)
{
    sw__free(p->uv), sw__free(p->tag), sw__free(p->id);
    memset(p, 0, sizeof *p);
}

static int pts_add(pts *p, double u, double v, uint32_t tag)
{
    if (p->n == p->cap) {
        uint32_t c1 = p->cap, c2 = p->cap, c3 = p->cap;
        if (!grow((void **)&p->uv, &c1, p->n + 1, 2 * sizeof(double)) ||
            !grow((void **)&p->tag, &c2, p->n + 1, sizeof(uint32_t)) ||
            !grow((void **)&p->id, &c3, p->n + 1, sizeof(uint32_t)))
            return 0;
        p->cap = c1;
    }
    p->uv[2 * p->n] = u, p->uv[2 * p->n + 1] = v, p->tag[p->n] = tag;
    p->n++;
    return 1;
}

/* Constraint pairs referring to point indices of a pts buffer (ids filled after insertion). */
typedef struct pairs {
    uint32_t *v;
    uint32_t n, cap;
} pairs;

static int pairs_add(pairs *p, uint32_t a, uint32_t b)
{
    if (!grow((void **)&p->v, &p->cap, p->n + 1, 2 * sizeof(uint32_t)))
        return 0;
    p->v[2 * p->n] = a, p->v[2 * p->n + 1] = b;
    p->n++;
    return 1;
}

/* Grid lines of the face: per column i, n_col[i] segments; gu[first_u[i] + k]. */
typedef struct grid {
    int32_t *n_col, *n_row;
    double *gu, *gv;
    int32_t *first_u, *first_v;
} grid;

static void grid_free(grid *g)
{
    sw__free(g->n_col), sw__free(g->n_row), sw__free(g->gu), sw__free(g->gv), sw__free(g->first_u),
        sw__free(g->first_v);
    memset(g, 0, sizeof *g);
}

static int grid_build(const face_dom *fd, double c, grid *g)
{
    memset(g, 0, sizeof *g);
    g->n_col = sw__calloc((size_t)fd->nu, sizeof *g->n_col);
    g->n_row = sw__calloc((size_t)fd->nv, sizeof *g->n_row);
    g->first_u = sw__malloc(((size_t)fd->nu + 1) * sizeof *g->first_u);
    g->first_v = sw__malloc(((size_t)fd->nv + 1) * sizeof *g->first_v);
    if (!g->n_col || !g->n_row || !g->first_u || !g->first_v)
        return 0;
    for (int32_t j = 0; j < fd->nv; ++j)
        for (int32_t i = 0; i < fd->nu; ++i) {
            if (!fd->sel[j * fd->nu + i])
                continue;
            const double *sc = fd->scale + 2 * ((size_t)j * fd->nu + i);
            const int32_t a = (int32_t)fmin(STATIC_MAX_CELLS, fmax(1.0, ceil(sc[0] / c)));
            const int32_t b = (int32_t)fmin(STATIC_MAX_CELLS, fmax(1.0, ceil(sc[1] / c)));
            g->n_col[i] = g->n_col[i] > a ? g->n_col[i] : a;
            g->n_row[j] = g->n_row[j] > b ? g->n_row[j] : b;
        }
    size_t tu = 0, tv = 0;
    for (int32_t i = 0; i < fd->nu; ++i)
        g->first_u[i] = (int32_t)tu, tu += (size_t)(g->n_col[i] ? g->n_col[i] : 1);
    for (int32_t j = 0; j < fd->nv; ++j)
        g->first_v[j] = (int32_t)tv, tv += (size_t)(g->n_row[j] ? g->n_row[j] : 1);
    g->first_u[fd->nu] = (int32_t)tu, g->first_v[fd->nv] = (int32_t)tv;
    g->gu = sw__malloc((tu + 1) * sizeof *g->gu);
    g->gv = sw__malloc((tv + 1) * sizeof *g->gv);
    if (!g->gu || !g->gv)
        return 0;
    for (int32_t i = 0; i < fd->nu; ++i) {
        const int32_t m = g->first_u[i + 1] - g->first_u[i];
        for (int32_t k = 0; k < m; ++k)
            g->gu[g->first_u[i] + k] = fd->ub[i] + (fd->ub[i + 1] - fd->ub[i]) * k / m;
    }
    g->gu[tu] = fd->ub[fd->nu];
    for (int32_t j = 0; j < fd->nv; ++j) {
        const int32_t m = g->first_v[j + 1] - g->first_v[j];
        for (int32_t k = 0; k < m; ++k)
            g->gv[g->first_v[j] + k] = fd->vb[j] + (fd->vb[j + 1] - fd->vb[j]) * k / m;
    }
    g->gv[tv] = fd->vb[fd->nv];
    return 1;
}

/* Whether a knot-grid corner (i, j) is where the selection's border turns. */
static int sel_turn(const face_dom *fd, int32_t i, int32_t j)
{
    const int a = sw__sl_sel_at(fd, i - 1, j - 1), b = sw__sl_sel_at(fd, i, j - 1),
              c = sw__sl_sel_at(fd, i - 1, j), d = sw__sl_sel_at(fd, i, j);
    const int n = a + b + c + d;
    return n == 1 || n == 3 || (n == 2 && a == d);
}

/* Whether (u, v) lies on the selection's border (to rounding: CGAL's intersection points). */
static int on_sel_border(const face_dom *fd, double u, double v)
{
    const double tu = 1e-9 * (fd->ub[fd->nu] - fd->ub[0]), tv = 1e-9 * (fd->vb[fd->nv] - fd->vb[0]);
    const int32_t i = sw__sl_locate(fd->ub, fd->nu, u), j = sw__sl_locate(fd->vb, fd->nv, v);
    for (int32_t ii = i; ii <= i + 1; ++ii)
        if (fabs(u - fd->ub[ii]) <= tu && sw__sl_sel_at(fd, ii - 1, j) != sw__sl_sel_at(fd, ii, j))
            return 1;
    for (int32_t jj = j; jj <= j + 1; ++jj)
        if (fabs(v - fd->vb[jj]) <= tv && sw__sl_sel_at(fd, i, jj - 1) != sw__sl_sel_at(fd, i, jj))
            return 1;
    return 0;
}

static int is_join(const sw_sg_scene *scene, const sw_sg_loop_rec *lr, const double *uv)
{
    for (uint32_t c = lr->first_curve; c < lr->first_curve + lr->n_curves; ++c) {
        sw_sg_curve cv;
        sw_sg_scene_curve(scene, c, &cv);
        if (cv.cpw[0] / cv.cpw[2] == uv[0] && cv.cpw[1] / cv.cpw[2] == uv[1])
            return 1;
    }
    return 0;
}

/* Loop points (subdivided to scaled length c) and their constraints. */
static int add_loops(const sw_sg_scene *scene, const face_dom *fd, double c, pts *p, pairs *cons)
{
    const sw_sg_scene_view *view = sw_sg_scene_view_ptr(scene);
    const sw_sg_face_rec *fr = &view->faces[fd->face];
    for (uint32_t l = 0; l < fd->n_loops; ++l) {
        const sw_sg_polyline *pl = &fd->loops[l];
        const sw_sg_loop_rec *lr = &view->loops[fr->first_loop + l];
        if (pl->count < 2)
            continue;
        const uint32_t first = p->n;
        for (uint32_t i = 0; i < pl->count; ++i) {
            const double *a = pl->uv + 2 * i, *b = pl->uv + 2 * ((i + 1) % pl->count);
            const uint32_t tag = TAG_TRIM | (is_join(scene, lr, a) ? TAG_CORNER : 0u);
            if (!pts_add(p, a[0], a[1], tag))
                return 0;
            const double len = hypot((b[0] - a[0]) * fd->au, (b[1] - a[1]) * fd->av);
            const int32_t m = (int32_t)fmin(STATIC_MAX_CELLS, ceil(len / c));
            for (int32_t k = 1; k < m; ++k)
                if (!pts_add(p, a[0] + (b[0] - a[0]) * k / m, a[1] + (b[1] - a[1]) * k / m,
                             TAG_TRIM))
                    return 0;
        }
        for (uint32_t k = first; k < p->n; ++k)
            if (!pairs_add(cons, k, k + 1 < p->n ? k + 1 : first))
                return 0;
    }
    return 1;
}

/* Grid points inside the loops and the selected patches' sides as constraints. */
static int add_grid(const face_dom *fd, const grid *g, pts *p, pairs *cons)
{
    for (int32_t j = 0; j < fd->nv; ++j)
        for (int32_t i = 0; i < fd->nu; ++i) {
            if (!fd->sel[j * fd->nu + i])
                continue;
            const int32_t u0 = g->first_u[i], u1 = g->first_u[i + 1];
            const int32_t v0 = g->first_v[j], v1 = g->first_v[j + 1];
            for (int32_t l = v0; l <= v1; ++l)
                for (int32_t k = u0; k <= u1; ++k) {
                    const double u = g->gu[k], v = g->gv[l];
                    if (fd->has_loops && !sw__sl_strips_inside(&fd->cls, u, v))
                        continue;
                    const int corner = (k == u0 || k == u1) && (l == v0 || l == v1) &&
                                       sel_turn(fd, k == u0 ? i : i + 1, l == v0 ? j : j + 1);
                    if (!pts_add(p, u, v, corner ? TAG_CORNER : TAG_GRID))
                        return 0;
                }
            /* sides: bottom and left always; top and right where the selection ends. The grid's
             * own border too: loops may run beyond uv_box (pcurves past a periodic domain). */
            const int side[4] = {1, 1, j + 1 == fd->nv || !fd->sel[(j + 1) * fd->nu + i],
                                 i + 1 == fd->nu || !fd->sel[j * fd->nu + i + 1]};
            for (int s = 0; s < 4; ++s) {
                if (!side[s])
                    continue;
                const int horiz = s == 0 || s == 2;
                const int32_t a = horiz ? u0 : v0, b = horiz ? u1 : v1;
                const uint32_t first = p->n;
                for (int32_t k = a; k <= b; ++k) {
                    const double u = horiz ? g->gu[k] : g->gu[s == 1 ? u0 : u1];
                    const double v = horiz ? g->gv[s == 0 ? v0 : v1] : g->gv[k];
                    if (!pts_add(p, u, v, TAG_GRID))
                        return 0;
                }
                for (uint32_t k = first; k + 1 < p->n; ++k)
                    if (!pairs_add(cons, k, k + 1))
                        return 0;
            }
        }
    return 1;
}

/* Smallest disc containing a triangle: centre and squared radius. */
static double min_disc(const double a[2], const double b[2], const double c[2], double ctr[2])
{
    const double *q[3] = {a, b, c};
    double e[3]; /* squared length of the edge opposite vertex k */
    for (int k = 0; k < 3; ++k) {
        const double *x = q[(k + 1) % 3], *y = q[(k + 2) % 3];
        e[k] = (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]);
    }
    const int m = e[0] >= e[1] ? (e[0] >= e[2] ? 0 : 2) : (e[1] >= e[2] ? 1 : 2);
    if (e[m] >= e[(m + 1) % 3] + e[(m + 2) % 3]) { /* right or obtuse: the longest edge */
        const double *x = q[(m + 1) % 3], *y = q[(m + 2) % 3];
        ctr[0] = 0.5 * (x[0] + y[0]), ctr[1] = 0.5 * (x[1] + y[1]);
        return 0.25 * e[m];
    }
    const double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
    const double d = 2.0 * (bx * cy - by * cx);
    const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
    ctr[0] = a[0] + ux, ctr[1] = a[1] + uy;
    return ux * ux + uy * uy;
}

/* Bound of a triangle's deviation (Waldron in the patch's scaled coordinates) and the point that
 * refines it. Returns -1 for a triangle outside the domain. */
static double tri_bound(const face_dom *fd, const double *uv0, const double *uv1, const double *uv2,
                        double refine[2])
{
    const double cu = (uv0[0] + uv1[0] + uv2[0]) / 3.0, cv = (uv0[1] + uv1[1] + uv2[1]) / 3.0;
    if (!sw__sl_in_domain(fd, cu, cv))
        return -1.0;
    const int32_t i = sw__sl_locate(fd->ub, fd->nu, cu), j = sw__sl_locate(fd->vb, fd->nv, cv);
    const double *sc = fd->scale + 2 * ((size_t)j * fd->nu + i);
    const double ku = sc[0] / (fd->ub[i + 1] - fd->ub[i]), kv = sc[1] / (fd->vb[j + 1] - fd->vb[j]);
    const double a[2] = {(uv0[0] - cu) * ku, (uv0[1] - cv) * kv};
    const double b[2] = {(uv1[0] - cu) * ku, (uv1[1] - cv) * kv};
    const double c[2] = {(uv2[0] - cu) * ku, (uv2[1] - cv) * kv};
    double ctr[2];
    const double r2 = min_disc(a, b, c, ctr);
    refine[0] = cu + ctr[0] / ku, refine[1] = cv + ctr[1] / kv;
    return 0.5 * r2;
}

static void surface_normal(const face_dom *fd, double u, double v, float out[3])
{
    sw_sg_surface_d2 d;
    sw_sg_surface_eval_d2(&fd->s, u, v, &d);
    double n[3] = {d.du[1] * d.dv[2] - d.du[2] * d.dv[1], d.du[2] * d.dv[0] - d.du[0] * d.dv[2],
                   d.du[0] * d.dv[1] - d.du[1] * d.dv[0]};
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double s = (fd->reversed ? -1.0 : 1.0) / (l > 0.0 ? l : 1.0);
    for (int c = 0; c < 3; ++c)
        out[c] = (float)(n[c] * s);
}

/* Appends the inside triangles of a finished CDT to the mesh. */
static sw_result emit_face(const face_dom *fd, const sw_lod_cdt_mesh *cm, mesh_buf *m,
                           uint32_t max_vertices, sw_status *status)
{
    uint32_t *map = sw__malloc((cm->n_vertices ? cm->n_vertices : 1) * sizeof *map);
    if (!map)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u", fd->face);
    for (uint32_t k = 0; k < cm->n_vertices; ++k)
        map[k] = UINT32_MAX;
    sw_result r = SW_OK;
    for (uint32_t t = 0; t < cm->n_triangles && r == SW_OK; ++t) {
        const uint32_t *tv = cm->tri + 3 * t;
        double ref[2];
        if (tri_bound(fd, cm->uv + 2 * tv[0], cm->uv + 2 * tv[1], cm->uv + 2 * tv[2], ref) < 0.0)
            continue;
        uint32_t out[3];
        for (int c = 0; c < 3 && r == SW_OK; ++c) {
            const uint32_t k = tv[c];
            if (map[k] == UINT32_MAX) {
                if (m->n_v >= max_vertices) {
                    r = sw__fail(status, SW_ERR_LIMIT, "static lod: more than %u vertices",
                                 max_vertices);
                    break;
                }
                if (!mesh_reserve(m, m->n_v + 1, m->n_t + 1)) {
                    r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: %u vertices", m->n_v);
                    break;
                }
                const uint32_t v = m->n_v++;
                const double u = cm->uv[2 * k], w = cm->uv[2 * k + 1];
                m->uv[2 * v] = u, m->uv[2 * v + 1] = w;
                sw_sg_surface_eval(&fd->s, u, w, m->pos + 3 * (size_t)v);
                surface_normal(fd, u, w, m->nrm + 3 * (size_t)v);
                m->face[v] = fd->face;
                const uint32_t tag = cm->tag[k];
                m->corner[v] = tag == SW_LOD_CDT_NO_TAG ? (uint8_t)on_sel_border(fd, u, w)
                                                        : (uint8_t)((tag & TAG_CORNER) != 0);
                map[k] = v;
            }
            out[c] = map[k];
        }
        if (r != SW_OK)
            break;
        if (!mesh_reserve(m, m->n_v, m->n_t + 1)) {
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: %u triangles", m->n_t);
            break;
        }
        uint32_t *o = m->tri + 3 * (size_t)m->n_t++;
        o[0] = out[0];
        o[1] = fd->reversed ? out[2] : out[1];
        o[2] = fd->reversed ? out[1] : out[2];
    }
    sw__free(map);
    return r;
}

/* The triangulation runs in the coordinates (u su, v sv) of the face's largest scaling (au, av),
 * normalised: Delaunay triangles in (u, v) of a strongly anisotropic surface (a cylinder's
 * straight direction, a ruled surface) would be needles in the metric of the bound, and refining
 * them would never end. */
static void cdt_scale(const face_dom *fd, double *su, double *sv)
{
    const double m = fmax(fd->au, fd->av);
    if (!(m > 0.0) || !isfinite(m)) {
        *su = *sv = 1.0;
        return;
    }
    *su = fmax(fd->au / m, 1e-6), *sv = fmax(fd->av / m, 1e-6);
}

static sw_result cdt_insert(const face_dom *fd, sw_lod_cdt *cdt, pts *p, pairs *cons,
                            sw_status *status)
{
    double su, sv;
    cdt_scale(fd, &su, &sv);
    for (uint32_t k = 0; k < p->n; ++k)
        p->uv[2 * k] *= su, p->uv[2 * k + 1] *= sv;
    sw_result r = sw_lod_cdt_insert_points(cdt, p->uv, p->tag, p->n, p->id, status);
    if (r != SW_OK || !cons)
        return r;
    for (uint32_t k = 0; k < 2 * cons->n; ++k)
        cons->v[k] = p->id[cons->v[k]];
    return sw_lod_cdt_insert_constraints(cdt, cons->v, cons->n, status);
}

static sw_result cdt_snapshot(const face_dom *fd, sw_lod_cdt *cdt, sw_lod_cdt_mesh *cm,
                              sw_status *status)
{
    double su, sv;
    cdt_scale(fd, &su, &sv);
    sw_result r = sw_lod_cdt_snapshot(cdt, cm, status);
    for (uint32_t k = 0; r == SW_OK && k < cm->n_vertices; ++k)
        cm->uv[2 * k] /= su, cm->uv[2 * k + 1] /= sv;
    return r;
}

/* Level 0 of one face: grid, loops, constraints, then refinement until every inside triangle's
 * bound is within delta_tri. */
static sw_result tessellate_face(const sw_sg_scene *scene, const face_dom *fd, double delta_tri,
                                 uint32_t max_vertices, mesh_buf *m, sw_status *status)
{
    const double c = sqrt(2.4 * delta_tri); /* a cell's triangles: c^2 / 4 = 0.6 delta_tri */
    grid g;
    pts p = {0};
    pairs cons = {0};
    sw_lod_cdt *cdt = NULL;
    sw_lod_cdt_mesh cm = {0};
    sw_result r = SW_OK;
    if (!grid_build(fd, c, &g) || !add_loops(scene, fd, c, &p, &cons)) {
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u grid", fd->face);
        goto done;
    }
    double est = 0.0;
    for (int32_t j = 0; j < fd->nv; ++j)
        for (int32_t i = 0; i < fd->nu; ++i)
            if (fd->sel[j * fd->nu + i])
                est += (double)(g.first_u[i + 1] - g.first_u[i] + 1) *
                       (g.first_v[j + 1] - g.first_v[j] + 1);
    if (est + m->n_v > (double)max_vertices) {
        r = sw__fail(status, SW_ERR_LIMIT, "static lod: face %u needs ~%.0f grid points (limit %u)",
                     fd->face, est, max_vertices);
        goto done;
    }
    if (!add_grid(fd, &g, &p, &cons)) {
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u grid", fd->face);
        goto done;
    }
    if ((r = sw_lod_cdt_create(&cdt, status)) != SW_OK ||
        (r = cdt_insert(fd, cdt, &p, &cons, status)) != SW_OK)
        goto done;
    for (int round = 0;; ++round) {
        sw_lod_cdt_mesh_free(&cm);
        if ((r = cdt_snapshot(fd, cdt, &cm, status)) != SW_OK)
            goto done;
        p.n = 0;
        for (uint32_t t = 0; t < cm.n_triangles; ++t) {
            const uint32_t *tv = cm.tri + 3 * t;
            double ref[2];
            if (tri_bound(fd, cm.uv + 2 * tv[0], cm.uv + 2 * tv[1], cm.uv + 2 * tv[2], ref) >
                    delta_tri &&
                !pts_add(&p, ref[0], ref[1], TAG_REFINE)) {
                r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: refinement");
                goto done;
            }
        }
        if (p.n == 0)
            break;
        if (round == STATIC_MAX_ROUNDS || cm.n_vertices + p.n > max_vertices) {
            r = sw__fail(status, SW_ERR_LIMIT,
                         "static lod: face %u: %u triangles above the bound after %d rounds",
                         fd->face, p.n, round);
            goto done;
        }
        if ((r = cdt_insert(fd, cdt, &p, NULL, status)) != SW_OK)
            goto done;
    }
    r = emit_face(fd, &cm, m, max_vertices, status);
done:
    sw_lod_cdt_mesh_free(&cm);
    sw_lod_cdt_free(cdt);
    pts_free(&p);
    sw__free(cons.v);
    grid_free(&g);
    return r;
}

/* ---- the chain --------------------------------------------------------------------------------
 */

/* A level from the level-0 mesh restricted to triangles tri[] (indices of level 0). */
static int level_from(const mesh_buf *m, const uint32_t *tri, uint32_t n_tri,
                      sw_lod_static_level *l)
{
    memset(l, 0, sizeof *l);
    uint32_t *map = sw__malloc((m->n_v ? m->n_v : 1) * sizeof *map);
    if (!map)
        return 0;
    for (uint32_t v = 0; v < m->n_v; ++v)
        map[v] = UINT32_MAX;
    uint32_t nv = 0;
    for (size_t k = 0; k < 3 * (size_t)n_tri; ++k)
        if (map[tri[k]] == UINT32_MAX)
            map[tri[k]] = nv++;
    l->positions = sw__malloc(((size_t)nv ? nv : 1) * 3 * sizeof(double));
    l->normals = sw__malloc(((size_t)nv ? nv : 1) * 3 * sizeof(float));
    l->uv = sw__malloc(((size_t)nv ? nv : 1) * 2 * sizeof(double));
    l->face = sw__malloc(((size_t)nv ? nv : 1) * sizeof(uint32_t));
    l->triangles = sw__malloc(((size_t)n_tri ? n_tri : 1) * 3 * sizeof(uint32_t));
    if (!l->positions || !l->normals || !l->uv || !l->face || !l->triangles) {
        sw__free(map);
        sw__sl_level_free(l);
        return 0;
    }
    for (uint32_t v = 0; v < m->n_v; ++v) {
        const uint32_t o = map[v];
        if (o == UINT32_MAX)
            continue;
        memcpy(l->positions + 3 * (size_t)o, m->pos + 3 * (size_t)v, 3 * sizeof(double));
        memcpy(l->normals + 3 * (size_t)o, m->nrm + 3 * (size_t)v, 3 * sizeof(float));
        memcpy(l->uv + 2 * (size_t)o, m->uv + 2 * (size_t)v, 2 * sizeof(double));
        l->face[o] = m->face[v];
    }
    for (size_t k = 0; k < 3 * (size_t)n_tri; ++k)
        l->triangles[k] = map[tri[k]];
    l->n_vertices = nv;
    l->n_triangles = n_tri;
    sw__free(map);
    return 1;
}

/* Normals where S_u x S_v vanishes (poles, apexes): the mean of the incident triangles'. */
static void repair_normals(mesh_buf *m)
{
    double *acc = NULL;
    for (uint32_t v = 0; v < m->n_v; ++v) {
        const float *n = m->nrm + 3 * (size_t)v;
        if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.5f)
            continue;
        if (!acc && !(acc = sw__calloc(3 * (size_t)m->n_v, sizeof *acc)))
            return;
        break;
    }
    if (!acc)
        return;
    for (uint32_t t = 0; t < m->n_t; ++t) {
        const uint32_t *tv = m->tri + 3 * (size_t)t;
        const double *a = m->pos + 3 * (size_t)tv[0], *b = m->pos + 3 * (size_t)tv[1],
                     *c = m->pos + 3 * (size_t)tv[2];
        const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double f[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2],
                             e[0] * f[1] - e[1] * f[0]};
        for (int k = 0; k < 3; ++k)
            for (int q = 0; q < 3; ++q)
                acc[3 * (size_t)tv[k] + q] += n[q];
    }
    for (uint32_t v = 0; v < m->n_v; ++v) {
        float *n = m->nrm + 3 * (size_t)v;
        if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.5f)
            continue;
        const double *a = acc + 3 * (size_t)v;
        const double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        for (int q = 0; q < 3; ++q)
            n[q] = l > 0.0 ? (float)(a[q] / l) : (q == 2 ? 1.0f : 0.0f);
    }
    sw__free(acc);
}

typedef struct build_ctx {
    const mesh_buf *m;
    sw_lod_static_chain *chain;
    const sw_lod_static_desc *d;
    sw_result r;
    sw_status *status;
    double t_certify;
    sw_lod_mesh_distance *level0; /* built for the first level, shared by all */
} build_ctx;

/* How tightly a level's distance to level 0 is certified: pieces are accepted at 5 % above the
 * largest distance found, or below 1e-3 δ (the floor relative to the data), and split at most 12
 * times (a triangle into 4^12 pieces at worst; the Lipschitz fallback beyond, counted). */
static const double k_certify_rel = 0.05, k_certify_floor = 1e-3;
enum { CERTIFY_MAX_DEPTH = 12 };

/* ε_k of a simplified level, certified (Kumar et al. 1997 §4.1 declare "the simplified polygons
 * lie within δ + ε of the surface" by their offset envelopes; our decimation keeps no envelope,
 * so the bound is computed after it): for Hausdorff distances H(level, S) <= H(level, level 0) +
 * H(level 0, S), level 0 is within δ of S both ways (the header comment), and both one-sided
 * distances between the meshes are bounded by sw_lod_mesh_distance_bound. Level 0 -> level first:
 * the other side then needs certifying only down to it. */
static sw_result declare_level(build_ctx *b, sw_lod_static_level *l)
{
    const double t0 = (sw__clock_ms() * 1e-3);
    const sw_lod_static_level *l0 = &b->chain->levels[0];
    const double delta = b->chain->delta, floor = k_certify_floor * delta;
    sw_lod_mesh_bound from0, to0;
    sw_lod_mesh_distance *level = NULL;
    sw_result r = SW_OK;
    if (!b->level0)
        r = sw_lod_mesh_distance_create(l0->positions, l0->triangles, l0->n_triangles, &b->level0,
                                        b->status);
    if (r == SW_OK)
        r = sw_lod_mesh_distance_create(l->positions, l->triangles, l->n_triangles, &level,
                                        b->status);
    if (r == SW_OK)
        r = sw_lod_mesh_distance_bound(level, l0->positions, l0->triangles, l0->n_triangles,
                                       k_certify_rel, floor, CERTIFY_MAX_DEPTH, &from0, b->status);
    if (r == SW_OK)
        r = sw_lod_mesh_distance_bound(b->level0, l->positions, l->triangles, l->n_triangles,
                                       k_certify_rel, fmax(floor, from0.upper), CERTIFY_MAX_DEPTH,
                                       &to0, b->status);
    sw_lod_mesh_distance_free(level);
    b->t_certify += (sw__clock_ms() * 1e-3) - t0;
    if (r != SW_OK)
        return r;
    l->bound[0] = to0.upper;
    l->bound[1] = from0.upper;
    l->eps = delta + fmax(to0.upper, from0.upper);
    b->chain->capped_pieces += to0.capped + from0.capped;
    return SW_OK;
}

static int on_level(void *ctx, int32_t level, const uint32_t *tri, uint32_t n_tri)
{
    build_ctx *b = ctx;
    sw_lod_static_level *l = &b->chain->levels[level + 1];
    if (!level_from(b->m, tri, n_tri, l)) {
        b->r = sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "static lod: level %d", (int)level + 1);
        return 1;
    }
    b->chain->n_levels = level + 2;
    l->eps_target = b->chain->delta * b->d->eps_first * pow(b->d->eps_growth, level);
    b->r = declare_level(b, l);
    return b->r != SW_OK;
}

/* The level-0 vertex limit of n patches: the smaller of the two limits. */
static uint32_t vertex_limit(const sw_lod_static_desc *d, uint32_t n_patches)
{
    const double per = (double)d->max_vertices_per_patch * n_patches;
    return per < (double)d->max_vertices ? (uint32_t)per : d->max_vertices;
}

sw_result sw_lod_static_build(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                              uint32_t n, const sw_lod_static_desc *desc, sw_lod_static_chain **out,
                              sw_status *status)
{
    *out = NULL;
    double t0 = (sw__clock_ms() * 1e-3);
    patch_set ps;
    mesh_buf m = {0};
    sw_lod_static_desc d;
    sw_lod_static_chain *chain = NULL;
    sw_result r = sw__sl_patch_set_init(scene, patches, n, &ps, status);
    if (r == SW_OK)
        r = sw_lod_static_desc_resolve(desc, &d, status);
    if (r == SW_OK && d.delta == 0.0)
        d.delta = sw_lod_static_default_delta(ps.box);
    const uint32_t max_vertices = r == SW_OK ? vertex_limit(&d, ps.n) : 0;
    for (uint32_t f = 0; r == SW_OK && f < ps.n_faces; ++f) {
        face_dom *fd = &ps.faces[f];
        if (!sw__sl_face_dom_refine(fd, sqrt(2.4 * 0.75 * d.delta))) {
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u cells", fd->face);
            break;
        }
        const double tol = 0.25 * d.delta / (fd->grad > 0.0 ? fd->grad : 1.0);
        r = sw__sl_face_dom_flatten(scene, fd, tol, status);
        if (r == SW_OK)
            r = tessellate_face(scene, fd, 0.75 * d.delta, max_vertices, &m, status);
    }
    if (r == SW_OK && m.n_t == 0)
        r = sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                     "static lod: the patches' trimmed domain "
                     "is empty");
    if (r == SW_OK) {
        repair_normals(&m);
        chain = sw__calloc(1, sizeof *chain);
        if (chain)
            chain->levels = sw__calloc((size_t)d.n_levels + 1, sizeof *chain->levels);
        if (!chain || !chain->levels || !level_from(&m, m.tri, m.n_t, &chain->levels[0]))
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: chain");
    }
    if (r == SW_OK) {
        chain->n_levels = 1;
        chain->n_patches = ps.n;
        chain->delta = d.delta;
        chain->levels[0].eps = chain->levels[0].eps_target = d.delta;
        chain->seconds[0] = (sw__clock_ms() * 1e-3) - t0;
        build_ctx b = {&m, chain, &d, SW_OK, status, 0.0, NULL};
        if (d.n_levels > 0) {
            double *tol = sw__malloc((size_t)d.n_levels * sizeof *tol);
            if (!tol)
                r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: levels");
            for (int32_t k = 0; r == SW_OK && k < d.n_levels; ++k) /* against level 0 */
                tol[k] = d.delta * (d.eps_first * pow(d.eps_growth, k) - 1.0);
            t0 = (sw__clock_ms() * 1e-3);
            const sw_lod_decimate_input in = {m.pos,    m.n_v, m.tri,     m.n_t,
                                              m.corner, tol,   d.n_levels};
            if (r == SW_OK)
                r = sw_lod_static_decimate(&in, on_level, &b, status);
            if (r == SW_OK)
                r = b.r;
            sw__free(tol);
            sw_lod_mesh_distance_free(b.level0);
            chain->seconds[1] = (sw__clock_ms() * 1e-3) - t0 - b.t_certify;
            chain->seconds[2] = b.t_certify;
        }
    }
    mesh_buf_free(&m);
    sw__sl_patch_set_free(&ps);
    if (r != SW_OK) {
        sw_lod_static_free(chain);
        return r;
    }
    *out = chain;
    sw__status_ok(status);
    return SW_OK;
}

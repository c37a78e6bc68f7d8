/* SPDX-License-Identifier: MIT */
/* The face domains a static LOD is built and measured in (static_lod.c's header comment says
 * why): per face of a super-surface its selected Bézier patches cut into a grid of cells with
 * their second-derivative scalings, its trim loops flattened to a tolerance, and an even-odd
 * classifier over them bucketed in v. */
#include "sw_lod_static_internal.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_lod_sampling.h"
#include "sw_lod_supersurface.h"
#include "sw_status_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define STATIC_TRIM_MAX_VERTICES (1u << 22)

static void strips_free(strip_classifier *c)
{
    sw__free(c->start);
    sw__free(c->seg);
    memset(c, 0, sizeof *c);
}

uint32_t sw__sl_strip_of(const strip_classifier *c, double v)
{
    double x = (v - c->v0) * c->inv_h;
    if (!(x > 0.0))
        return 0;
    return x >= (double)(c->n_strips - 1) ? c->n_strips - 1 : (uint32_t)x;
}

static int strips_build(strip_classifier *c, const sw_sg_polyline *loops, uint32_t n_loops)
{
    memset(c, 0, sizeof *c);
    size_t n_seg = 0;
    double lo = DBL_MAX, hi = -DBL_MAX;
    for (uint32_t l = 0; l < n_loops; ++l) {
        n_seg += loops[l].count;
        for (uint32_t i = 0; i < loops[l].count; ++i) {
            lo = fmin(lo, loops[l].uv[2 * i + 1]);
            hi = fmax(hi, loops[l].uv[2 * i + 1]);
        }
    }
    if (n_seg == 0)
        return 1;
    c->n_strips = (uint32_t)fmin(4096.0, fmax(1.0, sqrt((double)n_seg)));
    c->v0 = lo;
    c->inv_h = hi > lo ? (double)c->n_strips / (hi - lo) : 0.0;
    uint32_t *count = sw__calloc((size_t)c->n_strips + 1, sizeof *count);
    if (!count)
        return 0;
    for (int pass = 0; pass < 2; ++pass) {
        for (uint32_t l = 0; l < n_loops; ++l) {
            const double *p = loops[l].uv;
            for (uint32_t i = 0, j = loops[l].count - 1; i < loops[l].count; j = i++) {
                uint32_t a = sw__sl_strip_of(c, fmin(p[2 * i + 1], p[2 * j + 1]));
                uint32_t b = sw__sl_strip_of(c, fmax(p[2 * i + 1], p[2 * j + 1]));
                for (uint32_t s = a; s <= b; ++s) {
                    if (pass == 0) {
                        count[s]++;
                        continue;
                    }
                    double *e = c->seg + 4 * (size_t)(c->start[s] + count[s]++);
                    e[0] = p[2 * i], e[1] = p[2 * i + 1], e[2] = p[2 * j], e[3] = p[2 * j + 1];
                }
            }
        }
        if (pass == 0) {
            c->start = sw__malloc(((size_t)c->n_strips + 1) * sizeof *c->start);
            size_t total = 0;
            for (uint32_t s = 0; s < c->n_strips; ++s)
                total += count[s];
            c->seg = sw__malloc((total ? total : 1) * 4 * sizeof *c->seg);
            if (!c->start || !c->seg || total > UINT32_MAX) {
                sw__free(count);
                strips_free(c);
                return 0;
            }
            c->start[0] = 0;
            for (uint32_t s = 0; s < c->n_strips; ++s)
                c->start[s + 1] = c->start[s] + count[s];
            memset(count, 0, ((size_t)c->n_strips + 1) * sizeof *count);
        }
    }
    sw__free(count);
    return 1;
}

int sw__sl_strips_inside(const strip_classifier *c, double u, double v)
{
    if (c->n_strips == 0)
        return 0;
    const uint32_t s = sw__sl_strip_of(c, v);
    int inside = 0;
    for (uint32_t k = c->start[s]; k < c->start[s + 1]; ++k) {
        const double *e = c->seg + 4 * (size_t)k;
        if ((e[1] > v) != (e[3] > v) && u < e[0] + (v - e[1]) * (e[2] - e[0]) / (e[3] - e[1]))
            inside ^= 1;
    }
    return inside;
}

static void face_dom_free(face_dom *fd)
{
    sw_sg_bezier_set_free(&fd->set);
    sw__free(fd->pub);
    sw__free(fd->pvb);
    sw__free(fd->psel);
    sw__free(fd->ub);
    sw__free(fd->vb);
    sw__free(fd->sel);
    sw__free(fd->scale);
    for (uint32_t l = 0; l < fd->n_loops; ++l)
        sw_sg_polyline_free(&fd->loops[l]);
    sw__free(fd->loops);
    strips_free(&fd->cls);
    memset(fd, 0, sizeof *fd);
}

int sw__sl_sel_at(const face_dom *fd, int32_t i, int32_t j)
{
    if (i < 0 || j < 0 || i >= fd->nu || j >= fd->nv)
        return fd->outside_sel;
    return fd->sel[j * fd->nu + i];
}

int32_t sw__sl_locate(const double *b, int32_t n, double x)
{
    int32_t lo = 0, hi = n - 1; /* last cell whose start <= x */
    while (lo < hi) {
        int32_t mid = (lo + hi + 1) / 2;
        if (b[mid] <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

int sw__sl_in_domain(const face_dom *fd, double u, double v)
{
    if (!(u >= fd->ub[0] && u <= fd->ub[fd->nu] && v >= fd->vb[0] && v <= fd->vb[fd->nv]))
        return 0;
    if (!fd->sel[sw__sl_locate(fd->vb, fd->nv, v) * fd->nu + sw__sl_locate(fd->ub, fd->nu, u)])
        return 0;
    return !fd->has_loops || sw__sl_strips_inside(&fd->cls, u, v);
}

/* The scaling of the header comment for one cell's bounds: k from a geometric set, the one
 * needing the fewest grid points at cell size c (c <= 0: the k of the smallest cell area). */
static void patch_scale(const sw_lod_patch_bounds *pb, double c, double *a, double *b)
{
    const double m = fmax(fmax(pb->d2[0], pb->d2[2]), pb->d2[1]);
    const double eta = 1e-6 * m + 1e-300;
    const double mss = fmax(pb->d2[0], eta), mtt = fmax(pb->d2[2], eta), mst = pb->d2[1];
    double k = fmin(1e4, fmax(1e-4, sqrt(mss / mtt)));
    *a = sqrt(mss + k * mst), *b = sqrt(mtt + mst / k);
    if (!(c > 0.0) || mst == 0.0)
        return;
    double best = (ceil(*a / c) + 1.0) * (ceil(*b / c) + 1.0);
    for (int i = -20; i <= 20; ++i) {
        k = pow(10.0, i / 5.0);
        const double ka = sqrt(mss + k * mst), kb = sqrt(mtt + mst / k);
        const double e = (ceil(ka / c) + 1.0) * (ceil(kb / c) + 1.0);
        if (e < best)
            best = e, *a = ka, *b = kb;
    }
}

/* Bounds of the selected patches split into sub x sub cells (de Casteljau restriction of each
 * cut net): per cell the scaling A, B, and over them G, au, av. With c > 0, *est receives the grid
 * points the cells would need at cell size c. scale: (nu * sub) * (nv * sub) * 2 doubles, or NULL.
 */
static void cell_bounds(const face_dom *fd, int32_t sub, double c, double *scale, double *est,
                        double *grad, double *au, double *av)
{
    double e = 0.0, g = 0.0, mu = 0.0, mv = 0.0;
    double net[(SW_SG_MAX_DEGREE + 1) * (SW_SG_MAX_DEGREE + 1) * 4];
    const int32_t cnu = fd->pnu * sub;
    for (int32_t j = 0; j < fd->pnv; ++j)
        for (int32_t i = 0; i < fd->pnu; ++i) {
            if (!fd->psel[j * fd->pnu + i])
                continue;
            const sw_sg_bezier_patch *p = &fd->set.patches[j * fd->pnu + i];
            const double lu = (fd->pub[i + 1] - fd->pub[i]) / sub;
            const double lv = (fd->pvb[j + 1] - fd->pvb[j]) / sub;
            for (int32_t b = 0; b < sub; ++b)
                for (int32_t a = 0; a < sub; ++a) {
                    const double rect[4] = {(double)a / sub, (double)(a + 1) / sub, (double)b / sub,
                                            (double)(b + 1) / sub};
                    const double *cp = p->cpw;
                    if (sub > 1) {
                        sw_lod_bez_restrict(p->deg_u, p->deg_v, 4, p->cpw, rect, net);
                        cp = net;
                    }
                    sw_lod_patch_bounds pb;
                    sw_lod_rational_bezier_bounds(p->deg_u, p->deg_v, cp, &pb);
                    double sa, sb;
                    patch_scale(&pb, c, &sa, &sb);
                    if (scale) {
                        double *sc = scale + 2 * ((size_t)(j * sub + b) * cnu + i * sub + a);
                        sc[0] = sa, sc[1] = sb;
                    }
                    mu = fmax(mu, sa / lu), mv = fmax(mv, sb / lv);
                    g = fmax(g, hypot(pb.d1[0] / lu, pb.d1[1] / lv));
                    if (c > 0.0)
                        e += (fmin(STATIC_MAX_CELLS, ceil(sa / c)) + 1.0) *
                             (fmin(STATIC_MAX_CELLS, ceil(sb / c)) + 1.0);
                }
        }
    if (est)
        *est = e;
    *grad = g, *au = mu, *av = mv;
}

/* Sets the cell grid of the face to sub x sub cells per patch. */
static int set_cells(face_dom *fd, int32_t sub, double *scale)
{
    sw__free(fd->ub), sw__free(fd->vb), sw__free(fd->sel), sw__free(fd->scale);
    fd->sub = sub;
    fd->nu = fd->pnu * sub, fd->nv = fd->pnv * sub;
    fd->ub = sw__malloc(((size_t)fd->nu + 1) * sizeof *fd->ub);
    fd->vb = sw__malloc(((size_t)fd->nv + 1) * sizeof *fd->vb);
    fd->sel = sw__malloc((size_t)fd->nu * fd->nv);
    fd->scale = scale;
    if (!fd->ub || !fd->vb || !fd->sel || !scale)
        return 0;
    for (int32_t i = 0; i < fd->nu; ++i) {
        const int32_t pi = i / sub, k = i % sub;
        fd->ub[i] = k == 0 ? fd->pub[pi] : fd->pub[pi] + (fd->pub[pi + 1] - fd->pub[pi]) * k / sub;
    }
    fd->ub[fd->nu] = fd->pub[fd->pnu];
    for (int32_t j = 0; j < fd->nv; ++j) {
        const int32_t pj = j / sub, k = j % sub;
        fd->vb[j] = k == 0 ? fd->pvb[pj] : fd->pvb[pj] + (fd->pvb[pj + 1] - fd->pvb[pj]) * k / sub;
    }
    fd->vb[fd->nv] = fd->pvb[fd->pnv];
    for (int32_t j = 0; j < fd->nv; ++j)
        for (int32_t i = 0; i < fd->nu; ++i)
            fd->sel[j * fd->nu + i] = fd->psel[(j / sub) * fd->pnu + i / sub];
    return 1;
}

/* The control-net bounds of a whole patch can be far above the surface's true derivatives
 * (rational patches, high degrees); bounds of its quarters are never larger and often much
 * smaller. Splits the face's patches into 2, 4 or 8 cells per side while that saves at least
 * 30 % of the grid points at cell size c. */
int sw__sl_face_dom_refine(face_dom *fd, double c)
{
    double est, g, mu, mv;
    cell_bounds(fd, fd->sub, c, NULL, &est, &g, &mu, &mv);
    int32_t best = fd->sub;
    for (int32_t sub = 2 * fd->sub; sub <= 8 && (int64_t)fd->pnu * fd->pnv * sub * sub <= 1 << 20;
         sub *= 2) {
        double e2;
        cell_bounds(fd, sub, c, NULL, &e2, &g, &mu, &mv);
        if (!(e2 < 0.7 * est))
            break;
        est = e2, best = sub;
    }
    double *scale = sw__calloc(2 * (size_t)fd->pnu * fd->pnv * best * best, sizeof *scale);
    if (scale)
        cell_bounds(fd, best, c, scale, NULL, &fd->grad, &fd->au, &fd->av);
    return set_cells(fd, best, scale);
}

/* The face's patches as the hierarchy and the super-surfaces see them (sw_lod_face_patches: over
 * its uv_box, cut to it) and the selected ones. patches[0..n) are this face's, sorted. */
static sw_result face_dom_init(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                               uint32_t n, face_dom *fd, sw_status *status)
{
    const sw_sg_scene_view *view = sw_sg_scene_view_ptr(scene);
    const uint32_t face = patches[0].face;
    const sw_sg_face_rec *fr = &view->faces[face];
    memset(fd, 0, sizeof *fd);
    fd->face = face;
    fd->reversed = (fr->flags & SW_SG_FACE_REVERSED) != 0;
    sw_sg_scene_face_surface(scene, face, &fd->s);
    sw_result r = sw_lod_face_patches(scene, face, &fd->set, status);
    if (r != SW_OK)
        return r;
    fd->pnu = fd->set.n_u, fd->pnv = fd->set.n_v;
    const size_t np = (size_t)fd->pnu * fd->pnv;
    fd->pub = sw__malloc(((size_t)fd->pnu + 1) * sizeof *fd->pub);
    fd->pvb = sw__malloc(((size_t)fd->pnv + 1) * sizeof *fd->pvb);
    fd->psel = sw__calloc(np, 1);
    if (!fd->pub || !fd->pvb || !fd->psel)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u", face);
    for (int32_t i = 0; i < fd->pnu; ++i) {
        fd->pub[i] = fd->set.patches[i].u0;
        fd->pub[i + 1] = fd->set.patches[i].u1;
    }
    for (int32_t j = 0; j < fd->pnv; ++j) {
        fd->pvb[j] = fd->set.patches[j * fd->pnu].v0;
        fd->pvb[j + 1] = fd->set.patches[j * fd->pnu].v1;
    }
    for (uint32_t k = 0; k < n; ++k) {
        if (patches[k].iu >= fd->pnu || patches[k].iv >= fd->pnv)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "static lod: face %u has %d x %d patches, not (%u, %u)", face,
                            (int)fd->pnu, (int)fd->pnv, patches[k].iu, patches[k].iv);
        fd->psel[patches[k].iv * fd->pnu + patches[k].iu] = 1;
    }
    for (int c = 0; c < 3; ++c)
        fd->box[c] = DBL_MAX, fd->box[3 + c] = -DBL_MAX;
    for (int32_t j = 0; j < fd->pnv; ++j)
        for (int32_t i = 0; i < fd->pnu; ++i) {
            if (!fd->psel[j * fd->pnu + i])
                continue;
            fd->n_sel++;
            const sw_sg_bezier_patch *p = &fd->set.patches[j * fd->pnu + i]; /* cut already */
            const int32_t ncp = (p->deg_u + 1) * (p->deg_v + 1);
            for (int32_t q = 0; q < ncp; ++q)
                for (int c = 0; c < 3; ++c) {
                    const double x = p->cpw[4 * q + c] / p->cpw[4 * q + 3];
                    fd->box[c] = fmin(fd->box[c], x);
                    fd->box[3 + c] = fmax(fd->box[3 + c], x);
                }
        }
    fd->has_loops = fr->n_loops > 0;
    fd->outside_sel = fd->has_loops && fd->n_sel == np;
    double *scale = sw__calloc(2 * np, sizeof *scale);
    if (scale)
        cell_bounds(fd, 1, 0.0, scale, NULL, &fd->grad, &fd->au, &fd->av);
    if (!set_cells(fd, 1, scale))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u", face);
    sw__status_ok(status);
    return SW_OK;
}

/* Rounding noise of the rational evaluation leaves a flattened iso-line (a seam, a domain edge)
 * bent by ~1e-15; the constrained triangulation then fills the sliver pocket under the bend with
 * long zero-area triangles that no refinement can shorten. Coordinates within 1e-12 of the
 * parameter range of a knot line, or of the previous vertex, are made equal to it. */
static void snap_loop(const face_dom *fd, sw_sg_polyline *pl)
{
    const double tol[2] = {1e-12 * (fd->ub[fd->nu] - fd->ub[0]),
                           1e-12 * (fd->vb[fd->nv] - fd->vb[0])};
    for (int a = 0; a < 2; ++a) {
        const double *b = a == 0 ? fd->ub : fd->vb;
        const int32_t nb = a == 0 ? fd->nu : fd->nv;
        for (uint32_t i = 0; i < pl->count; ++i) {
            double *x = &pl->uv[2 * i + a];
            const int32_t k = sw__sl_locate(b, nb, *x);
            if (fabs(*x - b[k]) <= tol[a])
                *x = b[k];
            else if (fabs(*x - b[k + 1]) <= tol[a])
                *x = b[k + 1];
            else if (i > 0 && fabs(*x - pl->uv[2 * (i - 1) + a]) <= tol[a])
                *x = pl->uv[2 * (i - 1) + a];
        }
    }
}

/* Flattens the face's loops within tol (parameter units) and builds the classifier. */
sw_result sw__sl_face_dom_flatten(const sw_sg_scene *scene, face_dom *fd, double tol,
                                  sw_status *status)
{
    const sw_sg_face_rec *fr = &sw_sg_scene_view_ptr(scene)->faces[fd->face];
    for (uint32_t l = 0; l < fd->n_loops; ++l)
        sw_sg_polyline_free(&fd->loops[l]);
    sw__free(fd->loops);
    strips_free(&fd->cls);
    fd->n_loops = 0;
    fd->loops = sw__calloc(fr->n_loops ? fr->n_loops : 1, sizeof *fd->loops);
    if (!fd->loops)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u", fd->face);
    for (uint32_t l = 0; l < fr->n_loops; ++l) {
        sw_result r = sw_sg_trim_flatten_loop(scene, fr->first_loop + l, tol,
                                              STATIC_TRIM_MAX_VERTICES, &fd->loops[l], status);
        if (r != SW_OK)
            return r;
        snap_loop(fd, &fd->loops[l]);
        fd->n_loops++;
    }
    if (!strips_build(&fd->cls, fd->loops, fd->n_loops))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: face %u loops", fd->face);
    sw__status_ok(status);
    return SW_OK;
}

void sw__sl_patch_set_free(patch_set *ps)
{
    for (uint32_t f = 0; f < ps->n_faces; ++f)
        face_dom_free(&ps->faces[f]);
    sw__free(ps->faces);
    sw__free(ps->p);
    memset(ps, 0, sizeof *ps);
}

sw_result sw__sl_patch_set_init(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                                uint32_t n, patch_set *ps, sw_status *status)
{
    memset(ps, 0, sizeof *ps);
    const sw_sg_scene_view *view = sw_sg_scene_view_ptr(scene);
    if (n == 0 || !patches)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "static lod: no patches");
    for (uint32_t k = 0; k < n; ++k)
        if (patches[k].face >= view->n_faces)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "static lod: patch %u: face %u of %u",
                            k, patches[k].face, view->n_faces);
    ps->p = sw__malloc((size_t)n * sizeof *ps->p);
    if (!ps->p)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: %u patches", n);
    memcpy(ps->p, patches, (size_t)n * sizeof *ps->p);
    qsort(ps->p, n, sizeof *ps->p, sw__sl_patch_cmp);
    uint32_t m = 0, nf = 0;
    for (uint32_t k = 0; k < n; ++k)
        if (m == 0 || sw__sl_patch_cmp(&ps->p[m - 1], &ps->p[k]) != 0) {
            nf += m == 0 || ps->p[m - 1].face != ps->p[k].face;
            ps->p[m++] = ps->p[k];
        }
    ps->n = m;
    ps->faces = sw__calloc(nf, sizeof *ps->faces);
    if (!ps->faces)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static lod: %u faces", nf);
    for (int c = 0; c < 3; ++c)
        ps->box[c] = DBL_MAX, ps->box[3 + c] = -DBL_MAX;
    for (uint32_t k = 0; k < m;) {
        uint32_t e = k;
        while (e < m && ps->p[e].face == ps->p[k].face)
            ++e;
        face_dom *fd = &ps->faces[ps->n_faces++];
        sw_result r = face_dom_init(scene, ps->p + k, e - k, fd, status);
        if (r != SW_OK)
            return r;
        for (int c = 0; c < 3; ++c) {
            ps->box[c] = fmin(ps->box[c], fd->box[c]);
            ps->box[3 + c] = fmax(ps->box[3 + c], fd->box[3 + c]);
        }
        k = e;
    }
    return SW_OK;
}

const face_dom *sw__sl_find_face(const patch_set *ps, uint32_t face)
{
    uint32_t lo = 0, hi = ps->n_faces;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (ps->faces[mid].face < face)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < ps->n_faces && ps->faces[lo].face == face ? &ps->faces[lo] : NULL;
}

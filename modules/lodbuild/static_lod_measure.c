/* SPDX-License-Identifier: MIT */
/* The two-sided measurement of a static level against the exact surface (sw_lod_static_measure):
 * the maximum over lattice or random samples of both distances. Mesh-to-surface values are upper
 * bounds at each sample (a surface point found by Newton's iteration, or level 0 plus δ); the
 * surface-to-mesh side is exact per sample (CGAL AABB tree). Neither side is a bound between
 * samples, so it checks a declared ε_k from below (the tests) and declares none: the builder
 * certifies ε_k (static_lod.c, declare_level).
 */
#include "sw_lod_static_internal.h"
#include "sw_hooks.h"
#include "sw_lod_mesh_distance.h"
#include "sw_lod_sampling.h"
#include "sw_status_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- measurement ---------------------------------------------------------------------------- */

typedef struct rng {
    uint64_t s;
} rng;

static double rng_next(rng *r)
{
    r->s = r->s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(r->s >> 11) * (1.0 / 9007199254740992.0);
}

/* The point of the loops nearest to (u, v) in parameter space: strips are searched outwards
 * from the point's own until they are farther in v than the best segment found. */
static void nearest_on_loops(const strip_classifier *c, double u, double v, double out[2])
{
    double best = INFINITY;
    out[0] = u, out[1] = v;
    const int64_t s0 = sw__sl_strip_of(c, v), n = c->n_strips;
    const double h = c->inv_h > 0.0 ? 1.0 / c->inv_h : INFINITY;
    for (int64_t off = 0; off < n; ++off) {
        const double gap = off == 0 ? 0.0 : (double)(off - 1) * h;
        if (gap * gap >= best)
            break;
        for (int side = -1; side <= 1; side += 2) {
            const int64_t s = s0 + side * off;
            if (s < 0 || s >= n || (off == 0 && side == 1))
                continue;
            for (uint32_t k = c->start[s]; k < c->start[s + 1]; ++k) {
                const double *e = c->seg + 4 * (size_t)k;
                const double dx = e[2] - e[0], dy = e[3] - e[1], l2 = dx * dx + dy * dy;
                double t = l2 > 0.0 ? ((u - e[0]) * dx + (v - e[1]) * dy) / l2 : 0.0;
                t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
                const double x = e[0] + t * dx, y = e[1] + t * dy;
                const double d2 = (x - u) * (x - u) + (y - v) * (y - v);
                if (d2 < best)
                    best = d2, out[0] = x, out[1] = y;
            }
        }
    }
}

static double dist_at(const face_dom *fd, const double p[3], double u, double v)
{
    double x[3];
    sw_sg_surface_eval(&fd->s, u, v, x);
    return sqrt((x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) +
                (x[2] - p[2]) * (x[2] - p[2]));
}

/* Upper bound of the distance from p to the face's trimmed surface: Newton's iteration on
 * |S(u, v) - p|^2 from (u, v) over the uv_box; the best iterate inside the domain, or, when the
 * foot lies outside, the surface point at the nearest point of the selected patch (of the start)
 * and of the loops (flattened within 1 % of the level's ε: a border point of the surface). */
static double project(const face_dom *fd, const double p[3], double u, double v, int *inside)
{
    double best = INFINITY;
    const double lu = fd->ub[fd->nu] - fd->ub[0], lv = fd->vb[fd->nv] - fd->vb[0];
    const int32_t pi = sw__sl_locate(fd->ub, fd->nu, u), pj = sw__sl_locate(fd->vb, fd->nv, v);
    for (int it = 0; it < 8; ++it) {
        sw_sg_surface_d2 d;
        sw_sg_surface_eval_d2(&fd->s, u, v, &d);
        const double r[3] = {d.p[0] - p[0], d.p[1] - p[1], d.p[2] - p[2]};
        const double dist = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if (dist < best && sw__sl_in_domain(fd, u, v))
            best = dist;
        double g0 = 0, g1 = 0, h00 = 0, h01 = 0, h11 = 0, k00 = 0, k01 = 0, k11 = 0;
        for (int c = 0; c < 3; ++c) {
            g0 += r[c] * d.du[c], g1 += r[c] * d.dv[c];
            h00 += d.du[c] * d.du[c], h01 += d.du[c] * d.dv[c], h11 += d.dv[c] * d.dv[c];
            k00 += r[c] * d.duu[c], k01 += r[c] * d.duv[c], k11 += r[c] * d.dvv[c];
        }
        double a = h00 + k00, b = h01 + k01, e = h11 + k11;
        if (!(a > 0.0 && a * e - b * b > 0.0)) /* not convex here: Gauss-Newton */
            a = h00, b = h01, e = h11;
        const double det = a * e - b * b;
        if (!(det > 0.0))
            break;
        const double du = -(e * g0 - b * g1) / det, dv = -(a * g1 - b * g0) / det;
        u = fmin(fd->ub[fd->nu], fmax(fd->ub[0], u + du));
        v = fmin(fd->vb[fd->nv], fmax(fd->vb[0], v + dv));
        if (fabs(du) <= 1e-13 * lu && fabs(dv) <= 1e-13 * lv)
            break;
    }
    *inside = sw__sl_in_domain(fd, u, v);
    if (*inside)
        return fmin(best, dist_at(fd, p, u, v));
    if (!fd->sel[sw__sl_locate(fd->vb, fd->nv, v) * fd->nu + sw__sl_locate(fd->ub, fd->nu, u)]) {
        if (!fd->sel[pj * fd->nu + pi])
            return best;
        u = fmin(fd->ub[pi + 1], fmax(fd->ub[pi], u));
        v = fmin(fd->vb[pj + 1], fmax(fd->vb[pj], v));
    }
    if (fd->has_loops && !sw__sl_strips_inside(&fd->cls, u, v)) {
        double q[2];
        nearest_on_loops(&fd->cls, u, v, q);
        u = q[0], v = q[1];
    }
    return fmin(best, dist_at(fd, p, u, v));
}

static void measure_desc_defaults(const sw_lod_static_measure_desc *in,
                                  sw_lod_static_measure_desc *d)
{
    *d = in ? *in : (sw_lod_static_measure_desc){0};
    if (d->seed == 0)
        d->seed = 1;
    if (d->patch_samples <= 0)
        d->patch_samples = 10;
    if (d->triangle_samples <= 0)
        d->triangle_samples = 6;
}

/* Surface -> mesh over one face: lattice (or random points) per selected patch inside the loops,
 * the loop vertices (points of the exact curves) and the selection's border sides. */
static void measure_face_surface(const face_dom *fd, const sw_lod_mesh_distance *md,
                                 const sw_lod_static_measure_desc *d, int32_t m, rng *rg,
                                 sw_lod_static_distance *out)
{
    const double ox = fmod(0.5 + 0.6180339887498949 * d->seed, 1.0);
    const double oy = fmod(0.5 + 0.4142135623730950 * d->seed, 1.0);
    double x[3];
    for (int32_t j = 0; j < fd->nv; ++j)
        for (int32_t i = 0; i < fd->nu; ++i) {
            if (!fd->sel[j * fd->nu + i])
                continue;
            const double u0 = fd->ub[i], lu = fd->ub[i + 1] - u0;
            const double v0 = fd->vb[j], lv = fd->vb[j + 1] - v0;
            for (int32_t b = 0; b <= m; ++b)
                for (int32_t a = 0; a <= m; ++a) {
                    double s, t;
                    if (d->random)
                        s = rng_next(rg), t = rng_next(rg);
                    else if (a == m || b == m)
                        continue;
                    else
                        s = (a + ox) / m, t = (b + oy) / m;
                    /* borders of the selection: the patch sides there, sampled too */
                    const double u = u0 + s * lu, v = v0 + t * lv;
                    if (!sw__sl_in_domain(fd, u, v))
                        continue;
                    sw_sg_surface_eval(&fd->s, u, v, x);
                    out->surface_to_mesh =
                        fmax(out->surface_to_mesh, sw_lod_mesh_distance_query(md, x));
                    out->n_surface++;
                }
            const int border[4] = {!sw__sl_sel_at(fd, i, j - 1), !sw__sl_sel_at(fd, i - 1, j),
                                   !sw__sl_sel_at(fd, i, j + 1), !sw__sl_sel_at(fd, i + 1, j)};
            for (int sd = 0; sd < 4; ++sd) {
                if (!border[sd])
                    continue;
                for (int32_t a = 0; a < 4 * m; ++a) {
                    const double s = d->random ? rng_next(rg) : (a + ox) / (4 * m);
                    const double u = sd == 1 ? u0 : sd == 3 ? u0 + lu : u0 + s * lu;
                    const double v = sd == 0 ? v0 : sd == 2 ? v0 + lv : v0 + s * lv;
                    if (fd->has_loops && !sw__sl_strips_inside(&fd->cls, u, v))
                        continue;
                    sw_sg_surface_eval(&fd->s, u, v, x);
                    out->surface_to_mesh =
                        fmax(out->surface_to_mesh, sw_lod_mesh_distance_query(md, x));
                    out->n_surface++;
                }
            }
        }
    for (uint32_t l = 0; l < fd->n_loops; ++l) {
        const sw_sg_polyline *pl = &fd->loops[l];
        for (uint32_t k = 0; k < pl->count; ++k) {
            const double u = pl->uv[2 * k], v = pl->uv[2 * k + 1];
            if (!(u >= fd->ub[0] && u <= fd->ub[fd->nu] && v >= fd->vb[0] && v <= fd->vb[fd->nv]))
                continue;
            if (!fd->sel[sw__sl_locate(fd->vb, fd->nv, v) * fd->nu +
                         sw__sl_locate(fd->ub, fd->nu, u)])
                continue;
            sw_sg_surface_eval(&fd->s, u, v, x);
            out->surface_to_mesh = fmax(out->surface_to_mesh, sw_lod_mesh_distance_query(md, x));
            out->n_surface++;
        }
    }
}

static double longest2(const sw_lod_static_level *lv, uint32_t t)
{
    const uint32_t *tv = lv->triangles + 3 * (size_t)t;
    double l = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double *a = lv->positions + 3 * (size_t)tv[c];
        const double *b = lv->positions + 3 * (size_t)tv[(c + 1) % 3];
        l = fmax(l, (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2]));
    }
    return l;
}

/* Upper bound of the distance to the surface of the triangle point with barycentric (w0, w1). */
typedef struct mesh_ref {
    const sw_lod_mesh_distance *level0; /* may be NULL */
    double delta;
} mesh_ref;

static double mesh_point_distance(const face_dom *fd, const mesh_ref *ref, const double *const P[3],
                                  const double *const UV[3], double w0, double w1)
{
    const double w2 = 1.0 - w0 - w1;
    double x[3], uv[2];
    for (int c = 0; c < 3; ++c)
        x[c] = w0 * P[0][c] + w1 * P[1][c] + w2 * P[2][c];
    for (int c = 0; c < 2; ++c)
        uv[c] = w0 * UV[0][c] + w1 * UV[1][c] + w2 * UV[2][c];
    /* a foot outside the domain gives a loose bound: retry from the vertices */
    int inside;
    double dist = project(fd, x, uv[0], uv[1], &inside);
    for (int c = 0; c < 3 && !inside; ++c)
        dist = fmin(dist, project(fd, x, UV[c][0], UV[c][1], &inside));
    if (!(dist < INFINITY)) /* no start in the domain: the nearest vertex bounds it */
        for (int c = 0; c < 3; ++c)
            dist = fmin(dist, sqrt((x[0] - P[c][0]) * (x[0] - P[c][0]) +
                                   (x[1] - P[c][1]) * (x[1] - P[c][1]) +
                                   (x[2] - P[c][2]) * (x[2] - P[c][2])));
    /* Newton finds a local foot only: where the surface folds back (a thread's next turn) the
     * nearest point lies elsewhere. Level 0 is within delta of the surface everywhere (a
     * rigorous bound), so the exact distance to it plus delta also bounds the distance. */
    if (ref->level0)
        dist = fmin(dist, sw_lod_mesh_distance_query(ref->level0, x) + ref->delta);
    return dist;
}

/* Mesh -> surface: points of each triangle, projected by Newton from their interpolated (u, v). */
static void measure_mesh(const patch_set *ps, const mesh_ref *ref, const sw_lod_static_level *lv,
                         const sw_lod_static_measure_desc *d, rng *rg, sw_lod_static_distance *out)
{
    /* Samples in proportion to the triangles' squared longest edges (an area that does not
     * vanish for slivers), at least 3 per triangle (its edge midpoints in the lattice), in all
     * max(3 per triangle, min(20k, max(4k, 64 per triangle))) x triangle_samples / 6: a
     * coarse level's few large triangles are sampled densely. */
    double sum = 0.0;
    for (uint32_t t = 0; t < lv->n_triangles; ++t)
        sum += longest2(lv, t);
    const double budget =
        fmax(3.0 * lv->n_triangles, fmin(20000.0, fmax(4000.0, 64.0 * lv->n_triangles))) *
        d->triangle_samples / 6.0;
    for (uint32_t t = 0; t < lv->n_triangles; ++t) {
        const uint32_t *tv = lv->triangles + 3 * (size_t)t;
        const face_dom *fd = sw__sl_find_face(ps, lv->face[tv[0]]);
        if (!fd)
            continue;
        const double *P[3], *UV[3];
        for (int c = 0; c < 3; ++c) {
            P[c] = lv->positions + 3 * (size_t)tv[c];
            UV[c] = lv->uv + 2 * (size_t)tv[c];
        }
        const double want =
            fmin(4096.0, fmax(3.0, budget * longest2(lv, t) / (sum > 0.0 ? sum : 1.0)));
        int32_t k = 2; /* lattice order: (k + 1)(k + 2) / 2 - 3 points besides the vertices */
        while ((k + 1) * (k + 2) / 2 - 3 < want)
            ++k;
        const int32_t n_pts = (k + 1) * (k + 2) / 2;
        double tbest = 0.0, bw0 = 1.0 / 3.0, bw1 = 1.0 / 3.0;
        for (int32_t q = 0; q < n_pts; ++q) {
            double w0, w1;
            if (d->random) {
                double r1 = sqrt(rng_next(rg)), r2 = rng_next(rg);
                w0 = 1.0 - r1, w1 = r1 * (1.0 - r2);
            } else {
                int32_t row = 0, rem = q; /* (i, j) with i + j <= k, enumerated by rows */
                while (rem > k - row)
                    rem -= k - row + 1, ++row;
                w0 = (double)row / k, w1 = (double)rem / k;
            }
            const double w2 = 1.0 - w0 - w1;
            if (w0 == 1.0 || w1 == 1.0 || w2 == 1.0)
                continue; /* a vertex: on the surface by construction */
            const double dist = mesh_point_distance(fd, ref, P, UV, w0, w1);
            if (dist > tbest)
                tbest = dist, bw0 = w0, bw1 = w1;
            out->mesh_to_surface = fmax(out->mesh_to_surface, dist);
            out->n_mesh++;
        }
        /* Coarse levels: a pattern search from the triangle's worst sample, since the peak of a
         * needle triangle is narrow (one-sided decimation lets such triangles leave the surface).
         */
        if (lv->n_triangles > 20000 || !(tbest > 0.0))
            continue;
        for (double h = 0.5 / k; h > 0.02 / k; h *= 0.5)
            for (int improved = 1; improved;) {
                improved = 0;
                static const double dir[6][2] = {{1, 0},  {-1, 0}, {0, 1},
                                                 {0, -1}, {1, -1}, {-1, 1}};
                for (int q = 0; q < 6; ++q) {
                    const double w0 = bw0 + h * dir[q][0], w1 = bw1 + h * dir[q][1];
                    if (w0 < 0.0 || w1 < 0.0 || w0 + w1 > 1.0)
                        continue;
                    const double dist = mesh_point_distance(fd, ref, P, UV, w0, w1);
                    out->n_mesh++;
                    if (dist > tbest) {
                        tbest = dist, bw0 = w0, bw1 = w1, improved = 1;
                        out->mesh_to_surface = fmax(out->mesh_to_surface, dist);
                    }
                }
            }
    }
}

/* level0: the tree of level 0 for the mesh -> surface fallback, NULL when lv is level 0 */
/* Both distances of level lv to the surfaces of ps; level0: the tree of level 0 for the mesh ->
 * surface fallback, NULL when lv is level 0. */
static sw_result measure_with(const sw_sg_scene *scene, patch_set *ps,
                              const sw_lod_static_level *lv, const sw_lod_mesh_distance *level0,
                              double delta, double eps_hint, const sw_lod_static_measure_desc *din,
                              sw_lod_static_distance *out, sw_status *status)
{
    sw_lod_static_measure_desc d;
    measure_desc_defaults(din, &d);
    memset(out, 0, sizeof *out);
    if (lv->n_triangles == 0)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "static lod: empty level");
    for (uint32_t f = 0; f < ps->n_faces; ++f) {
        face_dom *fd = &ps->faces[f];
        /* a floor: a level measured exact (a plane) must not flatten at rounding level */
        const double range = fmax(fd->ub[fd->nu] - fd->ub[0], fd->vb[fd->nv] - fd->vb[0]);
        const double tol = fmax(0.01 * eps_hint / (fd->grad > 0.0 ? fd->grad : 1.0), 1e-9 * range);
        sw_result r = sw__sl_face_dom_flatten(scene, fd, tol, status);
        if (r != SW_OK)
            return r;
    }
    sw_lod_mesh_distance *md = NULL;
    sw_result r =
        sw_lod_mesh_distance_create(lv->positions, lv->triangles, lv->n_triangles, &md, status);
    if (r != SW_OK)
        return r;
    rng rg = {0x9e3779b97f4a7c15ull * d.seed + 1};
    const int32_t m =
        (int32_t)fmin(64.0, fmax((double)d.patch_samples, ceil(sqrt(20000.0 / (double)ps->n))));
    for (uint32_t f = 0; f < ps->n_faces; ++f) {
        const int32_t sub = ps->faces[f].sub;
        measure_face_surface(&ps->faces[f], md, &d, (m + sub - 1) / sub, &rg, out);
    }
    sw_lod_mesh_distance_free(md);
    const mesh_ref ref = {level0, delta};
    measure_mesh(ps, &ref, lv, &d, &rg, out);
    sw__status_ok(status);
    return SW_OK;
}

/* measure_with with level 0's tree built here (level0 NULL or lv itself: none). */
static sw_result measure_set(const sw_sg_scene *scene, patch_set *ps, const sw_lod_static_level *lv,
                             const sw_lod_static_level *level0, double delta, double eps_hint,
                             const sw_lod_static_measure_desc *din, sw_lod_static_distance *out,
                             sw_status *status)
{
    sw_lod_mesh_distance *tree = NULL;
    sw_result r = SW_OK;
    if (level0 && level0 != lv && level0->n_triangles > 0)
        r = sw_lod_mesh_distance_create(level0->positions, level0->triangles, level0->n_triangles,
                                        &tree, status);
    if (r == SW_OK)
        r = measure_with(scene, ps, lv, tree, delta, eps_hint, din, out, status);
    sw_lod_mesh_distance_free(tree);
    return r;
}

sw_result sw_lod_static_measure(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                                uint32_t n, const sw_lod_static_level *level,
                                const sw_lod_static_level *level0, double delta, double eps_hint,
                                const sw_lod_static_measure_desc *desc, sw_lod_static_distance *out,
                                sw_status *status)
{
    patch_set ps;
    sw_result r = sw__sl_patch_set_init(scene, patches, n, &ps, status);
    if (r == SW_OK && !(eps_hint > 0.0))
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT, "static lod: eps_hint %g", eps_hint);
    if (r == SW_OK)
        r = measure_set(scene, &ps, level, level0, delta, eps_hint, desc, out, status);
    sw__sl_patch_set_free(&ps);
    return r;
}

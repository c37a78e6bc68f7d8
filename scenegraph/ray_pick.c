/* SPDX-License-Identifier: MIT */
/* Picking by ray: BVH traversal nearest box first, then per face Bézier subdivision against the
 * ray's two planes and Newton on the exact surface (sw_sg_pick.h says why and how). */
#include "sw_sg_pick.h"
#include "sw_hooks.h"

#include "sw_sg_geom.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_DEPTH = 12,   /* subdivisions of a patch (alternating u, v): 64 x 64 cells at most */
    MAX_LEAVES = 256, /* Newton starts per patch (a grazing ray keeps many cells alive) */
    NEWTON_STEPS = 40,
    MAX_LOOP_VERTICES = 1u << 22,
};

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The ray in a face's frame: origin o, direction d (not unit: t keeps the world's meaning), and
 * the two unit normals n[0], n[1] of planes through it, n[2] = d / |d|^2 (t of a point). */
typedef struct local_ray {
    double o[3], d[3], n[3][3];
} local_ray;

static void ray_planes(local_ray *r)
{
    const double *d = r->d;
    double len = sqrt(dot3(d, d));
    /* The axis least aligned with d gives a well-conditioned first normal. */
    double ax[3] = {0, 0, 0};
    int k = fabs(d[0]) <= fabs(d[1]) && fabs(d[0]) <= fabs(d[2]) ? 0
            : fabs(d[1]) <= fabs(d[2])                           ? 1
                                                                 : 2;
    ax[k] = 1.0;
    double *n0 = r->n[0], *n1 = r->n[1];
    n0[0] = d[1] * ax[2] - d[2] * ax[1];
    n0[1] = d[2] * ax[0] - d[0] * ax[2];
    n0[2] = d[0] * ax[1] - d[1] * ax[0];
    double l0 = sqrt(dot3(n0, n0));
    for (int i = 0; i < 3; ++i)
        n0[i] /= l0;
    n1[0] = (d[1] * n0[2] - d[2] * n0[1]) / len;
    n1[1] = (d[2] * n0[0] - d[0] * n0[2]) / len;
    n1[2] = (d[0] * n0[1] - d[1] * n0[0]) / len;
    for (int i = 0; i < 3; ++i)
        r->n[2][i] = d[i] / (len * len);
}

/* ---- one face -----------------------------------------------------------------------------------
 */

typedef struct face_job {
    const sw_sg_scene *scene;
    sw_sg_surface srf;
    const sw_sg_face_rec *rec;
    local_ray ray;
    sw_sg_polyline *loops;
    uint32_t n_loops;
    double dom[4]; /* the face's parameter domain, for Newton's clamp */
    double scale;  /* size of the patch being solved, for tolerances */
    double best_t; /* the nearest accepted hit so far (world t) */
    double best_uv[2];
    int found, leaves;
} face_job;

/* Splits a homogeneous (du+1) x (dv+1) net at the middle of direction dir (0 = u) by de
 * Casteljau: lo and hi get the two halves. */
static void split(const double *net, int du, int dv, int dir, double *lo, double *hi)
{
    const int nu = du + 1, nv = dv + 1, n = dir == 0 ? nu : nv, lines = dir == 0 ? nv : nu;
    double tmp[32][4];
    for (int line = 0; line < lines; ++line) {
        for (int i = 0; i < n; ++i) {
            int idx = dir == 0 ? line * nu + i : i * nu + line;
            memcpy(tmp[i], net + 4 * idx, sizeof tmp[i]);
        }
        for (int i = 0; i < n; ++i) {
            int first = dir == 0 ? line * nu + i : i * nu + line;
            int last = dir == 0 ? line * nu + (n - 1 - i) : (n - 1 - i) * nu + line;
            memcpy(lo + 4 * first, tmp[0], sizeof tmp[0]);
            memcpy(hi + 4 * last, tmp[n - 1 - i], sizeof tmp[0]);
            for (int j = 0; j < n - 1 - i; ++j)
                for (int c = 0; c < 4; ++c)
                    tmp[j][c] = 0.5 * (tmp[j][c] + tmp[j + 1][c]);
        }
    }
}

/* 1 when the net's convex hull (Euclidean control points: weights are positive) may meet the ray
 * between t = 0 and the best hit so far. */
static int hull_meets_ray(const face_job *job, const double *net, int n_cp)
{
    const local_ray *r = &job->ray;
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (int i = 0; i < n_cp; ++i) {
        const double *h = net + 4 * i;
        double p[3] = {h[0] / h[3] - r->o[0], h[1] / h[3] - r->o[1], h[2] / h[3] - r->o[2]};
        for (int k = 0; k < 3; ++k) {
            double e = dot3(r->n[k], p);
            lo[k] = fmin(lo[k], e);
            hi[k] = fmax(hi[k], e);
        }
    }
    double eps = 1e-9 * job->scale;
    return lo[0] <= eps && hi[0] >= -eps && lo[1] <= eps && hi[1] >= -eps && hi[2] >= 0.0 &&
           lo[2] <= job->best_t + eps;
}

static int in_domain(const face_job *job, double u, double v)
{
    if (u < job->dom[0] || u > job->dom[1] || v < job->dom[2] || v > job->dom[3])
        return 0;
    if (!(job->rec->flags & SW_SG_FACE_TRIMMED))
        return u >= job->rec->uv_box[0] && u <= job->rec->uv_box[1] && v >= job->rec->uv_box[2] &&
               v <= job->rec->uv_box[3];
    return sw_sg_trim_classify(job->loops, job->n_loops, u, v);
}

/* Newton on the two plane equations from (u, v); accepts a converged root in the face. */
static void newton(face_job *job, double u, double v)
{
    const local_ray *r = &job->ray;
    for (int it = 0; it < NEWTON_STEPS; ++it) {
        sw_sg_surface_d2 s;
        sw_sg_surface_eval_d2(&job->srf, u, v, &s);
        double p[3] = {s.p[0] - r->o[0], s.p[1] - r->o[1], s.p[2] - r->o[2]};
        double f0 = dot3(r->n[0], p), f1 = dot3(r->n[1], p);
        if (fabs(f0) + fabs(f1) <= 1e-11 * job->scale) {
            double t = dot3(r->n[2], p);
            if (t > 0.0 && t < job->best_t && in_domain(job, u, v)) {
                job->best_t = t;
                job->best_uv[0] = u;
                job->best_uv[1] = v;
                job->found = 1;
            }
            return;
        }
        double a = dot3(r->n[0], s.du), b = dot3(r->n[0], s.dv);
        double c = dot3(r->n[1], s.du), d = dot3(r->n[1], s.dv), det = a * d - b * c;
        if (!(fabs(det) > 0.0))
            return;
        u = fmin(fmax(u - (d * f0 - b * f1) / det, job->dom[0]), job->dom[1]);
        v = fmin(fmax(v - (a * f1 - c * f0) / det, job->dom[2]), job->dom[3]);
    }
}

/* Subdivides a patch's net over face parameters rect while its hull meets the ray. */
static int subdivide(face_job *job, const double *net, int du, int dv, const double rect[4],
                     int depth)
{
    const int n_cp = (du + 1) * (dv + 1);
    if (job->leaves >= MAX_LEAVES || !hull_meets_ray(job, net, n_cp))
        return 0;
    if (depth == MAX_DEPTH) {
        job->leaves++;
        newton(job, 0.5 * (rect[0] + rect[1]), 0.5 * (rect[2] + rect[3]));
        return 0;
    }
    double *half = sw__malloc(2 * (size_t)n_cp * 4 * sizeof *half);
    if (!half)
        return -1;
    int dir = depth % 2;
    if ((dir == 0 && du == 0) || (dir == 1 && dv == 0))
        dir = 1 - dir;
    split(net, du, dv, dir, half, half + 4 * n_cp);
    double mid = dir == 0 ? 0.5 * (rect[0] + rect[1]) : 0.5 * (rect[2] + rect[3]);
    double r_lo[4] = {rect[0], dir == 0 ? mid : rect[1], rect[2], dir == 1 ? mid : rect[3]};
    double r_hi[4] = {dir == 0 ? mid : rect[0], rect[1], dir == 1 ? mid : rect[2], rect[3]};
    int rc = subdivide(job, half, du, dv, r_lo, depth + 1);
    if (rc == 0)
        rc = subdivide(job, half + 4 * n_cp, du, dv, r_hi, depth + 1);
    sw__free(half);
    return rc;
}

static double net_scale(const double *net, int n_cp)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (int i = 0; i < n_cp; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = net[4 * i + k] / net[4 * i + 3];
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
        }
    return fmax(hypot(hypot(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]), DBL_MIN);
}

static sw_result face_loops(face_job *job, sw_status *status)
{
    const sw_sg_face_rec *rec = job->rec;
    if (!(rec->flags & SW_SG_FACE_TRIMMED) || rec->n_loops == 0)
        return SW_OK;
    job->loops = sw__calloc(rec->n_loops, sizeof *job->loops);
    if (!job->loops)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "pick: out of memory");
    double tol = 1e-6 * fmax(rec->uv_box[1] - rec->uv_box[0], rec->uv_box[3] - rec->uv_box[2]);
    for (uint32_t k = 0; k < rec->n_loops; ++k) {
        sw_result r = sw_sg_trim_flatten_loop(job->scene, rec->first_loop + k, tol,
                                              MAX_LOOP_VERTICES, &job->loops[k], status);
        if (r != SW_OK)
            return r;
        job->n_loops = k + 1;
    }
    return SW_OK;
}

static void face_job_free(face_job *job)
{
    for (uint32_t k = 0; k < job->n_loops; ++k)
        sw_sg_polyline_free(&job->loops[k]);
    sw__free(job->loops);
}

/* Intersects one face with the local ray; updates *best_t and the hit when nearer. */
static sw_result face_pick(const sw_sg_scene *scene, uint32_t face, const local_ray *ray,
                           double *best_t, double uv[2], int *found, sw_status *status)
{
    face_job job;
    memset(&job, 0, sizeof job);
    job.scene = scene;
    job.rec = &sw_sg_scene_view_ptr(scene)->faces[face];
    job.ray = *ray;
    job.best_t = *best_t;
    sw_sg_scene_face_surface(scene, face, &job.srf);
    sw_sg_knots_domain(job.srf.knots_u, job.srf.deg_u, job.srf.n_u, &job.dom[0], &job.dom[1]);
    sw_sg_knots_domain(job.srf.knots_v, job.srf.deg_v, job.srf.n_v, &job.dom[2], &job.dom[3]);
    if (job.srf.deg_u > 31 || job.srf.deg_v > 31)
        return sw__fail(status, SW_ERR_LIMIT, "pick: face %u has degree above 31", face);
    sw_sg_bezier_set set;
    const double *b = job.rec->uv_box;
    sw_result r = sw_sg_surface_extract_bezier_in(&job.srf, b[0], b[1], b[2], b[3], &set, status);
    if (r != SW_OK)
        return r;
    r = face_loops(&job, status);
    for (int32_t i = 0; r == SW_OK && i < set.n_u * set.n_v; ++i) {
        const sw_sg_bezier_patch *p = &set.patches[i];
        const int n_cp = (p->deg_u + 1) * (p->deg_v + 1);
        const double rect[4] = {p->u0, p->u1, p->v0, p->v1};
        job.scale = net_scale(p->cpw, n_cp);
        job.leaves = 0;
        if (subdivide(&job, p->cpw, p->deg_u, p->deg_v, rect, 0) != 0)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "pick: out of memory");
    }
    if (r == SW_OK && job.found) {
        *best_t = job.best_t;
        uv[0] = job.best_uv[0];
        uv[1] = job.best_uv[1];
        *found = 1;
    }
    face_job_free(&job);
    sw_sg_bezier_set_free(&set);
    return r;
}

/* ---- the BVH -----------------------------------------------------------------------------------
 */

/* Entry parameter of the ray into a box (slab test), or +INF when it misses before t_max. */
static double ray_box(const double o[3], const double inv_d[3], const double box[6], double t_max)
{
    double t0 = 0.0, t1 = t_max;
    for (int k = 0; k < 3; ++k) {
        double a = (box[k] - o[k]) * inv_d[k], b = (box[3 + k] - o[k]) * inv_d[k];
        if (a > b) {
            double s = a;
            a = b;
            b = s;
        }
        if (isnan(a) || isnan(b)) /* the ray runs inside a slab's plane: inside iff within */
            continue;
        t0 = fmax(t0, a);
        t1 = fmin(t1, b);
    }
    return t0 <= t1 ? t0 : INFINITY;
}

/* The ray in an occurrence's frame (inverse of world = M x + T); 0 for a singular transform. */
static int world_ray(const double m[12], const double o[3], const double d[3], local_ray *r)
{
    if (!sw_sg_to_local(m, o, d, r->o, r->d))
        return 0;
    ray_planes(r);
    return 1;
}

/* ---- meshes ------------------------------------------------------------------------------------
 */

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Möller-Trumbore: t of the ray's crossing of triangle (a, b, c), both sides, with the weights of
 * b and c in *u, *v; INFINITY when it misses (or runs parallel). */
static double ray_triangle(const local_ray *r, const double *a, const double *b, const double *c,
                           double *u, double *v)
{
    double e1[3], e2[3], pv[3], tv[3], qv[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
        tv[k] = r->o[k] - a[k];
    }
    cross3(r->d, e2, pv);
    const double det = dot3(e1, pv);
    if (!(fabs(det) > 0.0))
        return INFINITY;
    const double inv = 1.0 / det;
    *u = dot3(tv, pv) * inv;
    if (!(*u >= 0.0 && *u <= 1.0))
        return INFINITY;
    cross3(tv, e1, qv);
    *v = dot3(r->d, qv) * inv;
    if (!(*v >= 0.0 && *u + *v <= 1.0))
        return INFINITY;
    const double t = dot3(e2, qv) * inv;
    return t > 0.0 ? t : INFINITY;
}

typedef struct mesh_job {
    const sw_sg_scene *scene;
    const double *origin, *dir, *inv_d;
    double best;
    sw_sg_pick_hit *hit;
    uint32_t occurrence;
} mesh_job;

/* One mesh occurrence: its world box (the box corners' images bound an affine map's image of
 * the box) against the ray, then every triangle in the mesh's frame. */
static int mesh_visit(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                      const float color[4])
{
    (void)color;
    mesh_job *job = ctx;
    const uint32_t occ = job->occurrence++;
    const sw_sg_mesh_rec *m = &sw_sg_scene_view_ptr(job->scene)->meshes[mesh];
    double box[6];
    sw_sg_box_transform(world, m->box, box);
    local_ray lr;
    if (ray_box(job->origin, job->inv_d, box, job->best) == INFINITY ||
        !world_ray(world, job->origin, job->dir, &lr))
        return 0;
    const double *pos, *nrm;
    const uint32_t *idx;
    sw_sg_scene_mesh(job->scene, mesh, &pos, &nrm, &idx);
    for (uint32_t t = 0; t < m->n_triangles; ++t) {
        const uint32_t *tri = idx + 3 * (size_t)t;
        double u = 0.0, v = 0.0;
        const double th = ray_triangle(&lr, pos + 3 * (size_t)tri[0], pos + 3 * (size_t)tri[1],
                                       pos + 3 * (size_t)tri[2], &u, &v);
        if (th < job->best) {
            job->best = th;
            sw_sg_pick_hit *h = job->hit;
            h->face = SW_SG_NONE;
            h->mesh = mesh;
            h->node = node;
            h->triangle = t;
            h->item = occ;
            h->t = th;
            h->bary[0] = 1.0 - u - v;
            h->bary[1] = u;
            h->bary[2] = v;
            h->uv[0] = h->uv[1] = 0.0;
        }
    }
    return 0;
}

static sw_result pick_meshes(const sw_sg_scene *scene, const double origin[3], const double dir[3],
                             const double inv_d[3], double *best, sw_sg_pick_hit *hit,
                             sw_status *status)
{
    mesh_job job = {scene, origin, dir, inv_d, *best, hit, 0};
    if (sw_sg_scene_traverse_meshes(scene, mesh_visit, &job) != SW_OK)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "pick: out of memory walking the meshes");
    *best = job.best;
    return SW_OK;
}

sw_result sw_sg_pick(const sw_sg_scene *scene, const sw_sg_bvh *bvh, const double origin[3],
                     const double dir[3], double t_max, sw_sg_pick_hit *hit, sw_status *status)
{
    memset(hit, 0, sizeof *hit);
    hit->face = SW_SG_NONE;
    hit->mesh = SW_SG_NONE;
    hit->node = SW_SG_NONE;
    double dd = dot3(dir, dir);
    if (!(dd > 0.0) || !isfinite(dd) || !isfinite(dot3(origin, origin)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "pick: zero or non-finite ray");
    double best = t_max > 0.0 ? t_max : INFINITY, inv_d[3];
    for (int k = 0; k < 3; ++k)
        inv_d[k] = 1.0 / dir[k];
    int32_t *stack = sw__malloc(((size_t)bvh->n_nodes + 1) * sizeof *stack);
    if (!stack)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "pick: out of memory");
    size_t top = 0;
    if (bvh->n_nodes)
        stack[top++] = 0;
    sw_result r = SW_OK;
    while (top > 0 && r == SW_OK) {
        const uint32_t id = (uint32_t)stack[--top];
        const sw_sg_bvh_node *n = &bvh->nodes[id];
        double box[6];
        sw_sg_bvh_node_box(bvh, id, box);
        if (ray_box(origin, inv_d, box, best) == INFINITY)
            continue;
        if (n->second >= 0) {
            /* The nearer child is popped first, so the best hit shrinks early and prunes more. */
            const int32_t child[2] = {(int32_t)id + 1, n->second};
            double b0[6], b1[6];
            sw_sg_bvh_node_box(bvh, (uint32_t)child[0], b0);
            sw_sg_bvh_node_box(bvh, (uint32_t)child[1], b1);
            double t0 = ray_box(origin, inv_d, b0, best);
            double t1 = ray_box(origin, inv_d, b1, best);
            int near = t1 < t0;
            stack[top++] = child[1 - near];
            stack[top++] = child[near];
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count && r == SW_OK; ++i) {
            sw_sg_bvh_item_view it;
            sw_sg_bvh_item_at(bvh, i, &it);
            local_ray lr;
            if (ray_box(origin, inv_d, it.box, best) == INFINITY ||
                !world_ray(it.world, origin, dir, &lr))
                continue;
            int found = 0;
            r = face_pick(scene, it.face, &lr, &best, hit->uv, &found, status);
            if (found) {
                hit->face = it.face;
                hit->item = i;
                hit->t = best;
            }
        }
    }
    sw__free(stack);
    if (r == SW_OK && sw_sg_scene_view_ptr(scene)->n_meshes)
        r = pick_meshes(scene, origin, dir, inv_d, &best, hit, status);
    if (r == SW_OK && (hit->face != SW_SG_NONE || hit->mesh != SW_SG_NONE))
        for (int k = 0; k < 3; ++k)
            hit->point[k] = origin[k] + hit->t * dir[k];
    return r;
}

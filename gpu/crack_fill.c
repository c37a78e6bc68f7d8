/* Crack filling between independently tessellated faces (Guthe et al. 2005 §7.1, after the fat
 * borders of Balázs et al. 2004). Core-profile GL has no wide lines, so each boundary loop of a
 * drawn face (its trim loops, or its parameter box when untrimmed) becomes a ribbon of triangles:
 * the loop is sampled on the exact surface (NURBS evaluation in double), and every sample is
 * joined to a copy of itself moved in the surface's tangent plane towards the face's inside, so
 * far that its image lies width_px pixels from the loop's image. The ribbon follows the surface
 * (on a plane it lies in the plane: depths stay exact), covers the face's own side of its exact
 * border, and reaches beyond it only by k_outer x width_px: silhouettes and open boundaries grow
 * by a fraction of a pixel, not by the ribbon's width.
 * Why it closes the cracks: where faces A and B meet along a curve C, each is drawn within ε_img
 * of the exact surface, so an uncovered pixel between them lies on A's or B's side of C's image
 * within ε_img of it, and that face's ribbon covers its side of C to width_px = 2 ε_img; the
 * ribbon's own border stays within ε_img / 2 + width_px / 4 = ε_img of C (the loop is cut at
 * most one grid cell apart in u and v, where the Filip bound of the face's grid holds; trim loops
 * are flattened to half a trim texel, one texel moving the surface by at most the object
 * tolerance; samples are dropped only where the kept chord stays within width_px / 4 of them on
 * screen). Not rigorous between samples (the surface is not bounded there), and the ribbon is
 * flat in the tangent plane: over one cell both are second-order small. A sliver k_outer x
 * width_px wide beyond C makes two ribbons meeting exactly on C overlap, so that no pixel centre
 * on C falls between them by rounding (without it, single-pixel holes remain at joins).
 */
#include "sw_gpu_internal.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_PIECES_PER_SEGMENT = 4096 };
static const double k_outer = 0.125; /* of the width: overlap on the far side, so that two ribbons
                                       meeting exactly on C leave no pixel centre between them */

typedef struct border_point {
    double p[3];  /* eye-relative world position */
    double n[3];  /* world normal (unnormalised) */
    double in[3]; /* world tangent vector pointing into the face (unnormalised) */
    double uv[2], in_uv[2]; /* the loop point and `in` in face parameters (trim lookups) */
} border_point;

/* in_uv: a direction in (u, v) pointing into the face at this point. */
static void eval_point(const sw_sg_surface *srf, const double world[12], const double eye[3],
                       double u, double v, const double in_uv[2], border_point *out)
{
    double h[12];
    sw_sg_surface_eval_h1(srf, u, v, h);
    double p[3], du[3], dv[3], n[3];
    for (int k = 0; k < 3; ++k) {
        p[k] = h[k] / h[3];
        du[k] = h[4 + k] * h[3] - h[k] * h[7];
        dv[k] = h[8 + k] * h[3] - h[k] * h[11];
    }
    n[0] = du[1] * dv[2] - du[2] * dv[1];
    n[1] = du[2] * dv[0] - du[0] * dv[2];
    n[2] = du[0] * dv[1] - du[1] * dv[0];
    double in[3];
    for (int k = 0; k < 3; ++k)
        in[k] = du[k] * in_uv[0] + dv[k] * in_uv[1];
    out->uv[0] = u;
    out->uv[1] = v;
    out->in_uv[0] = in_uv[0];
    out->in_uv[1] = in_uv[1];
    for (int r = 0; r < 3; ++r) {
        out->p[r] = world[4 * r] * p[0] + world[4 * r + 1] * p[1] + world[4 * r + 2] * p[2] +
                    world[4 * r + 3] - eye[r];
        out->n[r] = world[4 * r] * n[0] + world[4 * r + 1] * n[1] + world[4 * r + 2] * n[2];
        out->in[r] = world[4 * r] * in[0] + world[4 * r + 1] * in[1] + world[4 * r + 2] * in[2];
    }
}

/* Samples of a closed uv polyline, each segment cut into pieces no longer than (du, dv). */
static size_t count_samples(const double *uv, size_t n, double du, double dv)
{
    size_t total = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *a = uv + 2 * i, *b = uv + 2 * ((i + 1) % n);
        double k = fmax(fabs(b[0] - a[0]) / du, fabs(b[1] - a[1]) / dv);
        k = ceil(fmin(fmax(k, 1.0), (double)MAX_PIECES_PER_SEGMENT));
        total += (size_t)k;
    }
    return total;
}

/* Screen position (pixels from the centre) of an eye-relative point; 0 if not in front. */
static int screen_of(const sw__gpu_view *v, const double p[3], double out[2])
{
    double z = v->fwd[0] * p[0] + v->fwd[1] * p[1] + v->fwd[2] * p[2];
    if (!(z > v->near_plane))
        return 0;
    out[0] = v->focal_px * (v->right[0] * p[0] + v->right[1] * p[1] + v->right[2] * p[2]) / z;
    out[1] = v->focal_px * (v->up[0] * p[0] + v->up[1] * p[1] + v->up[2] * p[2]) / z;
    return 1;
}

static double dist_to_segment(const double p[2], const double a[2], const double b[2])
{
    double d[2] = {b[0] - a[0], b[1] - a[1]}, l2 = d[0] * d[0] + d[1] * d[1];
    double t = l2 > 0.0 ? ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return hypot(p[0] - a[0] - t * d[0], p[1] - a[1] - t * d[1]);
}

/* Drops samples (in place) whose screen image stays within tol_px of the chord between the
 * samples kept around them: the loop is sampled at the grid's cells, far denser than a ribbon
 * needs where it runs straight on screen. Returns the samples kept. */
static size_t thin_samples(const sw__gpu_view *v, border_point *bp, size_t n, double tol_px)
{
    enum { MAX_RUN = 64 };
    size_t kept = 1, i = 1;
    while (i < n) {
        double a[2], q[2], b[2];
        size_t end = i; /* extend the run [last kept, end] while every sample fits the chord */
        if (screen_of(v, bp[kept - 1].p, a)) {
            while (end + 1 < n && end + 1 - (kept - 1) <= MAX_RUN &&
                   screen_of(v, bp[end + 1].p, b)) {
                int fits = 1;
                for (size_t k = i; k <= end && fits; ++k)
                    fits = screen_of(v, bp[k].p, q) && dist_to_segment(q, a, b) <= tol_px;
                if (!fits)
                    break;
                ++end;
            }
        }
        bp[kept++] = bp[end];
        i = end + 1;
    }
    return kept;
}

/* Screen-space derivative (pixels) of the projection at eye-relative p along direction w. */
static void screen_deriv(const sw__gpu_view *v, const double p[3], const double w[3], double out[2])
{
    double r = 0.0, u = 0.0, z = 0.0, wr = 0.0, wu = 0.0, wz = 0.0;
    for (int k = 0; k < 3; ++k) {
        r += v->right[k] * p[k];
        u += v->up[k] * p[k];
        z += v->fwd[k] * p[k];
        wr += v->right[k] * w[k];
        wu += v->up[k] * w[k];
        wz += v->fwd[k] * w[k];
    }
    out[0] = v->focal_px * (wr * z - r * wz) / (z * z);
    out[1] = v->focal_px * (wu * z - u * wz) / (z * z);
}

/* Object-space length along the inward tangent `in` whose image moves width_px pixels away from
 * the loop's image (perpendicular to its screen tangent), capped at 4 x the screen-facing length
 * where the face is seen edge-on; 0 where the loop's image degenerates. */
static double inward_length(const sw__gpu_view *v, const double p[3], const double t[3],
                            const double in[3], double width_px)
{
    double z = v->fwd[0] * p[0] + v->fwd[1] * p[1] + v->fwd[2] * p[2];
    double li = sqrt(in[0] * in[0] + in[1] * in[1] + in[2] * in[2]);
    if (!(z > 0.0) || !(li > 0.0))
        return 0.0;
    double ts[2], is[2];
    screen_deriv(v, p, t, ts);
    screen_deriv(v, p, in, is);
    double tl = hypot(ts[0], ts[1]);
    if (!(tl > 0.0))
        return 0.0;
    double perp = fabs(is[0] * ts[1] - is[1] * ts[0]) / tl; /* pixels per unit of `in` */
    double cap = 4.0 * width_px * z / (v->focal_px * li);
    return perp > width_px / cap ? width_px / perp : cap;
}

/* One quad per loop segment, lying in the surface's tangent plane at the segment's start (on a
 * plane, in the plane), from k_outer x width_px outside the loop to width_px inside. Quads of
 * consecutive segments share their points on the loop; their inner edges are not joined, which
 * keeps a sharp corner of the loop from folding a quad across it. */
static void emit_ribbon(const sw__gpu_view *v, const border_point *bp, size_t n, double width_px,
                        const double *st_box, sw__gpu_mesh *mesh)
{
    for (size_t i = 0; i < n; ++i) {
        const border_point *e[2] = {&bp[i], &bp[(i + 1) % n]};
        const double *in = e[0]->in;
        double t[3] = {e[1]->p[0] - e[0]->p[0], e[1]->p[1] - e[0]->p[1], e[1]->p[2] - e[0]->p[2]};
        uint32_t base = (uint32_t)mesh->n_v;
        for (int end = 0; end < 2; ++end) {
            double h = inward_length(v, e[end]->p, t, in, width_px);
            for (int side = 0; side < 2; ++side) {
                sw__gpu_vertex *o = &mesh->v[mesh->n_v++];
                double sgn = side ? h : -k_outer * h;
                for (int k = 0; k < 3; ++k) {
                    o->pos[k] = (float)(e[end]->p[k] + sgn * in[k]);
                    o->nrm[k] = (float)e[end]->n[k];
                }
                o->st[0] = o->st[1] = 0.0f;
                if (st_box) { /* `in` moves uv by in_uv, to first order */
                    o->st[0] = (float)((e[end]->uv[0] + sgn * e[0]->in_uv[0] - st_box[0]) /
                                       (st_box[1] - st_box[0]));
                    o->st[1] = (float)((e[end]->uv[1] + sgn * e[0]->in_uv[1] - st_box[2]) /
                                       (st_box[3] - st_box[2]));
                }
            }
        }
        uint32_t *o = mesh->idx + mesh->n_idx;
        o[0] = base, o[1] = base + 1, o[2] = base + 3, o[3] = base, o[4] = base + 3,
        o[5] = base + 2;
        mesh->n_idx += 6;
    }
}

sw_result sw__gpu_fat_border(const sw__gpu_view *v, const sw_sg_surface *srf,
                             const double world[12], const double *uv, size_t n, int left_inside,
                             double du, double dv, double width_px, const double *st_box,
                             sw__gpu_mesh *mesh, sw_status *status)
{
    if (n < 2 || !(du > 0.0) || !(dv > 0.0))
        return SW_OK;
    size_t m = count_samples(uv, n, du, dv);
    sw_result r = sw__gpu_mesh_reserve(mesh, 4 * m, 6 * m, status);
    if (r != SW_OK)
        return r;
    border_point *bp = malloc(m * sizeof *bp);
    if (!bp)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "fat border: out of memory");
    size_t at = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *a = uv + 2 * i, *b = uv + 2 * ((i + 1) % n);
        double k = fmax(fabs(b[0] - a[0]) / du, fabs(b[1] - a[1]) / dv);
        int32_t pieces = (int32_t)ceil(fmin(fmax(k, 1.0), (double)MAX_PIECES_PER_SEGMENT));
        double t[2] = {b[0] - a[0], b[1] - a[1]};
        double in_uv[2] = {left_inside ? -t[1] : t[1], left_inside ? t[0] : -t[0]};
        for (int32_t j = 0; j < pieces; ++j) {
            double f = (double)j / pieces;
            eval_point(srf, world, v->eye, a[0] + f * t[0], a[1] + f * t[1], in_uv, &bp[at++]);
        }
    }
    emit_ribbon(v, bp, thin_samples(v, bp, m, 0.25 * width_px), width_px, st_box, mesh);
    free(bp);
    return SW_OK;
}

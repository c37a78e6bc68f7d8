/* SPDX-License-Identifier: MIT */
/* Crack filling between independently tessellated faces (Guthe et al. 2005 §7.1, after the fat
 * borders of Balázs et al. 2004). Core-profile GL has no wide lines, so each boundary loop of a
 * drawn face (its trim loops, or its parameter box when untrimmed) becomes a ribbon of triangles:
 * the loop is sampled on the exact surface (NURBS evaluation in double), and every sample is
 * joined to a point of the face inside it whose image lies width_px pixels across the loop's
 * image, and to a point k_outer x width_px beyond it. The ribbon covers the face's own side of
 * its exact border: silhouettes and open boundaries grow by a fraction of a pixel, not by the
 * ribbon's width.
 * Why it closes the cracks: where faces A and B meet along a curve C, each is drawn within ε_img
 * of the exact surface, so an uncovered pixel between them lies on A's or B's side of C's image
 * within ε_img of it, and that face's ribbon covers its side of C to width_px = 2 ε_img; the
 * ribbon's own border stays within ε_img / 2 + width_px / 4 = ε_img of C (the loop is cut at
 * most one grid cell apart in u and v, where the Filip bound of the face's grid holds; trim loops
 * are flattened to half a trim texel, one texel moving the surface by at most the object
 * tolerance; samples are dropped only where the kept chord stays within width_px / 4 of them on
 * screen). Not rigorous between samples (the surface is not bounded there). A sliver k_outer x
 * width_px wide beyond the chords makes two ribbons meeting on C overlap, so that no pixel centre
 * on C falls between their chords (without it, single-pixel holes remain at joins; two faces
 * sampled at different steps along one curve leave chords up to width_px / 4 apart), and closes
 * gaps of the model itself up to 2 k_outer width_px = 0.5 px wide: faces of a B-rep meet only
 * within their edges' tolerances (linkrods.step: two B-spline faces 4.2e-4 apart, 0.36 px at its
 * mid view, left a crack pixel with a sliver of width_px / 8; a wider one grows silhouettes, and
 * at width_px / 2 Motor-c's whole view had 99.87 % of its edge pixels within 1 px). The sliver
 * lies at its sample's depth, across the loop's image (outer_point).
 * Ribbons are pushed back along their eye rays (images unchanged) by k_push x width_px pixels'
 * worth of their depth slope, so that they show only where no surface is drawn within that
 * depth: a ribbon lies on exact points, up to width_px / 4 from the chords the face is drawn by,
 * and its sliver beyond the loop; in front of a neighbour drawn up to ε_img behind the exact
 * surface it made a dent that read as a depth edge at a grazing view (linkrods close-up through
 * the hierarchy: a 0.3 px dent, 0.6 % of splinewalk's edge pixels farther than 1 px from the
 * reference's). k_push x width_px = ε_img + width_px / 4 covers both.
 * The inner point: the step in (u, v) into the face whose image runs across the loop's image
 * and lies width_px pixels from it (first order, across_loop), then
 *  - cut where the step leaves the face across its own loop (a ray cast in (u, v); none at a
 *    corner it leaves at once): at an acute corner or across a face narrower than the step, the
 *    ribbon would otherwise cover what lies beyond the face (a silhouette grew by up to 1.4 px);
 *  - evaluated on the surface, and halved while the surface bulges more than width_px / 4 on
 *    screen from the chord to it, or its image lands over 2 x width_px from the loop's: a face
 *    seen at a grazing angle needs a long step (not capped: Ball's inner race, foreshortened 30
 *    times at its mid view, had ribbons 0.13 px wide under a cap of 4 x width_px in object size,
 *    and pinholes), which on a curved face leaves the surface (fins of a motor: 1 px and more).
 * An affine face (sw_sg_surface_affine: a plane, the most common face of a CAD model) is exact
 * along any straight (u, v) segment and any grid, so its ribbon takes the loop's vertices only and
 * its inner points by the straight step, with no evaluation in between; the cut at the loop and
 * the near plane are as above (tests/gpu/test_gpu_border_affine.c: the same inner vertices as the
 * sampled path within 1e-5 px).
 * Only the sample's own loop cuts the step: where another loop of the face comes closer than the
 * step (a thin bridge between a hole and the outer boundary), the ribbon may still reach up to
 * width_px beyond the face.
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_PIECES_PER_SEGMENT = 4096 };
static const double k_outer = 0.25; /* of the width: overlap beyond the loop (see above) */
static const double k_push = 0.375; /* of the width: depth push-back in pixels' worth of slope */

typedef struct border_point {
    double p[3];                 /* eye-relative world position */
    double n[3];                 /* world normal (unnormalised) */
    double in[3];                /* world tangent vector pointing into the face (unnormalised) */
    double uv[2];                /* the loop point in face parameters */
    double in_uv[2];             /* the step in (u, v) whose image is `in` (trim lookups too) */
    double d_prev[2], d_next[2]; /* loop directions before and after the sample (equal inside a
                                    segment; at a vertex, its two segments) */
    double scr[2];               /* screen position (thinning), valid when in_front */
    int in_front;
    int away;     /* the surface faces away from the eye here (a closed shell's back) */
    int run_away; /* after thinning: so did every sample from the kept one before to this one */
} border_point;

/* A loop sample in the surface's own space: what a ribbon takes from the surface there, for any
 * view and placement (sw__gpu_border_loop keeps these between frames). */
typedef struct border_sample {
    double uv[2], in_uv[2], d_prev[2], d_next[2]; /* as border_point's */
    double p[3], n[3], in[3];                     /* object space; unused on an affine surface */
} border_sample;

/* in_uv: a direction in (u, v) pointing into the face at this point. */
static void eval_sample(const sw_sg_surface *srf, double u, double v, const double in_uv[2],
                        border_sample *out)
{
    double h[12];
    sw_sg_surface_eval_h1(srf, u, v, h);
    double du[3], dv[3];
    sw_sg_h1_tangents(h, du, dv, out->n);
    for (int k = 0; k < 3; ++k)
        out->p[k] = h[k] / h[3];
    /* du, dv are w^2 S_u, w^2 S_v; `in` is the true derivative along in_uv, so that a length h
     * along `in` (across_loop) is the step h along in_uv in (u, v) that inner_point takes */
    const double w2 = h[3] * h[3];
    for (int k = 0; k < 3; ++k)
        out->in[k] = (du[k] * in_uv[0] + dv[k] * in_uv[1]) / w2;
}

/* The sample placed by `world`, eye-relative. */
static void place_sample(const border_sample *s, const double world[12], const double eye[3],
                         border_point *out)
{
    memcpy(out->uv, s->uv, sizeof out->uv);
    memcpy(out->in_uv, s->in_uv, sizeof out->in_uv);
    memcpy(out->d_prev, s->d_prev, sizeof out->d_prev);
    memcpy(out->d_next, s->d_next, sizeof out->d_next);
    for (int r = 0; r < 3; ++r) {
        const double *m = world + 4 * r;
        out->p[r] = m[0] * s->p[0] + m[1] * s->p[1] + m[2] * s->p[2] + m[3] - eye[r];
        out->n[r] = m[0] * s->n[0] + m[1] * s->n[1] + m[2] * s->n[2];
        out->in[r] = m[0] * s->in[0] + m[1] * s->in[1] + m[2] * s->in[2];
    }
}

/* Eye-relative world position of the surface point at (u, v). */
static void surface_point(const sw_sg_surface *srf, const double world[12], const double eye[3],
                          const double uv[2], double out[3])
{
    double p[3];
    sw_sg_surface_eval(srf, uv[0], uv[1], p);
    for (int r = 0; r < 3; ++r)
        out[r] = world[4 * r] * p[0] + world[4 * r + 1] * p[1] + world[4 * r + 2] * p[2] +
                 world[4 * r + 3] - eye[r];
}

/* Length of a closed uv polyline in cells (du, dv), each segment measured along its longer
 * side in cells: the samples count_samples makes, before rounding up and the per-segment cap. */
static double length_in_cells(const double *uv, size_t n, double du, double dv)
{
    double total = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double *a = uv + 2 * i, *b = uv + 2 * ((i + 1) % n);
        total += fmax(fabs(b[0] - a[0]) / du, fabs(b[1] - a[1]) / dv);
    }
    return total;
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

/* The most samples one ribbon may take: 64 per pixel of the frame's perimeter (a loop 32 times
 * around the frame at one sample per pixel), and never fewer than two per loop vertex. */
size_t sw__gpu_border_budget(const sw__gpu_view *v, size_t n)
{
    const size_t view =
        64u * ((size_t)(v->width > 0 ? v->width : 1) + (size_t)(v->height > 0 ? v->height : 1));
    return view > 2 * n ? view : 2 * n;
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

/* Depth of an eye-relative point along the view direction. */
static double depth_of(const sw__gpu_view *v, const double p[3])
{
    return v->fwd[0] * p[0] + v->fwd[1] * p[1] + v->fwd[2] * p[2];
}

/* A segment from a to b on screen, its direction and squared length made once for the many
 * samples tested against it. */
typedef struct screen_chord {
    double a[2], d[2], l2;
} screen_chord;

static screen_chord chord_of(const double a[2], const double b[2])
{
    screen_chord c = {{a[0], a[1]}, {b[0] - a[0], b[1] - a[1]}, 0.0};
    c.l2 = c.d[0] * c.d[0] + c.d[1] * c.d[1];
    return c;
}

static double dist2_to_chord(const double p[2], const screen_chord *c)
{
    const double *a = c->a, *d = c->d;
    double t = c->l2 > 0.0 ? ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / c->l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double x = p[0] - a[0] - t * d[0], y = p[1] - a[1] - t * d[1];
    return x * x + y * y;
}

/* Drops samples (in place) whose screen image stays within tol_px of the chord between the
 * samples kept around them: the loop is sampled at the grid's cells, far denser than a ribbon
 * needs where it runs straight on screen. Returns the samples kept. */
static size_t thin_samples(const sw__gpu_view *v, border_point *bp, size_t n, double tol_px)
{
    enum { MAX_RUN = 64 };
    for (size_t k = 0; k < n; ++k)
        bp[k].in_front = screen_of(v, bp[k].p, bp[k].scr);
    if (n == 0)
        return 0;
    size_t kept = 1, i = 1;
    while (i < n) {
        size_t end = i; /* extend the run [last kept = input i - 1, end] while every sample fits */
        if (bp[kept - 1].in_front) {
            const double *a = bp[kept - 1].scr;
            while (end + 1 < n && end + 1 - (i - 1) <= MAX_RUN && bp[end + 1].in_front) {
                const screen_chord c = chord_of(a, bp[end + 1].scr);
                int fits = 1;
                for (size_t k = i; k <= end && fits; ++k)
                    fits = bp[k].in_front && dist2_to_chord(bp[k].scr, &c) <= tol_px * tol_px;
                if (!fits)
                    break;
                ++end;
            }
        }
        int away = bp[kept - 1].away; /* the samples the kept ones span: i - 1 .. end */
        for (size_t k = i; k <= end; ++k)
            away &= bp[k].away;
        bp[kept] = bp[end];
        bp[kept++].run_away = away;
        i = end + 1;
    }
    bp[0].run_away = bp[0].away && bp[kept - 1].away; /* the closing chord: input n - 1 to 0 */
    return kept;
}

/* |(x, y)| of screen vectors: hypot guards against overflow and underflow at several times the
 * cost of the plain root (it was 5 % of a building's prepare), so it only takes the cases where
 * the squares leave the range of double. */
static double screen_length(double x, double y)
{
    const double r = sqrt(x * x + y * y);
    return r > 0.0 && r < INFINITY ? r : hypot(x, y);
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

/* ---- the loop's segments in a uniform grid over its (u, v) box, for ray casts ---------------- */
enum { SMALL_LOOP = 16 }; /* segments a ray cast tests one by one (one cell, no allocation) */
typedef struct loop_grid {
    const double *uv;
    size_t n;
    double lo[2], cell[2];
    int32_t g[2];
    double box_lo[2], box_hi[2];                      /* the loop's (u, v) box */
    uint32_t *start;                                  /* g[0] g[1] + 1 offsets into items */
    uint32_t *items;                                  /* segment indices, cell by cell */
    uint32_t small_start[2], small_items[SMALL_LOOP]; /* a small loop's, in place */
} loop_grid;

static int32_t grid_cell(const loop_grid *gr, int k, double x)
{
    double c = floor((x - gr->lo[k]) / gr->cell[k]);
    return c < 0.0 ? 0 : (c >= gr->g[k] ? gr->g[k] - 1 : (int32_t)c);
}

/* Loops over every cell (cx, cy) of the box spanned by points a and b. */
#define FOR_CELLS(gr, a, b, cx, cy)                                                                \
    for (int32_t cy = grid_cell(gr, 1, fmin(a[1], b[1]));                                          \
         cy <= grid_cell(gr, 1, fmax(a[1], b[1])); ++cy)                                           \
        for (int32_t cx = grid_cell(gr, 0, fmin(a[0], b[0]));                                      \
             cx <= grid_cell(gr, 0, fmax(a[0], b[0])); ++cx)

/* A loop of at most SMALL_LOOP segments (a window, a rectangle: most loops of a building) in one
 * cell: testing them all costs less than filing them, and nothing is allocated per ribbon. */
static void loop_grid_small(loop_grid *gr)
{
    gr->g[0] = gr->g[1] = 1;
    gr->cell[0] = gr->cell[1] = 1.0;
    gr->start = gr->small_start;
    gr->items = gr->small_items;
    gr->start[0] = 0;
    gr->start[1] = (uint32_t)gr->n;
    for (size_t i = 0; i < gr->n; ++i)
        gr->items[i] = (uint32_t)i;
}

/* About one segment per cell; segments are filed under every cell their box meets. */
static int loop_grid_build(loop_grid *gr, const double *uv, size_t n)
{
    memset(gr, 0, sizeof *gr);
    gr->uv = uv;
    gr->n = n;
    for (int k = 0; k < 2; ++k)
        gr->box_lo[k] = gr->box_hi[k] = n ? uv[k] : 0.0;
    for (size_t i = 1; i < n; ++i)
        for (int k = 0; k < 2; ++k) {
            gr->box_lo[k] = fmin(gr->box_lo[k], uv[2 * i + k]);
            gr->box_hi[k] = fmax(gr->box_hi[k], uv[2 * i + k]);
        }
    if (n <= SMALL_LOOP) {
        loop_grid_small(gr);
        return 1;
    }
    const double *hi = gr->box_hi;
    gr->lo[0] = gr->box_lo[0];
    gr->lo[1] = gr->box_lo[1];
    int32_t side = (int32_t)ceil(sqrt((double)n));
    side = side < 1 ? 1 : (side > 256 ? 256 : side);
    for (int k = 0; k < 2; ++k) {
        gr->g[k] = hi[k] > gr->lo[k] ? side : 1;
        gr->cell[k] = hi[k] > gr->lo[k] ? (hi[k] - gr->lo[k]) / side : 1.0;
    }
    size_t cells = (size_t)gr->g[0] * (size_t)gr->g[1];
    gr->start = sw__calloc(cells + 1, sizeof *gr->start);
    if (!gr->start)
        return 0;
    size_t total = 0;
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t i = 0; i < n; ++i) {
            const double *a = uv + 2 * i, *b = uv + 2 * ((i + 1) % n);
            FOR_CELLS(gr, a, b, cx, cy)
            {
                size_t c = (size_t)cy * (size_t)gr->g[0] + (size_t)cx;
                if (pass == 0)
                    gr->start[c + 1]++, total++;
                else
                    gr->items[gr->start[c]++] = (uint32_t)i;
            }
        }
        if (pass == 0) {
            if (total > UINT32_MAX ||
                !(gr->items = sw__malloc((total ? total : 1) * sizeof *gr->items)))
                return 0;
            for (size_t c = 0; c < cells; ++c)
                gr->start[c + 1] += gr->start[c];
        } else { /* the fill pass advanced each start to the next cell's: shift back */
            memmove(gr->start + 1, gr->start, cells * sizeof *gr->start);
            gr->start[0] = 0;
        }
    }
    return 1;
}

static void loop_grid_free(loop_grid *gr)
{
    if (gr->start == gr->small_start)
        return;
    sw__free(gr->start);
    sw__free(gr->items);
}

/* Largest s in [0, s_max] with p + s r inside the loop's (u, v) box. A step beyond it leaves the
 * face whatever ray_exit finds (a ray from a corner that leaves the face at once meets no
 * segment), and the surface is extrapolated there: along a degree-1 direction it extends
 * straight, passes inner_point's bulge test, and an inner point lay hundreds of pixels away
 * (Bottom.brep scaled to a diagonal of 10: a sample on a degenerate edge, S_u = 0, whose
 * first-order step was 3e8 in u). */
static double box_exit(const loop_grid *gr, const double p[2], const double r[2], double s_max)
{
    for (int k = 0; k < 2; ++k) {
        if (r[k] > 0.0)
            s_max = fmin(s_max, (gr->box_hi[k] - p[k]) / r[k]);
        else if (r[k] < 0.0)
            s_max = fmin(s_max, (gr->box_lo[k] - p[k]) / r[k]);
    }
    return fmax(s_max, 0.0);
}

/* Smallest s in (0, s_max] at which p + s r crosses a loop segment; s_max if none. Crossings at
 * s <= 1e-9 s_max are the segments p lies on. Segments parallel to r are skipped: a ray along
 * the loop stays on the face's border. */
static double ray_exit(const loop_grid *gr, const double p[2], const double r[2], double s_max)
{
    double q[2] = {p[0] + s_max * r[0], p[1] + s_max * r[1]}, best = s_max;
    double rr = r[0] * r[0] + r[1] * r[1];
    FOR_CELLS(gr, p, q, cx, cy)
    {
        size_t c = (size_t)cy * (size_t)gr->g[0] + (size_t)cx;
        for (uint32_t k = gr->start[c]; k < gr->start[c + 1]; ++k) {
            size_t i = gr->items[k];
            const double *a = gr->uv + 2 * i, *b = gr->uv + 2 * ((i + 1) % gr->n);
            double e[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {a[0] - p[0], a[1] - p[1]};
            double den = r[0] * e[1] - r[1] * e[0];
            if (!(den * den > 1e-24 * rr * (e[0] * e[0] + e[1] * e[1])))
                continue;
            double s = (w[0] * e[1] - w[1] * e[0]) / den, t = (w[0] * r[1] - w[1] * r[0]) / den;
            if (s > 1e-9 * s_max && s < best && t >= 0.0 && t <= 1.0)
                best = s;
        }
    }
    return best;
}

/* side x (a x b) >= 0, with a relative tolerance: b lies on the face's side of direction a. */
static int on_inner_side(const double a[2], const double b[2], double side)
{
    double c = side * (a[0] * b[1] - a[1] * b[0]);
    return c >= 0.0 || c * c <= 1e-24 * (a[0] * a[0] + a[1] * a[1]) * (b[0] * b[0] + b[1] * b[1]);
}

/* Does the step r from sample e start into the face (side: +1 when it lies left of the loop)?
 * At a vertex, into the wedge between its two segments (both sides at a convex corner, either
 * at a reflex one). */
static int starts_inside(const border_point *e, const double r[2], double side)
{
    int a = on_inner_side(e->d_prev, r, side), b = on_inner_side(e->d_next, r, side);
    int convex = side * (e->d_prev[0] * e->d_next[1] - e->d_prev[1] * e->d_next[0]) > 0.0;
    return convex ? a && b : a || b;
}

typedef struct ribbon_ctx {
    const sw__gpu_view *v;
    const sw_sg_surface *srf;
    const double *world;
    const loop_grid *grid;
    double side, width_px;
    const double *st_box; /* trim lookup's rectangle, or NULL (st = 0) */
    int affine;           /* the surface is affine in (u, v); then, in the world: */
    double su[3], sv[3];  /* its derivatives */
    double so[3];         /* its point at (0, 0), eye-relative */
    double sn[3];         /* its normal, scaled as eval_sample's */
} ribbon_ctx;

/* An affine surface (a plane, as CAD files store most faces) needs no evaluation along the step:
 * its world derivatives once per ribbon, from its map o + u du + v dv (object space). */
static void ribbon_affine(ribbon_ctx *c, const double o[3], const double du[3], const double dv[3])
{
    c->affine = 1;
    /* eval_sample's normal is (w^2 S_u) x (w^2 S_v) of the homogeneous form; the weight is one
     * constant on an affine surface */
    const double w = c->srf->cpw[3], w4 = w * w * w * w;
    const double n[3] = {w4 * (du[1] * dv[2] - du[2] * dv[1]), w4 * (du[2] * dv[0] - du[0] * dv[2]),
                         w4 * (du[0] * dv[1] - du[1] * dv[0])};
    for (int r = 0; r < 3; ++r) {
        const double *m = c->world + 4 * r;
        c->su[r] = m[0] * du[0] + m[1] * du[1] + m[2] * du[2];
        c->sv[r] = m[0] * dv[0] + m[1] * dv[1] + m[2] * dv[2];
        c->so[r] = m[0] * o[0] + m[1] * o[1] + m[2] * o[2] + m[3] - c->v->eye[r];
        c->sn[r] = m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
    }
}

/* place_sample on an affine surface: the map itself, no B-spline evaluation (half of a building's
 * ribbon samples lie on planes). */
static void eval_point_affine(const ribbon_ctx *c, double u, double v, const double in_uv[2],
                              border_point *out)
{
    out->uv[0] = u;
    out->uv[1] = v;
    out->in_uv[0] = in_uv[0];
    out->in_uv[1] = in_uv[1];
    for (int r = 0; r < 3; ++r) {
        out->p[r] = c->so[r] + u * c->su[r] + v * c->sv[r];
        out->n[r] = c->sn[r];
        out->in[r] = c->su[r] * in_uv[0] + c->sv[r] * in_uv[1];
    }
}

/* The loop's image at a sample: its screen position and the unit direction of the quad's chord
 * on screen (ok = 0 where either is behind the near plane or the chord's image is a point). */
typedef struct loop_image {
    int ok;
    double at[2], dir[2];
} loop_image;

static loop_image loop_image_of(const border_point *e, const border_point *other)
{
    loop_image li = {0, {e->scr[0], e->scr[1]}, {0.0, 0.0}};
    if (!e->in_front || !other->in_front) /* screen positions from thin_samples */
        return li;
    const double dx = other->scr[0] - li.at[0], dy = other->scr[1] - li.at[1];
    const double l = screen_length(dx, dy);
    li.ok = l > 0.0 && l < INFINITY;
    if (li.ok) {
        li.dir[0] = dx / l;
        li.dir[1] = dy / l;
    }
    return li;
}

/* Whether the image sq lies within `most` pixels of the loop sample's image (or that is
 * unknown): first order fails where the surface turns towards or away from the eye along the step
 * (a fold near a silhouette); a step whose image lands farther is halved. */
static int within_reach(const loop_image *li, const double sq[2], double most)
{
    return !li->ok || screen_length(sq[0] - li->at[0], sq[1] - li->at[1]) <= most;
}

/* The inner point on an affine surface: exact along the step, so no bulge to halve for; halved
 * while it or the chord's middle is behind the near plane, or its image lands more than 2 x
 * width_px from the loop's (within_reach), as for curved ones. */
static double inner_point_affine(const ribbon_ctx *c, const border_point *e, const loop_image *li,
                                 const double r_uv[2], double s, double out[3])
{
    enum { MAX_HALVINGS = 12 };
    for (int k = 0; k < MAX_HALVINGS; ++k, s *= 0.5) {
        double q[3], m[3], sq[2], sm[2];
        for (int i = 0; i < 3; ++i) {
            q[i] = e->p[i] + s * (c->su[i] * r_uv[0] + c->sv[i] * r_uv[1]);
            m[i] = 0.5 * (e->p[i] + q[i]);
        }
        if (screen_of(c->v, q, sq) && screen_of(c->v, m, sm) &&
            within_reach(li, sq, 2.0 * c->width_px)) {
            memcpy(out, q, sizeof q);
            return s;
        }
    }
    return 0.0;
}

/* The inner point of sample e for the step direction r_uv (first-order length h along r_uv):
 * cut at the loop, on the surface, halved while the surface bulges from the chord to it or its
 * image lands more than 2 x width_px from the loop's (within_reach). Returns the step taken along
 * r_uv (0: the inner point is e itself). */
static double inner_point(const ribbon_ctx *c, const border_point *e, const loop_image *li,
                          const double r_uv[2], double h, double out[3])
{
    enum { MAX_HALVINGS = 12 };
    memcpy(out, e->p, 3 * sizeof *out);
    if (!(h > 0.0) || !starts_inside(e, r_uv, c->side))
        return 0.0;
    double s = ray_exit(c->grid, e->uv, r_uv, box_exit(c->grid, e->uv, r_uv, h));
    const double tol = 0.25 * c->width_px;
    if (c->affine)
        return inner_point_affine(c, e, li, r_uv, s, out);
    for (int k = 0; k < MAX_HALVINGS; ++k, s *= 0.5) {
        double uq[2] = {e->uv[0] + s * r_uv[0], e->uv[1] + s * r_uv[1]};
        double um[2] = {e->uv[0] + 0.5 * s * r_uv[0], e->uv[1] + 0.5 * s * r_uv[1]};
        double q[3], m[3], chord[3], sq[2], sm[2], sc[2];
        surface_point(c->srf, c->world, c->v->eye, uq, q);
        surface_point(c->srf, c->world, c->v->eye, um, m);
        for (int i = 0; i < 3; ++i)
            chord[i] = 0.5 * (e->p[i] + q[i]);
        if (screen_of(c->v, q, sq) && screen_of(c->v, m, sm) && screen_of(c->v, chord, sc) &&
            screen_length(sm[0] - sc[0], sm[1] - sc[1]) <= tol &&
            within_reach(li, sq, 2.0 * c->width_px)) {
            memcpy(out, q, sizeof q);
            return s;
        }
    }
    return 0.0;
}

/* The ribbon's step into the face at one end of a quad. */
typedef struct across_step {
    double dir[3], dir_uv[2]; /* `in` less its part along the loop, world and (u, v) */
    double img[2];            /* dir's image per unit of it: across the loop's image */
    double h;                 /* the length along dir whose image is width_px (first order):
                                 infinite where the face is seen exactly edge-on (inner_point cuts
                                 it at the loop's box and halves it); 0 where the loop's image or
                                 the point degenerates */
} across_step;

/* The ribbon's step into the face: the tangent vector `in` (its step in_uv in (u, v)) less its
 * part along the loop (the chord t, t_uv), so that its image runs across the loop's image (first
 * order), and as long as it takes to land width_px pixels across: not capped in object size (see
 * the inner point above). Where the surface's parameters are sheared on screen, `in`'s image runs
 * nearly along the loop: a step along it reached across by a fraction of a pixel (the old 4 x
 * width_px cap), or, uncapped, by width_px only after tens of pixels along the loop, a sliver quad
 * whose depths stood in front of the face (linkrods' close view: 38 depth-edge pixels of its
 * own). */
static across_step across_loop(const sw__gpu_view *v, const double p[3], const double t[3],
                               const double t_uv[2], const double in[3], const double in_uv[2],
                               double width_px)
{
    across_step a = {{0.0, 0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}, 0.0};
    double ts[2], is[2];
    screen_deriv(v, p, t, ts);
    screen_deriv(v, p, in, is);
    const double tt = ts[0] * ts[0] + ts[1] * ts[1];
    const double beta = tt > 0.0 && tt < INFINITY ? (is[0] * ts[0] + is[1] * ts[1]) / tt : 0.0;
    for (int k = 0; k < 3; ++k)
        a.dir[k] = in[k] - beta * t[k];
    a.dir_uv[0] = in_uv[0] - beta * t_uv[0];
    a.dir_uv[1] = in_uv[1] - beta * t_uv[1];
    a.img[0] = is[0] - beta * ts[0];
    a.img[1] = is[1] - beta * ts[1];
    const double across = screen_length(a.img[0], a.img[1]); /* pixels per unit of dir */
    if (depth_of(v, p) > 0.0 && tt > 0.0 && tt < INFINITY)
        a.h = across > 0.0 ? width_px / across : INFINITY;
    return a;
}

/* The outer point of sample e: k_outer x width_px beyond the loop's image, across it, at the
 * sample's depth (pushed back with the quad). Not in the tangent plane: at a grazing view a point
 * k_outer x width_px across the loop lies far along the tangent plane, which leaves a curved
 * surface and stands in front of a neighbour face at a crease; capped in object space it lay a
 * fraction of a pixel across, and between faces meeting along one curve, sampled at different
 * steps, pixel centres fell between the two ribbons' chords (Ball's mid view: 0.17 px apart, 3
 * pinholes). Returns its step along -a->dir to first order, for the trim lookup's (u, v); the
 * sample itself (0) where the loop's image or the step's is degenerate. */
static double outer_point(const ribbon_ctx *c, const border_point *e, const loop_image *li,
                          const across_step *a, double out[3])
{
    memcpy(out, e->p, 3 * sizeof *out);
    double nx = -li->dir[1], ny = li->dir[0], side = nx * a->img[0] + ny * a->img[1];
    if (!li->ok || !(fabs(side) > 0.0))
        return 0.0;
    if (side > 0.0) { /* (nx, ny) points into the face: the outer point lies the other way */
        nx = -nx;
        ny = -ny;
    }
    const double z = depth_of(c->v, e->p);
    const double x = (li->at[0] + k_outer * c->width_px * nx) / c->v->focal_px;
    const double y = (li->at[1] + k_outer * c->width_px * ny) / c->v->focal_px;
    for (int k = 0; k < 3; ++k)
        out[k] = z * (c->v->fwd[k] + x * c->v->right[k] + y * c->v->up[k]);
    return a->h < INFINITY ? -k_outer * a->h : 0.0;
}

/* Depth change per pixel from eye-relative a to b on screen (0 when either is behind the eye or
 * their images coincide). */
static double depth_per_px(const sw__gpu_view *v, const double a[3], const double b[3])
{
    double sa[2], sb[2];
    if (!screen_of(v, a, sa) || !screen_of(v, b, sb))
        return 0.0;
    double px = screen_length(sb[0] - sa[0], sb[1] - sa[1]), dz = 0.0;
    for (int k = 0; k < 3; ++k)
        dz += v->fwd[k] * (b[k] - a[k]);
    return px > 0.0 ? fabs(dz) / px : 0.0;
}

/* Moves the quad's points q[end][side] back along their eye rays (their images stay where they
 * are) by k_push x width_px pixels' worth of the quad's depth slope: the larger of its slopes
 * across the ribbon and along the loop, a lower bound of the gradient within a factor sqrt 2. */
static void push_back(const ribbon_ctx *c, const border_point *const e[2], double q[2][2][3])
{
    double slope = depth_per_px(c->v, e[0]->p, e[1]->p);
    for (int end = 0; end < 2; ++end)
        slope = fmax(slope, depth_per_px(c->v, q[end][0], q[end][1]));
    double dz = k_push * c->width_px * slope;
    for (int end = 0; end < 2; ++end)
        for (int side = 0; side < 2; ++side) {
            double *p = q[end][side], z = depth_of(c->v, p);
            double s = z > 0.0 ? 1.0 + dz / z : 1.0;
            for (int k = 0; k < 3; ++k)
                p[k] *= s;
        }
}

/* The point of chord keep -> behind (keep in front of the near plane, behind not) at depth
 * near_plane x (1 + margin), its fields interpolated along the chord (exact on an affine
 * surface), its loop direction the chord's (dir, in loop order). 0 when there is none. An end
 * behind the near plane takes no step (nothing of it is on screen), so a ribbon tapered to nothing
 * along the visible part of a loop segment reaching past the near plane: a plane seen from near
 * its far edge showed a crack pixel there once trim textures no longer grew faces by a texel. What
 * lies nearer than the plane is clipped anyway. */
static int clip_to_near(const sw__gpu_view *v, const border_point *keep, const border_point *behind,
                        const double dir[2], double margin, border_point *out)
{
    const double za = depth_of(v, keep->p), zb = depth_of(v, behind->p);
    const double z = v->near_plane * (1.0 + margin);
    if (!(za > z) || !(zb < za))
        return 0;
    const double t = (za - z) / (za - zb), k = 1.0 - t;
    for (int i = 0; i < 3; ++i) {
        out->p[i] = k * keep->p[i] + t * behind->p[i];
        out->n[i] = k * keep->n[i] + t * behind->n[i];
        out->in[i] = k * keep->in[i] + t * behind->in[i];
    }
    for (int i = 0; i < 2; ++i) {
        out->uv[i] = k * keep->uv[i] + t * behind->uv[i];
        out->in_uv[i] = k * keep->in_uv[i] + t * behind->in_uv[i];
        out->d_prev[i] = out->d_next[i] = dir[i];
    }
    out->in_front = screen_of(v, out->p, out->scr);
    return out->in_front;
}

/* A quad's two ends: outer [0] and inner [1] points, their steps along dir_uv, and the first-order
 * step h that reaches width_px across. */
typedef struct quad_ends {
    double q[2][2][3], step[2][2], dir_uv[2][2], h[2];
} quad_ends;

static void quad_ends_of(const ribbon_ctx *c, const border_point *const e[2], quad_ends *qe)
{
    double t[3] = {e[1]->p[0] - e[0]->p[0], e[1]->p[1] - e[0]->p[1], e[1]->p[2] - e[0]->p[2]};
    const double t_uv[2] = {e[1]->uv[0] - e[0]->uv[0], e[1]->uv[1] - e[0]->uv[1]};
    for (int end = 0; end < 2; ++end) {
        const loop_image li = loop_image_of(e[end], e[1 - end]);
        const across_step a =
            across_loop(c->v, e[end]->p, t, t_uv, e[0]->in, e[0]->in_uv, c->width_px);
        memcpy(qe->dir_uv[end], a.dir_uv, sizeof a.dir_uv);
        qe->h[end] = a.h;
        qe->step[end][1] = inner_point(c, e[end], &li, a.dir_uv, a.h, qe->q[end][1]);
        qe->step[end][0] = outer_point(c, e[end], &li, &a, qe->q[end][0]);
    }
}

/* A quad's ends with an end behind the near plane moved in front of it (clip_to_near): at the
 * plane, or farther when the step into the face from there runs back behind it (it is then cut
 * short): the margins tried in turn. */
static void quad_ends_clipped(const ribbon_ctx *c, const border_point *const e_in[2],
                              border_point *clipped, const border_point **e, quad_ends *qe)
{
    static const double k_margins[] = {1e-4, 1e-3, 1e-2, 5e-2};
    const int n = (int)(sizeof k_margins / sizeof k_margins[0]);
    e[0] = e_in[0];
    e[1] = e_in[1];
    const int b = e_in[0]->in_front; /* the end behind */
    const double dir[2] = {e_in[1]->uv[0] - e_in[0]->uv[0], e_in[1]->uv[1] - e_in[0]->uv[1]};
    for (int k = 0; k < n; ++k) {
        e[b] = clip_to_near(c->v, e_in[1 - b], e_in[b], dir, k_margins[k], clipped) ? clipped
                                                                                    : e_in[b];
        quad_ends_of(c, e, qe);
        if (e[b] != clipped || !(qe->step[b][1] < 0.5 * qe->h[b]))
            return;
    }
}

/* One quad per loop segment, from k_outer x width_px outside the loop (outer_point) to the inner
 * points, across the loop's image (across_loop), pushed back (push_back); an end behind the near
 * plane moved in front of it (quad_ends_clipped). Quads of consecutive segments share their points
 * on the loop on screen; their inner edges are not joined, which keeps a sharp corner of the loop
 * from folding a quad across it. */
static void emit_ribbon(const ribbon_ctx *c, const border_point *bp, size_t n, sw__gpu_mesh *mesh)
{
    for (size_t i = 0; i < n; ++i) {
        const border_point *e_in[2] = {&bp[i], &bp[(i + 1) % n]}, *e[2] = {e_in[0], e_in[1]};
        if (e_in[1]->run_away) { /* hidden by the shell's front (sample_facing_away) */
            mesh->border_quads_away++;
            continue;
        }
        border_point clipped;
        quad_ends qe;
        if (e_in[0]->in_front != e_in[1]->in_front)
            quad_ends_clipped(c, e_in, &clipped, e, &qe);
        else
            quad_ends_of(c, e, &qe);
        push_back(c, e, qe.q);
        uint32_t base = (uint32_t)mesh->n_v;
        for (int end = 0; end < 2; ++end) {
            for (int side = 0; side < 2; ++side) {
                sw__gpu_vertex *o = &mesh->v[mesh->n_v++];
                for (int k = 0; k < 3; ++k) {
                    o->pos[k] = (float)qe.q[end][side][k];
                    o->nrm[k] = (float)e[end]->n[k];
                }
                o->st[0] = o->st[1] = 0.0f;
                if (c->st_box) { /* inner point: its exact (u, v); outer: to first order */
                    const double *b = c->st_box, *d = qe.dir_uv[end];
                    double s = qe.step[end][side];
                    o->st[0] = (float)((e[end]->uv[0] + s * d[0] - b[0]) / (b[1] - b[0]));
                    o->st[1] = (float)((e[end]->uv[1] + s * d[1] - b[2]) / (b[3] - b[2]));
                }
            }
        }
        uint32_t *o = mesh->idx + mesh->n_idx;
        o[0] = base, o[1] = base + 1, o[2] = base + 3, o[3] = base, o[4] = base + 3,
        o[5] = base + 2;
        mesh->n_idx += 6;
    }
}

/* Direction of the last segment of length > 0 ending at vertex i (zero if the loop has none). */
static void prev_direction(const double *uv, size_t n, size_t i, double out[2])
{
    out[0] = out[1] = 0.0;
    for (size_t k = 1; k <= n && out[0] == 0.0 && out[1] == 0.0; ++k) {
        size_t j = (i + n - k) % n;
        const double *a = uv + 2 * j, *b = uv + 2 * ((j + 1) % n);
        out[0] = b[0] - a[0];
        out[1] = b[1] - a[1];
    }
}

struct sw__gpu_border_loop {
    sw_sg_surface srf;
    const double *uv; /* the caller's loop, n points */
    size_t n, n_samples;
    int left_inside;
    int capped; /* sampled coarser than asked, to stay within the sample budget */
    int affine; /* the surface is o + u du + v dv (object space): */
    double aff_o[3], aff_du[3], aff_dv[3];
    loop_grid grid;
    border_sample *s;
};

/* The loop's samples: each segment cut into pieces no longer than (du, dv), each piece's start
 * sampled (on an affine surface only its (u, v), placed per view). */
static void sample_loop(sw__gpu_border_loop *bl, double du, double dv)
{
    const double *uv = bl->uv;
    const size_t n = bl->n;
    size_t at = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *a = uv + 2 * i, *b = uv + 2 * ((i + 1) % n);
        double k = fmax(fabs(b[0] - a[0]) / du, fabs(b[1] - a[1]) / dv);
        int32_t pieces = (int32_t)ceil(fmin(fmax(k, 1.0), (double)MAX_PIECES_PER_SEGMENT));
        double t[2] = {b[0] - a[0], b[1] - a[1]}, before[2];
        double in_uv[2] = {bl->left_inside ? -t[1] : t[1], bl->left_inside ? t[0] : -t[0]};
        prev_direction(uv, n, i, before);
        for (int32_t j = 0; j < pieces; ++j, ++at) {
            border_sample *o = &bl->s[at];
            double f = (double)j / pieces;
            o->uv[0] = a[0] + f * t[0];
            o->uv[1] = a[1] + f * t[1];
            memcpy(o->in_uv, in_uv, sizeof in_uv);
            memcpy(o->d_prev, j == 0 ? before : t, sizeof before);
            memcpy(o->d_next, t, sizeof t);
            if (!bl->affine)
                eval_sample(&bl->srf, o->uv[0], o->uv[1], in_uv, o);
        }
    }
}

sw_result sw__gpu_border_loop_make(const sw_sg_surface *srf, const double *uv, size_t n,
                                   int left_inside, double du, double dv, int affine,
                                   size_t max_samples, sw__gpu_border_loop **out, sw_status *status)
{
    *out = NULL;
    sw__gpu_border_loop *bl = sw__calloc(1, sizeof *bl);
    if (!bl)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "fat border: out of memory");
    bl->srf = *srf;
    bl->uv = uv;
    bl->n = n;
    bl->left_inside = left_inside;
    bl->affine = affine && sw_sg_surface_affine(srf, bl->aff_o, bl->aff_du, bl->aff_dv);
    /* On an affine surface a straight uv segment is a straight line on screen, drawn exactly by
     * any grid: its ribbon needs its ends only (thinning would drop every sample between). */
    if (bl->affine)
        du = dv = INFINITY;
    size_t m = count_samples(uv, n, du, dv);
    /* The cap from the request: the view's pixels bound the samples a ribbon can use;
     * cells shrunk by a deep refinement (fovy 1e-9 grew memory at ~600 MB/s here) are widened
     * until the loop fits. A segment of L cells takes at most L + 1 samples after widening by
     * f, L / f + 1, so f = (sum of L) / (budget - n) keeps m <= budget (n <= budget / 2 by
     * sw__gpu_border_budget). The sum is taken before the per-segment cap: scaled by the capped
     * count, a loop of 748k vertices in cells of 7e-16 still asked for 3e9 samples. */
    if (m > max_samples) {
        const double room = max_samples > n ? (double)(max_samples - n) : 0.0;
        const double widen = room > 0.0 ? length_in_cells(uv, n, du, dv) / room : INFINITY;
        du *= widen;
        dv *= widen;
        m = count_samples(uv, n, du, dv);
        bl->capped = 1;
    }
    bl->n_samples = m;
    bl->s = sw__malloc((m ? m : 1) * sizeof *bl->s);
    if (!bl->s || !loop_grid_build(&bl->grid, uv, n)) {
        sw__gpu_border_loop_free(bl);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "fat border: out of memory");
    }
    sample_loop(bl, du, dv);
    *out = bl;
    return SW_OK;
}

void sw__gpu_border_loop_free(sw__gpu_border_loop *bl)
{
    if (!bl)
        return;
    loop_grid_free(&bl->grid);
    sw__free(bl->s);
    sw__free(bl);
}

size_t sw__gpu_border_loop_samples(const sw__gpu_border_loop *bl)
{
    return bl->n_samples;
}

size_t sw__gpu_border_loop_bytes(const sw__gpu_border_loop *bl)
{
    const loop_grid *g = &bl->grid;
    size_t grid = 0;
    if (g->start != g->small_start)
        grid = ((size_t)g->g[0] * (size_t)g->g[1] + 1) * sizeof *g->start +
               (size_t)g->start[(size_t)g->g[0] * (size_t)g->g[1]] * sizeof *g->items;
    return sizeof *bl + bl->n_samples * sizeof *bl->s + grid;
}

/* 1 when the surface at object point p with normal n (S_u x S_v, any positive scale) faces away
 * from the eye by more than k_away, on a face bounding a closed shell seen from outside. Such a
 * point is hidden: the eye ray to it leaves the solid there, so it entered it before, through a
 * surface facing the eye, which is drawn within ε_img and whose own cracks its own ribbons cover
 * (where that front surface ends at a silhouette crease, its ribbon covers the pixels on its
 * side, which is the side a back face folds under). A ribbon quad is left out only when every
 * sample it spans faces away; the margin keeps the ribbons along smooth silhouettes, where the
 * normal turns between samples. */
static int sample_facing_away(const sw__gpu_ribbon_facing *f, const double p[3], const double n[3])
{
    static const double k_away = 0.1; /* cosine beyond the silhouette: about 6 degrees */
    const double d[3] = {f->eye[0] - p[0], f->eye[1] - p[1], f->eye[2] - p[2]};
    const double dn = f->outward * (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
    const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    return dn < 0.0 && dn * dn > k_away * k_away * nn * dd;
}

/* Marks the samples facing away (none without `facing`). */
static void mark_away(const sw__gpu_border_loop *bl, const sw__gpu_ribbon_facing *f,
                      border_point *bp)
{
    const double *o = bl->aff_o, *du = bl->aff_du, *dv = bl->aff_dv;
    const double aff_n[3] = {du[1] * dv[2] - du[2] * dv[1], du[2] * dv[0] - du[0] * dv[2],
                             du[0] * dv[1] - du[1] * dv[0]}; /* an affine surface's one normal */
    for (size_t i = 0; i < bl->n_samples; ++i) {
        const border_sample *s = &bl->s[i];
        double p[3];
        for (int k = 0; bl->affine && k < 3; ++k) /* affine samples keep only their (u, v) */
            p[k] = o[k] + s->uv[0] * du[k] + s->uv[1] * dv[k];
        bp[i].away =
            f && (bl->affine ? sample_facing_away(f, p, aff_n) : sample_facing_away(f, s->p, s->n));
    }
}

sw_result sw__gpu_fat_border_of(const sw__gpu_view *v, const double world[12],
                                const sw__gpu_border_loop *bl, double width_px,
                                const double *st_box, const sw__gpu_ribbon_facing *facing,
                                sw__gpu_mesh *mesh, sw_status *status)
{
    const size_t m = bl->n_samples;
    mesh->border_capped += (uint64_t)bl->capped;
    sw_result r = sw__gpu_mesh_reserve(mesh, 4 * m, 6 * m, status);
    if (r != SW_OK)
        return r;
    border_point *bp = sw__malloc((m ? m : 1) * sizeof *bp);
    if (!bp)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "fat border: out of memory");
    ribbon_ctx c = {.v = v,
                    .srf = &bl->srf,
                    .world = world,
                    .grid = &bl->grid,
                    .side = bl->left_inside ? 1.0 : -1.0,
                    .width_px = width_px,
                    .st_box = st_box};
    if (bl->affine)
        ribbon_affine(&c, bl->aff_o, bl->aff_du, bl->aff_dv);
    for (size_t i = 0; i < m; ++i) {
        const border_sample *s = &bl->s[i];
        if (c.affine) {
            eval_point_affine(&c, s->uv[0], s->uv[1], s->in_uv, &bp[i]);
            memcpy(bp[i].d_prev, s->d_prev, sizeof s->d_prev);
            memcpy(bp[i].d_next, s->d_next, sizeof s->d_next);
        } else {
            place_sample(s, world, v->eye, &bp[i]);
        }
    }
    mark_away(bl, facing, bp);
    emit_ribbon(&c, bp, thin_samples(v, bp, m, 0.25 * width_px), mesh);
    sw__free(bp);
    return SW_OK;
}

sw_result sw__gpu_fat_border(const sw__gpu_view *v, const sw_sg_surface *srf,
                             const double world[12], const double *uv, size_t n, int left_inside,
                             double du, double dv, double width_px, const double *st_box,
                             int affine, const sw__gpu_ribbon_facing *facing, sw__gpu_mesh *mesh,
                             sw_status *status)
{
    if (n < 2 || !(du > 0.0) || !(dv > 0.0))
        return SW_OK;
    sw__gpu_border_loop *bl = NULL;
    sw_result r = sw__gpu_border_loop_make(srf, uv, n, left_inside, du, dv, affine,
                                           sw__gpu_border_budget(v, n), &bl, status);
    if (r == SW_OK)
        r = sw__gpu_fat_border_of(v, world, bl, width_px, st_box, facing, mesh, status);
    sw__gpu_border_loop_free(bl);
    return r;
}

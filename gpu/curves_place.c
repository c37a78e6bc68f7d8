/* SPDX-License-Identifier: MIT */
/* Outlines placed in 3D (sw_curves.h, sw__curves_project): a planar outline's loops mapped
 * through the camera into exact outlines in target pixels, which the 2D path then draws
 * anti-aliased (Santana §3-§5).
 *
 * Why this is exact: the map from a plane to the screen is a projective map of the plane, so a
 * rational Bézier piece maps to a rational Bézier piece of the same degree whose homogeneous
 * control points are the images of its own (Farin, Curves and Surfaces for CAGD, ch. 16): lines
 * stay lines, conics stay conics (drawn exactly), cubics become rational cubics (drawn through the
 * 2D path's bounded Hermite approximation, 1/256 px). Nothing is flattened.
 *
 * The map is only projective in front of the eye. Each loop is first cut to the half-plane of the
 * plane in front of the near plane, then to a guard band around the target (its larger side on
 * every side: it keeps screen coordinates, and the pieces an approximation needs, bounded
 * however large the outline is). Cutting a loop at a line keeps its kept arcs in order and joins
 * each exit point to the next entry point by a segment along the line: for a point strictly
 * inside the half-plane, a ray parallel to the line crosses the new loop exactly where it
 * crossed the old one, so even-odd parity, hence the fill, is the old one's there.
 *
 * Roots of the cut function along a piece come from its Bernstein coefficients (variation
 * diminishing: no sign change, no root), bisected to 1e-13 of the piece's parameter, depth 60.
 * After the cuts every curve point is in front of the near plane, but a control point may not be:
 * pieces are halved until every control point's depth is at least a quarter of the near plane
 * (its weight in pixels then is positive), at most SPLIT_CAP times each and SPLIT_BUDGET times in
 * all; a piece still short of it is replaced by its chord and counted (`fallbacks`).
 */
#include "sw_curves.h"
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <string.h>

enum {
    ROOT_DEPTH = 60, /* bisection levels of a root: 2^-60 of the piece's parameter */
    SPLIT_CAP = 24,  /* halvings of a piece for positive projected weights */
    /* halvings for positive weights in one outline, all pieces together: splitting is only
     * needed next to the near plane's cut and ends after a few levels there, but a piece
     * crossing behind the eye (cut data gone wrong) would split into 2^SPLIT_CAP pieces */
    SPLIT_BUDGET = 1 << 14,
};
#define ROOT_WIDTH 1e-13  /* parameter width at which a root is taken as found */
#define SUB_MIN 1e-12     /* sub-pieces narrower than this (parameter) are dropped */
#define WEIGHT_FLOOR 0.25 /* of the near plane: a control point's least depth after splitting */
#define GUARD_SIDES 1.0   /* the guard band: the target grown by this times its larger side */

/* A rational Bézier piece in a growing pool of homogeneous doubles (x w, y w, w). */
typedef struct bez {
    int32_t p;
    size_t at; /* offset of its (p + 1) * 3 doubles */
} bez;

typedef struct loop_set {
    bez *pieces;
    size_t n, cap;
    size_t *loop_end; /* pieces [loop_end[L - 1], loop_end[L]) form loop L */
    size_t cap_loops;
    uint32_t n_loops;
} loop_set;

typedef struct place_ctx {
    double *pool;
    size_t n_pool, cap_pool;
    int oom;
    uint32_t fallbacks;
    uint32_t splits; /* halvings made for positive weights (at most SPLIT_BUDGET) */
} place_ctx;

static double *pool_take(place_ctx *c, size_t k, size_t *at)
{
    if (!sw__grow((void **)&c->pool, &c->cap_pool, c->n_pool + k, sizeof *c->pool)) {
        c->oom = 1;
        return NULL;
    }
    *at = c->n_pool;
    c->n_pool += k;
    return c->pool + *at;
}

static int push_piece(place_ctx *c, loop_set *s, int32_t p, const double *h)
{
    size_t at;
    double *dst = pool_take(c, 3 * (size_t)(p + 1), &at);
    if (!dst || !sw__grow((void **)&s->pieces, &s->cap, s->n + 1, sizeof *s->pieces)) {
        c->oom = 1;
        return 0;
    }
    memcpy(dst, h, sizeof(double) * 3 * (size_t)(p + 1));
    s->pieces[s->n++] = (bez){p, at};
    return 1;
}

/* Ends the loop being appended at the pieces appended so far (an empty loop is not ended). */
static void end_loop(place_ctx *c, loop_set *s)
{
    size_t first = s->n_loops ? s->loop_end[s->n_loops - 1] : 0;
    if (c->oom || s->n == first)
        return;
    if (!sw__grow((void **)&s->loop_end, &s->cap_loops, s->n_loops + 1, sizeof *s->loop_end)) {
        c->oom = 1;
        return;
    }
    s->loop_end[s->n_loops++] = s->n;
}

static void loop_set_free(loop_set *s)
{
    sw__free(s->pieces);
    sw__free(s->loop_end);
    memset(s, 0, sizeof *s);
}

static void euclid(const double *h, double out[2])
{
    out[0] = h[0] / h[2];
    out[1] = h[1] / h[2];
}

/* ---- the source loops as Bézier pieces ------------------------------------------------------- */

static void add_bezier(void *ctx, const double *h, int32_t p)
{
    void **pair = ctx;
    push_piece(pair[0], pair[1], p, h);
}

static sw_result source_pieces(place_ctx *c, const sw__curves_loop *loops, uint32_t n_loops,
                               loop_set *out, sw_status *status)
{
    for (uint32_t L = 0; L < n_loops; ++L) {
        for (uint32_t k = 0; k < loops[L].n_curves; ++k) {
            void *pair[2] = {c, out};
            sw_result r = sw__curves_for_each_bezier(&loops[L].curves[k], add_bezier, pair, status);
            if (r != SW_OK)
                return r;
        }
        end_loop(c, out);
    }
    return c->oom ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "placed outline: out of memory") : SW_OK;
}

/* ---- cutting a loop at a line ------------------------------------------------------------------
 * The half-plane kept: f[0] x + f[1] y + f[2] >= 0, in homogeneous form f . (x w, y w, w). */

typedef struct roots {
    double t[64];
    int n;
} roots;

static void add_root(roots *r, double t)
{
    if (r->n > 0 && t - r->t[r->n - 1] < SUB_MIN)
        return;
    if (r->n < (int)(sizeof r->t / sizeof r->t[0]))
        r->t[r->n++] = t;
}

static int sign_changes(const double *g, int32_t p)
{
    int n = 0, last = 0;
    for (int32_t i = 0; i <= p; ++i) {
        int s = g[i] > 0.0 ? 1 : g[i] < 0.0 ? -1 : 0;
        if (s != 0 && last != 0 && s != last)
            n++;
        if (s != 0)
            last = s;
    }
    return n;
}

/* Roots in (t0, t1) of the scalar Bernstein polynomial g (degree p) over [t0, t1], ascending. */
static void bernstein_roots(const double *g, int32_t p, double t0, double t1, int depth, roots *r)
{
    if (sign_changes(g, p) == 0)
        return;
    if (t1 - t0 < ROOT_WIDTH || depth >= ROOT_DEPTH) {
        if ((g[0] <= 0.0) != (g[p] <= 0.0))
            add_root(r, 0.5 * (t0 + t1));
        return;
    }
    double l[SW_SG_MAX_DEGREE + 1], rt[SW_SG_MAX_DEGREE + 1];
    sw_lod_bez_subdivide(p, 0, 1, g, 0, 0.5, l, rt);
    double m = 0.5 * (t0 + t1);
    bernstein_roots(l, p, t0, m, depth + 1, r);
    bernstein_roots(rt, p, m, t1, depth + 1, r);
}

static double cut_value(const double f[3], const double *h)
{
    return f[0] * h[0] + f[1] * h[1] + f[2] * h[2];
}

/* A piece of the loop being cut: the source piece restricted to [t0, t1], kept or not. */
typedef struct sub {
    size_t piece;
    double t0, t1;
    int kept;
} sub;

static int push_sub(place_ctx *c, sub **subs, size_t *n, size_t *cap, sub s)
{
    if (!sw__grow((void **)subs, cap, *n + 1, sizeof **subs)) {
        c->oom = 1;
        return 0;
    }
    (*subs)[(*n)++] = s;
    return 1;
}

/* The sub-pieces of piece `i` between the roots of the cut function, each kept or not. */
static void split_piece(place_ctx *c, const loop_set *in, size_t i, const double f[3], sub **subs,
                        size_t *n, size_t *cap)
{
    const bez *b = &in->pieces[i];
    const double *h = c->pool + b->at;
    double g[SW_SG_MAX_DEGREE + 1];
    int pos = 0, neg = 0;
    for (int32_t k = 0; k <= b->p; ++k) {
        g[k] = cut_value(f, h + 3 * k);
        pos |= g[k] > 0.0;
        neg |= g[k] < 0.0;
    }
    if (!neg || !pos) {
        push_sub(c, subs, n, cap, (sub){i, 0.0, 1.0, !neg});
        return;
    }
    roots r = {.n = 0};
    bernstein_roots(g, b->p, 0.0, 1.0, 0, &r);
    double at = 0.0;
    for (int k = 0; k <= r.n; ++k) {
        double end = k < r.n ? r.t[k] : 1.0;
        if (end - at < SUB_MIN && k < r.n)
            continue;
        double mid[1], gm = 0.5 * (at + end);
        sw_lod_bez_eval(b->p, 0, 1, g, gm, 0.0, mid);
        if (!push_sub(c, subs, n, cap, (sub){i, at, end, mid[0] >= 0.0}))
            return;
        at = end;
    }
}

/* The restriction of piece s to its parameter range, appended to out. */
static int emit_sub(place_ctx *c, const loop_set *in, const sub *s, loop_set *out)
{
    const bez *b = &in->pieces[s->piece];
    double h[3 * (SW_SG_MAX_DEGREE + 1)];
    const double range[4] = {s->t0, s->t1, 0.0, 1.0};
    sw_lod_bez_restrict(b->p, 0, 3, c->pool + b->at, range, h);
    return push_piece(c, out, b->p, h);
}

static void sub_point(place_ctx *c, const loop_set *in, const sub *s, int at_end, double out[2])
{
    const bez *b = &in->pieces[s->piece];
    double h[3];
    sw_lod_bez_eval(b->p, 0, 3, c->pool + b->at, at_end ? s->t1 : s->t0, 0.0, h);
    euclid(h, out);
}

static int emit_line(place_ctx *c, loop_set *out, const double a[2], const double e[2])
{
    if (a[0] == e[0] && a[1] == e[1])
        return 1;
    const double h[6] = {a[0], a[1], 1.0, e[0], e[1], 1.0};
    return push_piece(c, out, 1, h);
}

/* Loop [first, end) of `in` cut to the half-plane, appended to `out` as a loop (or nothing). */
static void cut_loop(place_ctx *c, const loop_set *in, size_t first, size_t end, const double f[3],
                     loop_set *out)
{
    sub *subs = NULL;
    size_t n = 0, cap = 0;
    for (size_t i = first; i < end && !c->oom; ++i)
        split_piece(c, in, i, f, &subs, &n, &cap);
    size_t start = n; /* a kept sub whose predecessor is dropped */
    int any_kept = 0, any_dropped = 0;
    for (size_t k = 0; k < n; ++k) {
        any_kept |= subs[k].kept;
        any_dropped |= !subs[k].kept;
        if (subs[k].kept && !subs[(k + n - 1) % n].kept && start == n)
            start = k;
    }
    if (c->oom || !any_kept) {
        /* nothing of the loop is kept */
    } else if (!any_dropped) {
        for (size_t k = 0; k < n && !c->oom; ++k)
            emit_sub(c, in, &subs[k], out);
    } else {
        double exit_pt[2], entry[2], first_entry[2];
        sub_point(c, in, &subs[start], 0, first_entry);
        int outside = 0;
        for (size_t j = 0; j < n && !c->oom; ++j) {
            const sub *s = &subs[(start + j) % n];
            if (!s->kept) {
                outside = 1;
                continue;
            }
            if (outside) {
                sub_point(c, in, s, 0, entry);
                emit_line(c, out, exit_pt, entry);
                outside = 0;
            }
            emit_sub(c, in, s, out);
            sub_point(c, in, s, 1, exit_pt);
        }
        emit_line(c, out, exit_pt, first_entry); /* the run before `start` was dropped */
    }
    sw__free(subs);
    end_loop(c, out);
}

static void cut_set(place_ctx *c, const loop_set *in, const double f[3], loop_set *out)
{
    for (uint32_t L = 0; L < in->n_loops && !c->oom; ++L)
        cut_loop(c, in, L ? in->loop_end[L - 1] : 0, in->loop_end[L], f, out);
}

/* ---- the projection ------------------------------------------------------------------------ */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A linear function of eye-relative world points on the plane, as a function of the plane's
 * homogeneous coordinates (x w, y w, w). */
static void on_plane(const sw__curves_plane *pl, const double dir[3], double scale, double out[3])
{
    out[0] = scale * dot3(dir, pl->ax);
    out[1] = scale * dot3(dir, pl->ay);
    out[2] = scale * dot3(dir, pl->origin);
}

/* The projection's rows: depth d (along the view axis), and the pixel coordinates times d. */
typedef struct proj_rows {
    double d[3], px[3], py[3];
} proj_rows;

static void projection_rows(const sw__curves_plane *pl, const sw__gpu_view *v, proj_rows *r)
{
    double rx[3], uy[3];
    on_plane(pl, v->fwd, 1.0, r->d);
    on_plane(pl, v->right, 0.5 * v->width / v->tan_x, rx);
    on_plane(pl, v->up, 0.5 * v->height / v->tan_y, uy);
    for (int k = 0; k < 3; ++k) {
        r->px[k] = rx[k] + 0.5 * v->width * r->d[k];
        r->py[k] = uy[k] + 0.5 * v->height * r->d[k];
    }
}

/* The cut functions: in front of the near plane, then the guard band's four sides
 * (px >= -B, px <= width + B, likewise y; multiplied by d > 0, which the near cut ensured). */
static int cut_functions(const proj_rows *r, const sw__gpu_view *v, double f[5][3])
{
    double guard = GUARD_SIDES * (double)(v->width > v->height ? v->width : v->height);
    for (int k = 0; k < 3; ++k) {
        f[0][k] = r->d[k];
        f[1][k] = r->px[k] + guard * r->d[k];
        f[2][k] = (v->width + guard) * r->d[k] - r->px[k];
        f[3][k] = r->py[k] + guard * r->d[k];
        f[4][k] = (v->height + guard) * r->d[k] - r->py[k];
    }
    f[0][2] -= v->near_plane;
    return 5;
}

/* Halves piece h (degree p) until every control point lies at depth >= WEIGHT_FLOOR * near, then
 * appends its projection (homogeneous pixels) to out; a piece still short after SPLIT_CAP
 * halvings is replaced by its chord (its end points are on the curve, in front). */
static void project_piece(place_ctx *c, const proj_rows *r, double near_plane, const double *h,
                          int32_t p, int depth, loop_set *out)
{
    int ok = 1;
    for (int32_t k = 0; k <= p; ++k)
        ok &= cut_value(r->d, h + 3 * k) >= WEIGHT_FLOOR * near_plane * h[3 * k + 2];
    if (!ok && depth < SPLIT_CAP && c->splits < SPLIT_BUDGET) {
        c->splits++;
        double l[3 * (SW_SG_MAX_DEGREE + 1)], rt[3 * (SW_SG_MAX_DEGREE + 1)];
        sw_lod_bez_subdivide(p, 0, 3, h, 0, 0.5, l, rt);
        project_piece(c, r, near_plane, l, p, depth + 1, out);
        project_piece(c, r, near_plane, rt, p, depth + 1, out);
        return;
    }
    double chord[6], q[3 * (SW_SG_MAX_DEGREE + 1)];
    if (!ok) {
        c->fallbacks++;
        memcpy(chord, h, 3 * sizeof(double));
        memcpy(chord + 3, h + 3 * p, 3 * sizeof(double));
        h = chord;
        p = 1;
    }
    for (int32_t k = 0; k <= p; ++k) {
        q[3 * k] = cut_value(r->px, h + 3 * k);
        q[3 * k + 1] = cut_value(r->py, h + 3 * k);
        q[3 * k + 2] = cut_value(r->d, h + 3 * k);
    }
    push_piece(c, out, p, q);
}

/* The plane's depth on the screen: along the ray through pixel point (px, py), eye-relative
 * direction fwd + u right + v up (u, v the pixel's tangents), the plane n . P = n . origin is met
 * at view-axis distance d = (n . origin) / (n . dir), so 1 / d is affine in (px, py).
 * 0: the plane passes through the eye (seen edge-on, it covers no pixel). */
static int plane_depth(const sw__curves_plane *pl, const sw__gpu_view *v, sw__curves_depth *out)
{
    const double n[3] = {pl->ax[1] * pl->ay[2] - pl->ax[2] * pl->ay[1],
                         pl->ax[2] * pl->ay[0] - pl->ax[0] * pl->ay[2],
                         pl->ax[0] * pl->ay[1] - pl->ax[1] * pl->ay[0]};
    double n_o = dot3(n, pl->origin);
    if (!(fabs(n_o) > 0.0))
        return 0;
    double nr = dot3(n, v->right) * v->tan_x, nu = dot3(n, v->up) * v->tan_y;
    out->inv_d[0] = 2.0 * nr / (v->width * n_o);
    out->inv_d[1] = 2.0 * nu / (v->height * n_o);
    out->inv_d[2] = (dot3(n, v->fwd) - nr - nu) / n_o;
    out->near_plane = v->near_plane;
    return 1;
}

/* The projected pieces as clamped Bézier curves, one sw__curves_loop per loop, and the shape. */
static sw_result make_shape(place_ctx *c, const loop_set *s, sw__curves_shape **out,
                            sw_status *status)
{
    size_t n_knots = 0;
    for (size_t i = 0; i < s->n; ++i)
        n_knots += 2 * (size_t)(s->pieces[i].p + 1);
    double *knots = sw__malloc((n_knots ? n_knots : 1) * sizeof *knots);
    sw_sg_curve *curves = sw__malloc((s->n ? s->n : 1) * sizeof *curves);
    sw__curves_loop *loops = sw__malloc((s->n_loops ? s->n_loops : 1) * sizeof *loops);
    sw_result r = SW_OK;
    if (!knots || !curves || !loops) {
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "placed outline: out of memory");
        goto done;
    }
    double *k = knots;
    for (size_t i = 0; i < s->n; ++i) {
        int32_t p = s->pieces[i].p;
        for (int32_t j = 0; j <= p; ++j) {
            k[j] = 0.0;
            k[p + 1 + j] = 1.0;
        }
        curves[i] = (sw_sg_curve){p, p + 1, 3, k, c->pool + s->pieces[i].at};
        k += 2 * (size_t)(p + 1);
    }
    for (uint32_t L = 0; L < s->n_loops; ++L) {
        size_t first = L ? s->loop_end[L - 1] : 0;
        loops[L] = (sw__curves_loop){curves + first, (uint32_t)(s->loop_end[L] - first)};
    }
    r = sw__curves_shape_create(loops, s->n_loops, 1.0, out, status);
done:
    sw__free(knots);
    sw__free(curves);
    sw__free(loops);
    return r;
}

sw_result sw__curves_project(const sw__curves_loop *loops, uint32_t n_loops,
                             const sw__curves_plane *plane, const sw__gpu_view *view,
                             sw__curves_projected *out, sw_status *status)
{
    assert((loops || !n_loops) && plane && view && out);
    memset(out, 0, sizeof *out);
    place_ctx c = {0};
    loop_set a = {0}, b = {0};
    sw_result r = source_pieces(&c, loops, n_loops, &a, status);
    proj_rows rows;
    projection_rows(plane, view, &rows);
    double f[5][3];
    int n_cuts = cut_functions(&rows, view, f);
    for (int k = 0; k < n_cuts && r == SW_OK; ++k) {
        cut_set(&c, &a, f[k], &b);
        loop_set_free(&a);
        a = b;
        memset(&b, 0, sizeof b);
        if (c.oom)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "placed outline: out of memory");
    }
    if (r == SW_OK && a.n > 0 && plane_depth(plane, view, &out->depth)) {
        for (uint32_t L = 0; L < a.n_loops && !c.oom; ++L) {
            for (size_t i = L ? a.loop_end[L - 1] : 0; i < a.loop_end[L] && !c.oom; ++i) {
                double h[3 * (SW_SG_MAX_DEGREE + 1)];
                memcpy(h, c.pool + a.pieces[i].at, sizeof(double) * 3 * (a.pieces[i].p + 1));
                project_piece(&c, &rows, view->near_plane, h, a.pieces[i].p, 0, &b);
            }
            end_loop(&c, &b);
        }
        r = c.oom ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "placed outline: out of memory")
                  : make_shape(&c, &b, &out->shape, status);
        out->fallbacks = c.fallbacks;
    }
    loop_set_free(&a);
    loop_set_free(&b);
    sw__free(c.pool);
    return r;
}

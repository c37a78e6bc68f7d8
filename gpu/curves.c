/* SPDX-License-Identifier: MIT */
/* Drawing filled outlines with exact, anti-aliased edges (sw_curves.h; Santana §3-§5).
 *
 * Per draw, on the CPU in double: the view's pixel positions of three triangle sets — the stencil
 * fan over the pieces' end points plus each curved piece's control hull (Santana §3's curved
 * triangles), a cover rectangle, and each piece's band (its control hull grown by 0.75 px: every
 * pixel of its slab whose square meets the curve) — with the piece's local coordinates at each
 * vertex and its implicit form expanded in them (local_form). Then
 * four passes: stencil parity, cover, edge corrections (glsl/curves.frag.glsl) into a float
 * coverage target, and the composite over the caller's framebuffer
 * (glsl/curves_composite.frag.glsl). The geometry depends on the view (the band's width is in
 * pixels), so a draw rebuilds it: outlines are small next to surfaces; a cache keyed by the view's
 * scale would be the next step for large ones.
 */
#include "sw_curves.h"
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* px: the band must hold every pixel centre in the piece's slab (between its cut lines) whose
 * square meets the curve. That curve point lies within the square's half diagonal (0.7071 px)
 * of the centre; it is on this piece, or, near a cut line, on the neighbour just past it, hence
 * within about that distance of this piece's end point: so the control hull grown by 0.75 px (the
 * hull of the control points offset by +-0.75 px in x and y) holds them all. A wider band (this
 * was 1.5 px) only adds pixels whose correction must be 0 but where another branch of the
 * piece's implicit curve, or an edge's straight extension past a corner, can make it non-zero;
 * the hull grown by only the pixel square (0.5 px) misses pixels at joins whose square meets the
 * curve just past the cut line (nurbs7 x1: 36/255). */
#define BAND_MARGIN 0.75
/* px: a shape smaller than this on screen in both directions is drawn VBAA_SCALE times larger (the
 * view-based path); one smaller in one direction only (a line of small text, a thin strip)
 * VBAA_SCALE_THIN times: its fragments are as many as its area, and a label 16 px tall took
 * ~5 ms at 8x on llvmpipe (test_gpu_labels at 14 px per em: 0.29/255 mean, 0.95/255 max at 4x;
 * without the path 2.16/255 and 16.95/255) */
#define VBAA_SIZE 24.0
#define VBAA_SCALE 8
#define VBAA_SCALE_THIN 4

typedef struct vtx {
    float pos[2];
    float uv[2];  /* the piece's local coordinates: (model - centre) / size */
    float cut[3]; /* px past the start cut line, before the end cut line, left of the chord */
    float flags[3];
    /* F(u, v): 1, u, v, u^2, u v, v^2, u^3, u^2 v, u v^2, v^3; then the least and the largest
     * signed distance (px) of the control points from the chord: the strip holding the piece */
    float coef[12];
} vtx;

/* A piece's implicit form expanded into a bivariate polynomial in local coordinates, in double
 * precision, then scaled so that |grad F| = 1 at the local origin. Why: evaluated in float as
 * k^3 - l m, F loses everything when k, l and m are nearly constant over the piece (a short,
 * nearly straight piece of a cubic whose inflections or double point lie far away: then k^3 and
 * l m agree in their leading digits): we measured distance errors of 3 px at zoom 1 that way.
 * Expanded around the piece, the terms are of the size of F's variation across the piece. */
typedef struct local_form {
    double centre[2], size;
    double c[10];
} local_form;

typedef struct bipoly {
    double a[4][4]; /* a[i][j] u^i v^j, i + j <= 3 */
} bipoly;

static bipoly bp_mul(const bipoly *x, const bipoly *y)
{
    bipoly r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; i + j < 4; ++j)
            for (int k = 0; i + k < 4; ++k)
                for (int l = 0; j + l < 4 && i + k + j + l < 4; ++l)
                    r.a[i + k][j + l] += x->a[i][j] * y->a[k][l];
    return r;
}

/* The local form of piece p around the box `box` (model x0, y0, x1, y1; NULL: the piece's
 * control points' box). */
static void local_form_make(const sw__curves_piece *p, int fault, const double *box, local_form *f)
{
    double lo[2] = {p->cp[0][0], p->cp[0][1]}, hi[2] = {lo[0], lo[1]};
    for (int i = 1; i < p->n_cp; ++i)
        for (int k = 0; k < 2; ++k) {
            lo[k] = fmin(lo[k], p->cp[i][k]);
            hi[k] = fmax(hi[k], p->cp[i][k]);
        }
    if (box) {
        lo[0] = box[0];
        lo[1] = box[1];
        hi[0] = box[2];
        hi[1] = box[3];
    }
    f->centre[0] = 0.5 * (lo[0] + hi[0]);
    f->centre[1] = 0.5 * (lo[1] + hi[1]);
    f->size = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1e-300);
    bipoly k[3];
    for (int j = 0; j < 3; ++j) {
        memset(&k[j], 0, sizeof k[j]);
        k[j].a[0][0] = p->klm[j][0] * f->centre[0] + p->klm[j][1] * f->centre[1] + p->klm[j][2];
        k[j].a[1][0] = p->klm[j][0] * f->size;
        k[j].a[0][1] = p->klm[j][1] * f->size;
    }
    if (p->kind == SW__CURVES_CUSP) {
        /* not a polynomial: k and l as affine forms, then the branch (the fault: the other one) */
        memset(f->c, 0, sizeof f->c);
        for (int j = 0; j < 2; ++j) {
            f->c[3 * j] = k[j].a[0][0];
            f->c[3 * j + 1] = k[j].a[1][0];
            f->c[3 * j + 2] = k[j].a[0][1];
        }
        f->c[6] = fault == 1 ? -p->branch : p->branch;
        return;
    }
    bipoly F;
    if (p->kind == SW__CURVES_LINE) {
        F = k[0];
    } else {
        F = bp_mul(&k[0], &k[0]);
        if (p->kind == SW__CURVES_CUBIC)
            F = bp_mul(&F, &k[0]);
        bipoly lm = bp_mul(&k[1], &k[2]);
        /* the planted fault of the tests: a sign error in the implicit form, k^n + l m */
        double sg = fault == 1 ? 1.0 : -1.0;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; i + j < 4; ++j)
                F.a[i][j] += sg * lm.a[i][j];
    }
    /* scaled to a largest coefficient of 1: float's range then holds any zoom */
    double g = 0.0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; i + j < 4; ++j)
            g = fmax(g, fabs(F.a[i][j]));
    if (!(g > 0.0))
        g = 1.0;
    static const int idx[10][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1},
                                   {0, 2}, {3, 0}, {2, 1}, {1, 2}, {0, 3}};
    for (int t = 0; t < 10; ++t)
        f->c[t] = F.a[idx[t][0]][idx[t][1]] / g;
}

struct sw__curves_renderer {
    GLuint prog, prog_comp, vao, vbo, fbo, tex, rb;
    int32_t fbo_w, fbo_h;
    GLint loc_size, loc_mode, loc_h;
    GLint loc_c_size;
    int fault, vbaa;
    vtx *v;
    size_t n, cap;
    double clip[4]; /* x0, y0, x1, y1 (Sutherland-Hodgman order: min x, min y, max x, max y) */
};

sw_result sw__curves_renderer_create(sw__curves_renderer **out, sw_status *status)
{
    assert(out);
    *out = NULL;
    sw__curves_renderer *r = sw__calloc(1, sizeof *r);
    if (!r)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    r->vbaa = 1;
    sw_result res = sw__gpu_program_link(sw__gpu_curves_glsl(0), sw__gpu_curves_glsl(1), "curves",
                                         &r->prog, status);
    if (res == SW_OK)
        res = sw__gpu_program_link(sw__gpu_curves_glsl(0), sw__gpu_curves_glsl(2),
                                   "curves composite", &r->prog_comp, status);
    if (res != SW_OK) {
        sw__curves_renderer_free(r);
        return res;
    }
    r->loc_size = glGetUniformLocation(r->prog, "u_size");
    r->loc_mode = glGetUniformLocation(r->prog, "u_mode");
    r->loc_h = glGetUniformLocation(r->prog, "u_h");
    r->loc_c_size = glGetUniformLocation(r->prog_comp, "u_size");
    glGenVertexArrays(1, &r->vao);
    glGenBuffers(1, &r->vbo);
    glBindVertexArray(r->vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo);
    for (GLuint a = 0; a < 7; ++a)
        glEnableVertexAttribArray(a);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(vtx), (void *)offsetof(vtx, pos));
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(vtx), (void *)offsetof(vtx, uv));
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, sizeof(vtx), (void *)offsetof(vtx, cut));
    glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, sizeof(vtx), (void *)offsetof(vtx, flags));
    for (GLuint a = 0; a < 3; ++a)
        glVertexAttribPointer(4 + a, 4, GL_FLOAT, GL_FALSE, sizeof(vtx),
                              (void *)(offsetof(vtx, coef) + 16 * a));
    res = sw__gpu_check(status, "curves renderer set-up");
    if (res != SW_OK) {
        sw__curves_renderer_free(r);
        return res;
    }
    *out = r;
    return SW_OK;
}

void sw__curves_renderer_free(sw__curves_renderer *r)
{
    if (!r)
        return;
    glDeleteProgram(r->prog);
    glDeleteProgram(r->prog_comp);
    glDeleteVertexArrays(1, &r->vao);
    glDeleteBuffers(1, &r->vbo);
    glDeleteFramebuffers(1, &r->fbo);
    glDeleteTextures(1, &r->tex);
    glDeleteRenderbuffers(1, &r->rb);
    sw__free(r->v);
    sw__free(r);
}

void sw__curves_renderer_set_fault(sw__curves_renderer *r, int fault)
{
    r->fault = fault;
}

void sw__curves_renderer_set_vbaa(sw__curves_renderer *r, int on)
{
    r->vbaa = on;
}

static sw_result ensure_target(sw__curves_renderer *r, int32_t w, int32_t h, sw_status *status)
{
    if (r->fbo && r->fbo_w >= w && r->fbo_h >= h)
        return SW_OK;
    w = w > r->fbo_w ? w : r->fbo_w;
    h = h > r->fbo_h ? h : r->fbo_h;
    if (!r->fbo) {
        glGenFramebuffers(1, &r->fbo);
        glGenTextures(1, &r->tex);
        glGenRenderbuffers(1, &r->rb);
    }
    glBindTexture(GL_TEXTURE_2D, r->tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, w, h, 0, GL_RED, GL_FLOAT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, r->rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->tex, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, r->rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return sw__fail(status, SW_ERR_GL, "curves: coverage target %dx%d incomplete", w, h);
    r->fbo_w = w;
    r->fbo_h = h;
    return sw__gpu_check(status, "curves coverage target");
}

static vtx *push(sw__curves_renderer *r, size_t k)
{
    if (r->n + k > r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 1024;
        while (cap < r->n + k)
            cap *= 2;
        vtx *q = sw__realloc(r->v, cap * sizeof *q);
        if (!q)
            return NULL;
        r->v = q;
        r->cap = cap;
    }
    vtx *out = r->v + r->n;
    r->n += k;
    return out;
}

typedef struct xform {
    double m[6];   /* model -> coverage pixels */
    double inv[6]; /* coverage pixels -> model */
} xform;

static void apply(const double m[6], const double p[2], double out[2])
{
    out[0] = m[0] * p[0] + m[1] * p[1] + m[2];
    out[1] = m[3] * p[0] + m[4] * p[1] + m[5];
}

void sw__curves_piece_local_form(const sw__curves_piece *p, double centre[2], double *size,
                                 double c[10])
{
    local_form f;
    local_form_make(p, 0, NULL, &f);
    centre[0] = f.centre[0];
    centre[1] = f.centre[1];
    *size = f.size;
    memcpy(c, f.c, sizeof f.c);
}

/* A vertex at pixel position q for piece p with local form f (NULL: a fan / cover vertex). */
static void set_vtx(vtx *v, const xform *x, const sw__curves_piece *p, const local_form *f,
                    const double q[2], float kind)
{
    memset(v, 0, sizeof *v);
    v->pos[0] = (float)q[0];
    v->pos[1] = (float)q[1];
    v->flags[0] = kind;
    v->flags[1] = v->flags[2] = 1.0f;
    if (!p)
        return;
    double m[2];
    apply(x->inv, q, m);
    v->uv[0] = (float)((m[0] - f->centre[0]) / f->size);
    v->uv[1] = (float)((m[1] - f->centre[1]) / f->size);
    for (int t = 0; t < 10; ++t)
        v->coef[t] = (float)f->c[t];
    /* cut lines in pixel space: the end tangents mapped by the view's linear part */
    double a[2], b[2];
    apply(x->m, p->cp[0], a);
    apply(x->m, p->cp[p->n_cp - 1], b);
    double t0[2] = {x->m[0] * p->tan0[0] + x->m[1] * p->tan0[1],
                    x->m[3] * p->tan0[0] + x->m[4] * p->tan0[1]};
    double t1[2] = {x->m[0] * p->tan1[0] + x->m[1] * p->tan1[1],
                    x->m[3] * p->tan1[0] + x->m[4] * p->tan1[1]};
    double l0 = hypot(t0[0], t0[1]), l1 = hypot(t1[0], t1[1]);
    v->cut[0] = (float)(((q[0] - a[0]) * t0[0] + (q[1] - a[1]) * t0[1]) / l0);
    v->cut[1] = (float)(((b[0] - q[0]) * t1[0] + (b[1] - q[1]) * t1[1]) / l1);
    /* the chord strip: with the slab, a box around the piece in which a foot point found by the
     * shader's Newton steps must lie to be on this piece (glsl/curves.frag.glsl) */
    double e[2] = {b[0] - a[0], b[1] - a[1]}, le = hypot(e[0], e[1]);
    double nl[2] = {le > 0.0 ? -e[1] / le : 0.0, le > 0.0 ? e[0] / le : 0.0};
    double hmin = 0.0, hmax = 0.0;
    for (int k = 1; k + 1 < p->n_cp; ++k) {
        double c[2];
        apply(x->m, p->cp[k], c);
        double h = (c[0] - a[0]) * nl[0] + (c[1] - a[1]) * nl[1];
        hmin = fmin(hmin, h);
        hmax = fmax(hmax, h);
    }
    if (!(le > 0.0)) { /* no chord: no strip to check against */
        hmin = -1e30;
        hmax = 1e30;
    }
    v->cut[2] = (float)((q[0] - a[0]) * nl[0] + (q[1] - a[1]) * nl[1]);
    v->coef[10] = (float)hmin;
    v->coef[11] = (float)hmax;
    v->flags[1] = (float)p->s_chord;
    v->flags[2] = (float)p->s_in;
}

static double cross3(const double o[2], const double a[2], const double b[2])
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

static int cmp_pt(const void *a, const void *b)
{
    const double *p = a, *q = b;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

/* Convex hull (Andrew's monotone chain), counter-clockwise, of n <= 16 points; returns its size. */
static int hull(double (*pts)[2], int n, double (*out)[2])
{
    qsort(pts, (size_t)n, sizeof *pts, cmp_pt);
    int k = 0;
    for (int i = 0; i < n; ++i) {
        while (k >= 2 && cross3(out[k - 2], out[k - 1], pts[i]) <= 0)
            k--;
        memcpy(out[k++], pts[i], sizeof out[0]);
    }
    for (int i = n - 2, t = k + 1; i >= 0; --i) {
        while (k >= t && cross3(out[k - 2], out[k - 1], pts[i]) <= 0)
            k--;
        memcpy(out[k++], pts[i], sizeof out[0]);
    }
    return k > 1 ? k - 1 : k;
}

/* Clips a convex polygon (n <= 24) to the rectangle [x0, x1] x [y0, y1] (Sutherland-Hodgman);
 * returns the new size (<= n + 4). Far zooms make pieces 1e5 px wide: clipped here, in double,
 * the rasterizer gets triangles of the target's size and interpolates over a short range. */
static int clip_rect(const double (*in)[2], int n, const double rect[4], double (*out)[2])
{
    double a[32][2], b[32][2];
    memcpy(a, in, sizeof(double) * 2 * (size_t)n);
    for (int side = 0; side < 4 && n > 0; ++side) {
        int axis = side & 1, upper = side >> 1, m = 0;
        double lim = rect[side];
        for (int i = 0; i < n; ++i) {
            const double *p = a[i], *q = a[(i + 1) % n];
            int pin = upper ? p[axis] <= lim : p[axis] >= lim;
            int qin = upper ? q[axis] <= lim : q[axis] >= lim;
            if (pin)
                memcpy(b[m++], p, sizeof b[0]);
            if (pin != qin) {
                double t = (lim - p[axis]) / (q[axis] - p[axis]);
                b[m][axis] = lim;
                b[m][1 - axis] = p[1 - axis] + t * (q[1 - axis] - p[1 - axis]);
                m++;
            }
        }
        memcpy(a, b, sizeof(double) * 2 * (size_t)m);
        n = m;
    }
    memcpy(out, a, sizeof(double) * 2 * (size_t)n);
    return n;
}

/* Fan triangles over a convex polygon clipped to r->clip, carrying piece p's local form expanded
 * around the clipped polygon. Why there: F is evaluated in float, and its error is float's
 * epsilon times the size of F's terms over the region it is expanded for, divided by |grad F|
 * where the fragment is. Expanded around the whole piece, at x1000 the region is 1e5 px across
 * and a pixel of the cusp test, where |grad F| is 1/40 of its value at the piece's centre, was
 * off by 2 px (cusp x1000: mean 46/255). Around the clipped polygon the region is at most the
 * target's size (and the band's width), whatever the zoom. */
static int emit_polygon(sw__curves_renderer *r, const xform *x, const sw__curves_piece *p,
                        int fault, const double (*poly_in)[2], int n_in, float kind)
{
    double poly[32][2];
    int n = clip_rect(poly_in, n_in, r->clip, poly);
    if (n < 3)
        return 1;
    local_form lf, *f = NULL;
    if (p) {
        double box[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
        for (int i = 0; i < n; ++i) {
            double q[2];
            apply(x->inv, poly[i], q);
            for (int k = 0; k < 2; ++k) {
                box[k] = fmin(box[k], q[k]);
                box[2 + k] = fmax(box[2 + k], q[k]);
            }
        }
        local_form_make(p, fault, box, &lf);
        f = &lf;
    }
    vtx *v = push(r, 3 * (size_t)(n - 2));
    if (!v)
        return 0;
    for (int i = 1; i + 1 < n; ++i) {
        set_vtx(v++, x, p, f, poly[0], kind);
        set_vtx(v++, x, p, f, poly[i], kind);
        set_vtx(v++, x, p, f, poly[i + 1], kind);
    }
    return 1;
}

/* Where a shape's coverage went: the target pixels [x0, x1) x [y0, y1) it may touch, drawn ss
 * times larger with its origin at (ox, oy) when ss > 1 (the view-based path for small shapes). */
typedef struct coverage {
    int32_t x0, y0, x1, y1, ox, oy;
    int ss;
    int empty; /* nothing on the target */
} coverage;

/* Passes 1-3: the shape's coverage into the renderer's float target. */
static sw_result draw_coverage(sw__curves_renderer *r, sw__curves_shape *shape,
                               const sw__curves_view *view, coverage *cv, sw_status *status)
{
    assert(r && shape && view);
    memset(cv, 0, sizeof *cv);
    cv->empty = 1;
    const double *m = view->m;
    /* the view's zoom: the largest singular value of its linear part */
    double a = m[0], b = m[1], c = m[3], d = m[4];
    double s1 = a * a + b * b + c * c + d * d, s2 = a * d - b * c;
    double px_per_unit = sqrt(0.5 * (s1 + sqrt(fmax(s1 * s1 - 4 * s2 * s2, 0.0))));
    sw_result res = sw__curves_shape_fit_view(shape, px_per_unit, NULL, status);
    if (res != SW_OK)
        return res;
    if (shape->n_pieces == 0)
        return SW_OK;

    /* the shape's box on screen */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 4; ++k) {
        double p[2] = {shape->box[(k & 1) ? 2 : 0], shape->box[(k & 2) ? 3 : 1]}, q[2];
        apply(m, p, q);
        for (int j = 0; j < 2; ++j) {
            lo[j] = fmin(lo[j], q[j]);
            hi[j] = fmax(hi[j], q[j]);
        }
    }
    const int thin_x = hi[0] - lo[0] < VBAA_SIZE, thin_y = hi[1] - lo[1] < VBAA_SIZE;
    const int ss = !r->vbaa           ? 1
                   : thin_x && thin_y ? VBAA_SCALE
                   : thin_x || thin_y ? VBAA_SCALE_THIN
                                      : 1;
    int32_t x0 = (int32_t)floor(fmax(lo[0] - 2.0, 0.0)),
            y0 = (int32_t)floor(fmax(lo[1] - 2.0, 0.0));
    int32_t x1 = (int32_t)ceil(fmin(hi[0] + 2.0, view->width)),
            y1 = (int32_t)ceil(fmin(hi[1] + 2.0, view->height));
    if (x1 <= x0 || y1 <= y0)
        return SW_OK;
    xform x;
    int32_t tw = view->width, th = view->height, ox = 0, oy = 0;
    if (ss > 1) { /* the coverage target holds the box, ss times larger */
        ox = x0;
        oy = y0;
        tw = (x1 - x0) * ss;
        th = (y1 - y0) * ss;
    }
    for (int k = 0; k < 3; ++k) {
        x.m[k] = ss * m[k];
        x.m[3 + k] = ss * m[3 + k];
    }
    x.m[2] -= ss * ox;
    x.m[5] -= ss * oy;
    double det = x.m[0] * x.m[4] - x.m[1] * x.m[3];
    if (!(fabs(det) > 0.0))
        return SW_OK;
    x.inv[0] = x.m[4] / det;
    x.inv[1] = -x.m[1] / det;
    x.inv[3] = -x.m[3] / det;
    x.inv[4] = x.m[0] / det;
    x.inv[2] = -(x.inv[0] * x.m[2] + x.inv[1] * x.m[5]);
    x.inv[5] = -(x.inv[3] * x.m[2] + x.inv[4] * x.m[5]);

    /* geometry: [0, n_stencil) fan + hulls, then the cover quad, then the bands */
    r->n = 0;
    r->clip[0] = -2.0;
    r->clip[1] = -2.0;
    r->clip[2] = tw + 2.0;
    r->clip[3] = th + 2.0;
    double anchor[2];
    apply(x.m, shape->pieces[0].cp[0], anchor);
    for (size_t i = 0; i < shape->n_pieces; ++i) {
        const sw__curves_piece *p = &shape->pieces[i];
        double tri[3][2];
        memcpy(tri[0], anchor, sizeof tri[0]);
        apply(x.m, p->cp[0], tri[1]);
        apply(x.m, p->cp[p->n_cp - 1], tri[2]);
        /* a clockwise triangle is still convex: the clipper keeps either orientation */
        if (!emit_polygon(r, &x, NULL, 0, (const double(*)[2])tri, 3, -1.0f))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
        if (p->kind == SW__CURVES_LINE)
            continue;
        double pts[4][2], h[8][2];
        for (int k = 0; k < p->n_cp; ++k)
            apply(x.m, p->cp[k], pts[k]);
        int nh = hull(pts, p->n_cp, h);
        if (!emit_polygon(r, &x, p, r->fault, (const double(*)[2])h, nh, (float)p->kind))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    }
    size_t n_stencil = r->n;
    {
        double q[4][2] = {{(x0 - ox) * ss, (y0 - oy) * ss},
                          {(x1 - ox) * ss, (y0 - oy) * ss},
                          {(x1 - ox) * ss, (y1 - oy) * ss},
                          {(x0 - ox) * ss, (y1 - oy) * ss}};
        if (!emit_polygon(r, &x, NULL, 0, (const double(*)[2])q, 4, -1.0f))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    }
    size_t n_cover_end = r->n;
    for (size_t i = 0; i < shape->n_pieces; ++i) {
        const sw__curves_piece *p = &shape->pieces[i];
        double pts[16][2], h[20][2];
        int n = 0;
        for (int k = 0; k < p->n_cp; ++k) {
            double q[2];
            apply(x.m, p->cp[k], q);
            for (int s = 0; s < 4; ++s) {
                pts[n][0] = q[0] + ((s & 1) ? BAND_MARGIN : -BAND_MARGIN);
                pts[n][1] = q[1] + ((s & 2) ? BAND_MARGIN : -BAND_MARGIN);
                n++;
            }
        }
        int nh = hull(pts, n, h);
        if (!emit_polygon(r, &x, p, r->fault, (const double(*)[2])h, nh, (float)p->kind))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    }
    size_t n_all = r->n;

    res = ensure_target(r, tw, th, status);
    if (res != SW_OK)
        return res;
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n_all * sizeof(vtx)), r->v, GL_STREAM_DRAW);
    glBindVertexArray(r->vao);

    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, tw, th);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_MULTISAMPLE);
    /* Only the shape's box is cleared and drawn: every pass stays inside it (the fan and the
     * hulls inside the control points' hull, the bands within 0.75 px of it, the box grown by
     * 2 px), and the composite reads no more. A clear of the whole target per outline cost
     * ~5 ms each at 1280 x 720 on llvmpipe. */
    glEnable(GL_SCISSOR_TEST);
    glScissor((x0 - ox) * ss, (y0 - oy) * ss, (x1 - x0) * ss, (y1 - y0) * ss);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glStencilMask(0xff);
    glClearColor(0, 0, 0, 0);
    glClearStencil(0);
    glClear(GL_COLOR_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glUseProgram(r->prog);
    glUniform2f(r->loc_size, (float)tw, (float)th);

    /* 1: parity into the stencil's low bit */
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_STENCIL_TEST);
    glStencilMask(1);
    glStencilFunc(GL_ALWAYS, 0, 1);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INVERT);
    glUniform1i(r->loc_mode, 0);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)n_stencil);

    /* 2: cover the odd pixels with 1 */
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glStencilMask(0);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    glStencilFunc(GL_EQUAL, 1, 1);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUniform1i(r->loc_mode, 1);
    glDrawArrays(GL_TRIANGLES, (GLint)n_stencil, (GLsizei)(n_cover_end - n_stencil));

    /* 3: edge corrections, each relative to its own half-plane's value at the pixel centre but
     * for centres on the curve, where the stencil's value stands for it (glsl/curves.frag.glsl
     * says why): once over stencil-odd pixels and once over the others */
    glUniform1i(r->loc_mode, 2);
    for (int h = 1; h >= 0; --h) {
        glStencilFunc(GL_EQUAL, h, 1);
        glUniform1f(r->loc_h, (float)h);
        glDrawArrays(GL_TRIANGLES, (GLint)n_cover_end, (GLsizei)(n_all - n_cover_end));
    }
    glDisable(GL_STENCIL_TEST);
    glStencilMask(0xff);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    *cv = (coverage){x0, y0, x1, y1, ox, oy, ss, 0};
    return SW_OK;
}

/* Pass 4's set-up: blending "over" into the target, the coverage texture on unit 0. */
static void composite_begin(sw__curves_renderer *r, const coverage *cv, const sw__curves_view *view,
                            const float rgba[4], GLuint target_fbo)
{
    const GLuint prog = r->prog_comp;
    glBindFramebuffer(GL_FRAMEBUFFER, target_fbo);
    glViewport(0, 0, view->width, view->height);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_cov"), 0);
    glUniform4f(glGetUniformLocation(prog, "u_color"), rgba[0] * rgba[3], rgba[1] * rgba[3],
                rgba[2] * rgba[3], rgba[3]);
    glUniform2i(glGetUniformLocation(prog, "u_origin"), cv->ox, cv->oy);
    glUniform1i(glGetUniformLocation(prog, "u_ss"), cv->ss);
    glUniform2f(r->loc_c_size, (float)view->width, (float)view->height);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->tex);
}

/* Pass 4's draw: the coverage box in target pixels, with the fan's vertex layout. */
static sw_result composite_box(sw__curves_renderer *r, const coverage *cv,
                               const sw__curves_view *view, sw_status *status)
{
    glBindVertexArray(r->vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo);
    r->n = 0;
    xform id = {{1, 0, 0, 0, 1, 0}, {1, 0, 0, 0, 1, 0}};
    r->clip[0] = r->clip[1] = -2.0;
    r->clip[2] = view->width + 2.0;
    r->clip[3] = view->height + 2.0;
    double q[4][2] = {{cv->x0, cv->y0}, {cv->x1, cv->y0}, {cv->x1, cv->y1}, {cv->x0, cv->y1}};
    if (!emit_polygon(r, &id, NULL, 0, (const double(*)[2])q, 4, -1.0f))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "curves: out of memory");
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(r->n * sizeof(vtx)), r->v, GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)r->n);
    glDisable(GL_BLEND);
    return SW_OK;
}

/* The four passes; with depth (a placed outline) the composite takes its plane's depth. */
static sw_result draw_outline(sw__curves_renderer *r, sw__curves_shape *shape,
                              const sw__curves_view *view, const float rgba[4], GLuint target_fbo,
                              const sw__curves_depth *depth, sw_status *status)
{
    assert(rgba);
    coverage cv;
    sw_result res = draw_coverage(r, shape, view, &cv, status);
    if (res != SW_OK || cv.empty)
        return res;
    /* 4: composite over the target */
    composite_begin(r, &cv, view, rgba, target_fbo);
    if (depth) {
        /* 1 / d about the box's corner, so that float keeps its digits over the box */
        const double *k = depth->inv_d;
        glUniform3f(glGetUniformLocation(r->prog_comp, "u_inv_d"), (float)k[0], (float)k[1],
                    (float)(k[0] * cv.x0 + k[1] * cv.y0 + k[2]));
        glUniform2f(glGetUniformLocation(r->prog_comp, "u_depth_origin"), (float)cv.x0,
                    (float)cv.y0);
        glUniform1f(glGetUniformLocation(r->prog_comp, "u_depth_scale"),
                    (float)(depth->near_plane * (1.0 + SW__CURVES_DECAL_PULL)));
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GEQUAL);
        glDepthMask(GL_FALSE);
    }
    res = composite_box(r, &cv, view, status);
    if (depth) {
        glUniform1f(glGetUniformLocation(r->prog_comp, "u_depth_scale"), 0.0f);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_TRUE);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    return res == SW_OK ? sw__gpu_check(status, "curves draw") : res;
}

sw_result sw__curves_draw(sw__curves_renderer *r, sw__curves_shape *shape,
                          const sw__curves_view *view, const float rgba[4], GLuint target_fbo,
                          sw_status *status)
{
    return draw_outline(r, shape, view, rgba, target_fbo, NULL, status);
}

sw_result sw__curves_draw_placed(sw__curves_renderer *r, sw__curves_shape *shape,
                                 const sw__curves_view *view, const float rgba[4],
                                 GLuint target_fbo, const sw__curves_depth *depth,
                                 sw_status *status)
{
    assert(depth);
    return draw_outline(r, shape, view, rgba, target_fbo, depth, status);
}

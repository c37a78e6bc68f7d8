/* SPDX-License-Identifier: MIT */
/* Outlines placed in 3D (gpu/curves_place.c, sw__curves_draw_placed) against exact area coverage
 * computed here in double precision, with depth against opaque geometry.
 *
 * The outline lies in the world plane z = 0: a closed cubic B-spline (its perspective image is a
 * rational cubic: the 2D path's bounded approximation), a rational-quadratic circle as a hole in
 * it (an exact conic on screen) and a rectangle of lines. It is drawn red into a 256 x 256 RGBA8
 * target with a 32-bit float depth buffer, reversed-Z as the frame draws (the view's view_proj).
 *
 * The reference: each curve's rational Bézier pieces subdivided in the plane until their
 * perspective image is within 1e-3 px of its chord (or the piece lies behind the near plane, or
 * wholly beyond one side of the target), the polygon of their end points cut to the half-plane in
 * front of the near plane (Sutherland-Hodgman, exact for even-odd fills), its vertices projected
 * in double (a projective map takes chords to chords) and the area per pixel taken by
 * curves_reference.h. Depth: per pixel centre, the ray's distances to the outline's plane and to
 * the occluder's plane.
 *
 * Views: "tilted" (the whole outline, the plane at ~50 degrees), "near" (the eye low over the
 * plane: the near plane cuts the outline on screen, and the rest runs far past the target: the
 * cut and the guard band), "zoom" (1.5 degrees onto the hole's edge from far: ~x100), "wall"
 * (tilted, an opaque wall x = 0.2 hides the part of the outline behind it), "decal" (an opaque
 * floor in the outline's own plane: the outline lies on it and must show whole), "lifted" (the
 * floor 2e-5 above the plane, within the decal rule: the outline must still show whole), "buried"
 * (the floor 3e-3 above: nothing of the outline may show).
 *
 * Pass: along edges mean coverage error <= 2/255, and every pixel more than 1.5 px from a corner,
 * a near-plane cut point or the wall's line within 12/255 (corners are reported apart); "buried"
 * shows no red at all.
 *
 * What it catches (each planted once while writing it, and seen failing): loops not cut at the
 * near plane (control points behind the eye: "near" fails on its whole lower half); the cut's
 * closing segment left out (loops open: "near" refused); the composite without depth test
 * ("wall", "buried": the outline over what hides it); without the pull toward the eye ("lifted":
 * hidden); a projection that drops a piece's weights (conics drawn as parabolas:
 * "tilted" and "zoom" 30-200/255 along the hole).
 */
#include "curves_reference.h"
#include "sw_curves.h"
#include "sw_gpu.h"
#include "sw_gpu_internal.h"

#include <GL/glcorearb.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 256
#define H 256

/* ---- the outline ------------------------------------------------------------------------- */

typedef struct tcurve {
    int deg, n;
    double knots[16];
    double cpw[3 * 12];
} tcurve;

enum { N_CURVES = 6, N_LOOPS = 3 };

typedef struct outline {
    tcurve c[N_CURVES];
    int loop_of[N_CURVES];
    double sign[N_LOOPS]; /* winding weight per loop: all counter-clockwise, the hole -1 */
    double corners[8][2];
    int n_corners;
} outline;

static void line_curve(tcurve *c, double ax, double ay, double bx, double by)
{
    *c = (tcurve){.deg = 1, .n = 2, .knots = {0, 0, 1, 1}, .cpw = {ax, ay, 1, bx, by, 1}};
}

static void make_outline(outline *o)
{
    memset(o, 0, sizeof *o);
    /* a closed clamped cubic blob around (-0.3, 0), counter-clockwise; the closure is a corner */
    tcurve *b = &o->c[0];
    b->deg = 3;
    b->n = 8;
    const double k[12] = {0, 0, 0, 0, 1, 2, 3, 4, 5, 5, 5, 5};
    memcpy(b->knots, k, sizeof k);
    for (int i = 0; i < 7; ++i) {
        double a = 2 * M_PI * i / 7, r = (i % 2) ? 0.85 : 0.6;
        b->cpw[3 * i] = -0.3 + 1.1 * r * cos(a);
        b->cpw[3 * i + 1] = r * sin(a);
        b->cpw[3 * i + 2] = 1;
    }
    memcpy(&b->cpw[21], &b->cpw[0], 3 * sizeof(double));
    o->corners[o->n_corners][0] = b->cpw[0];
    o->corners[o->n_corners++][1] = b->cpw[1];
    o->loop_of[0] = 0;
    o->sign[0] = 1;
    /* the hole: a circle of radius 0.22 at (-0.25, 0.05), nine rational quadratic points */
    tcurve *c = &o->c[1];
    c->deg = 2;
    c->n = 9;
    const double kc[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    memcpy(c->knots, kc, sizeof kc);
    for (int i = 0; i < 9; ++i) {
        double a = M_PI / 4 * i, w = (i % 2) ? sqrt(0.5) : 1.0,
               rr = (i % 2) ? 0.22 * sqrt(2) : 0.22;
        c->cpw[3 * i] = w * (-0.25 + rr * cos(a));
        c->cpw[3 * i + 1] = w * (0.05 + rr * sin(a));
        c->cpw[3 * i + 2] = w;
    }
    c->cpw[24] = c->cpw[0];
    c->cpw[25] = c->cpw[1];
    o->loop_of[1] = 1;
    o->sign[1] = -1;
    /* a rectangle [0.75, 1.15] x [-0.5, 0.35] */
    const double r[4][2] = {{0.75, -0.5}, {1.15, -0.5}, {1.15, 0.35}, {0.75, 0.35}};
    for (int i = 0; i < 4; ++i) {
        line_curve(&o->c[2 + i], r[i][0], r[i][1], r[(i + 1) % 4][0], r[(i + 1) % 4][1]);
        o->loop_of[2 + i] = 2;
        o->corners[o->n_corners][0] = r[i][0];
        o->corners[o->n_corners++][1] = r[i][1];
    }
    o->sign[2] = 1;
}

/* ---- the view and the reference ----------------------------------------------------------- */

typedef struct scene_view {
    sw__gpu_view v;
    sw__curves_plane plane; /* z = 0, eye-relative */
} scene_view;

static int make_view(const double eye[3], const double target[3], double fovy, double near_plane,
                     scene_view *out)
{
    sw_gpu_camera cam = {
        {eye[0], eye[1], eye[2]}, {target[0], target[1], target[2]}, {0, 0, 1}, fovy};
    sw_status st = {0};
    if (sw__gpu_view_init(&out->v, &cam, W, H, near_plane, &st) != SW_OK) {
        fprintf(stderr, "FAIL: view: %s\n", st.message);
        return 0;
    }
    out->plane = (sw__curves_plane){{-eye[0], -eye[1], -eye[2]}, {1, 0, 0}, {0, 1, 0}};
    return 1;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* depth along the view axis and pixel position of plane point (x, y) */
static double plane_depth(const scene_view *s, double x, double y)
{
    double p[3];
    for (int k = 0; k < 3; ++k)
        p[k] = s->plane.origin[k] + x * s->plane.ax[k] + y * s->plane.ay[k];
    return dot3(s->v.fwd, p);
}

static void to_px(const scene_view *s, const double q[2], double out[2])
{
    double p[3];
    for (int k = 0; k < 3; ++k)
        p[k] = s->plane.origin[k] + q[0] * s->plane.ax[k] + q[1] * s->plane.ay[k];
    double d = dot3(s->v.fwd, p);
    out[0] = 0.5 * W * (1 + dot3(s->v.right, p) / (d * s->v.tan_x));
    out[1] = 0.5 * H * (1 + dot3(s->v.up, p) / (d * s->v.tan_y));
}

/* Emits the end point (plane coordinates) of each chord of piece h (homogeneous, degree p). */
static void flatten_piece(const scene_view *s, const double *h, int p, ref_poly *pl, int depth)
{
    double e[2] = {h[3 * p] / h[3 * p + 2], h[3 * p + 1] / h[3 * p + 2]};
    int front = 1, behind = 1, beyond[4] = {1, 1, 1, 1};
    double px[12][2];
    for (int i = 0; i <= p; ++i) {
        double q[2] = {h[3 * i] / h[3 * i + 2], h[3 * i + 1] / h[3 * i + 2]};
        double d = plane_depth(s, q[0], q[1]);
        front &= d >= s->v.near_plane;
        behind &= d < s->v.near_plane;
        if (d > 0) {
            to_px(s, q, px[i]);
            beyond[0] &= px[i][0] < -2;
            beyond[1] &= px[i][0] > W + 2;
            beyond[2] &= px[i][1] < -2;
            beyond[3] &= px[i][1] > H + 2;
        }
    }
    int split = depth < 50 && !behind;
    if (split && front && (beyond[0] || beyond[1] || beyond[2] || beyond[3]))
        split = 0;
    if (split && front) { /* flat enough on screen? the image's control points are the images */
        double d[2] = {px[p][0] - px[0][0], px[p][1] - px[0][1]}, len2 = d[0] * d[0] + d[1] * d[1];
        double worst = 0;
        for (int i = 1; i < p; ++i) {
            double q[2] = {px[i][0] - px[0][0], px[i][1] - px[0][1]};
            double t = len2 > 0 ? (q[0] * d[0] + q[1] * d[1]) / len2 : 0;
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            worst = fmax(worst, hypot(q[0] - t * d[0], q[1] - t * d[1]));
        }
        split = worst > 1e-3;
    }
    if (split) {
        double l[3 * 12], r[3 * 12];
        ref_split_half(h, p, l, r);
        flatten_piece(s, l, p, pl, depth + 1);
        flatten_piece(s, r, p, pl, depth + 1);
        return;
    }
    ref_poly_add(pl, e);
}

typedef struct plane_flatten {
    const scene_view *s;
    ref_poly *pl;
} plane_flatten;

static void flatten_bezier(void *ctx, const double *h, int p)
{
    const plane_flatten *f = ctx;
    flatten_piece(f->s, h, p, f->pl, 0);
}

/* A curve's Bézier pieces by knot insertion, flattened. */
static void flatten_curve(const scene_view *s, const tcurve *c, ref_poly *pl)
{
    plane_flatten f = {s, pl};
    ref_curve_pieces(c->deg, c->n, c->knots, c->cpw, flatten_bezier, &f);
}

/* The polygon cut to depth >= near (Sutherland-Hodgman), projected; cut points become corners. */
static void cut_and_project(const scene_view *s, const ref_poly *in, ref_poly *out,
                            ref_poly *corners)
{
    for (size_t k = 0; k < in->n; ++k) {
        const double *a = in->p[k], *b = in->p[(k + 1) % in->n];
        double da = plane_depth(s, a[0], a[1]) - s->v.near_plane,
               db = plane_depth(s, b[0], b[1]) - s->v.near_plane;
        if (da >= 0) {
            double q[2];
            to_px(s, a, q);
            ref_poly_add(out, q);
        }
        if ((da >= 0) != (db >= 0)) {
            double t = da / (da - db), m[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])},
                   q[2];
            to_px(s, m, q);
            ref_poly_add(out, q);
            ref_poly_add(corners, q);
        }
    }
}

static void reference(const scene_view *s, const outline *o, double *cov, ref_poly *corners)
{
    memset(cov, 0, sizeof(double) * W * H);
    for (int L = 0; L < N_LOOPS; ++L) {
        ref_poly pl = {0}, pr = {0};
        for (int k = 0; k < N_CURVES; ++k)
            if (o->loop_of[k] == L)
                flatten_curve(s, &o->c[k], &pl);
        cut_and_project(s, &pl, &pr, corners);
        if (pr.n >= 3)
            ref_area_accumulate(&pr, o->sign[L], W, H, cov);
        free(pl.p);
        free(pr.p);
    }
    for (int i = 0; i < W * H; ++i)
        cov[i] = fmin(fabs(cov[i]), 1.0);
    for (int k = 0; k < o->n_corners; ++k)
        if (plane_depth(s, o->corners[k][0], o->corners[k][1]) > s->v.near_plane) {
            double q[2];
            to_px(s, o->corners[k], q);
            ref_poly_add(corners, q);
        }
}

/* ---- the occluder: an opaque quad drawn with the frame's depth convention ---------------------
 */

typedef struct occluder {
    int on;
    double n[3], c; /* world plane n . x = c */
    double quad[4][3];
    float color[4];
} occluder;

static GLuint g_wall_prog;

static const char *k_wall_vs = "#version 450 core\n"
                               "layout(location = 0) in vec3 a_pos;\n"
                               "uniform mat4 u_vp;\n"
                               "void main() { gl_Position = u_vp * vec4(a_pos, 1.0); }\n";
static const char *k_wall_fs = "#version 450 core\n"
                               "uniform vec4 u_c;\n"
                               "layout(location = 0) out vec4 o;\n"
                               "void main() { o = u_c; }\n";

static void draw_occluder(const scene_view *s, const double eye[3], const occluder *oc)
{
    float q[4][3];
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j)
            q[k][j] = (float)(oc->quad[k][j] - eye[j]);
    GLuint vao, vbo;
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof q, q, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glUseProgram(g_wall_prog);
    glUniformMatrix4fv(glGetUniformLocation(g_wall_prog, "u_vp"), 1, GL_FALSE, s->v.view_proj);
    glUniform4fv(glGetUniformLocation(g_wall_prog, "u_c"), 1, oc->color);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glUseProgram(0);
}

/* ray parameter (distance units of the direction) from the eye to a plane; INFINITY: none */
static double ray_plane(const double dir[3], const double eye[3], const double n[3], double c)
{
    double den = dot3(n, dir);
    if (den == 0)
        return INFINITY;
    double t = (c - dot3(n, eye)) / den;
    return t > 0 ? t : INFINITY;
}

/* ---- one view ----------------------------------------------------------------------------- */

typedef struct view_case {
    const char *name;
    double eye[3], target[3], fovy, near_plane;
    occluder oc;
    int expect_hidden; /* nothing of the outline may show */
} view_case;

/* Whether the outline's plane is nearer than the occluder's along the ray through pixel point
 * (x, y), by the decal rule: an outline less than SW__CURVES_DECAL_PULL of its distance behind
 * a surface shows on it (the distances' ratio along a ray is their view-axis depths' ratio). */
static int outline_shown(const scene_view *s, const view_case *vc, double x, double y)
{
    double u = (2 * x / W - 1) * s->v.tan_x, v = (2 * y / H - 1) * s->v.tan_y, dir[3];
    for (int k = 0; k < 3; ++k)
        dir[k] = s->v.fwd[k] + u * s->v.right[k] + v * s->v.up[k];
    const double zn[3] = {0, 0, 1};
    double t_shape = ray_plane(dir, vc->eye, zn, 0.0);
    double t_wall = vc->oc.on ? ray_plane(dir, vc->eye, vc->oc.n, vc->oc.c) : INFINITY;
    return t_shape <= t_wall * (1.0 + SW__CURVES_DECAL_PULL);
}

static int run_case(sw__curves_renderer *r, const outline *o, const sw__curves_loop *loops,
                    const view_case *vc, GLuint fbo)
{
    scene_view s;
    if (!make_view(vc->eye, vc->target, vc->fovy, vc->near_plane, &s))
        return 0;
    const float bg[4] = {0, 0, 0.25f, 1};
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, W, H);
    glClearColor(bg[0], bg[1], bg[2], bg[3]);
    glClearDepth(0.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (vc->oc.on)
        draw_occluder(&s, vc->eye, &vc->oc);

    sw_status st = {0};
    sw__curves_projected pr;
    if (sw__curves_project(loops, N_LOOPS, &s.plane, &s.v, &pr, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s: project: %s\n", vc->name, st.message);
        return 0;
    }
    const float red[4] = {1, 0, 0, 1};
    sw__curves_view cv = {{1, 0, 0, 0, 1, 0}, W, H};
    if (pr.shape && sw__curves_draw_placed(r, pr.shape, &cv, red, fbo, &pr.depth, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s: draw: %s\n", vc->name, st.message);
        return 0;
    }
    static unsigned char px[W * H * 4];
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);

    static double cov[W * H];
    ref_poly corners = {0};
    reference(&s, o, cov, &corners);
    double sum = 0, mx = 0, csum = 0, cmx = 0;
    size_t n_edge = 0, n_corner = 0, n_wall_line = 0, n_red = 0, n_visible = 0;
    int mxi = 0, mxj = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const unsigned char *q = px + 4 * (j * W + i);
            n_red += q[0] > 0;
            if (vc->expect_hidden)
                continue;
            int shown = outline_shown(&s, vc, i + 0.5, j + 0.5), changes = 0;
            /* within 1.5 px of where the wall meets the outline's plane: not judged */
            for (int k = 0; k < 4; ++k)
                changes |= outline_shown(&s, vc, i + 0.5 + ((k & 1) ? 1.5 : -1.5) * !(k & 2),
                                         j + 0.5 + ((k & 1) ? 1.5 : -1.5) * !!(k & 2)) != shown;
            if (changes) {
                n_wall_line++;
                continue;
            }
            double want = shown ? cov[j * W + i] : 0.0;
            n_visible += shown && want > 0;
            double got = q[0] / 255.0, err = fabs(got - want);
            int near = 0;
            for (size_t k = 0; k < corners.n && !near; ++k)
                near = hypot(i + 0.5 - corners.p[k][0], j + 0.5 - corners.p[k][1]) <= 1.5;
            if (near) {
                n_corner++;
                csum += err;
                cmx = fmax(cmx, err);
                continue;
            }
            if ((want > 1e-9 && want < 1 - 1e-9) || (q[0] > 0 && q[0] < 255)) {
                n_edge++;
                sum += err;
            }
            if (err > mx) {
                mx = err;
                mxi = i;
                mxj = j;
            }
        }
    free(corners.p);
    if (getenv("SW_PLACED_DUMP")) { /* error image: red = rendered too high, green = too low */
        char path[256];
        snprintf(path, sizeof path, "%s/placed_%s.ppm", getenv("SW_PLACED_DUMP"), vc->name);
        FILE *f = fopen(path, "wb");
        if (f) {
            fprintf(f, "P6 %d %d 255\n", W, H);
            for (int j = H - 1; j >= 0; --j)
                for (int i = 0; i < W; ++i) {
                    double e = px[4 * (j * W + i)] / 255.0 - cov[j * W + i];
                    unsigned char c[3] = {(unsigned char)fmin(255, fmax(0, e * 2550)),
                                          (unsigned char)fmin(255, fmax(0, -e * 2550)),
                                          (unsigned char)(px[4 * (j * W + i)] / 4)};
                    fwrite(c, 1, 3, f);
                }
            fclose(f);
        }
    }
    double mean = n_edge ? sum / n_edge : 0;
    printf("  %-7s pieces %4zu (approx %3u)  fallbacks %u  edge px %5zu  mean %5.2f/255  max "
           "%6.2f/255 at (%d,%d)  | near corners/cuts: %3zu px, max %6.2f/255 | wall line %zu px "
           "| red px %zu\n",
           vc->name, pr.shape ? pr.shape->n_pieces : 0, pr.shape ? pr.shape->n_approx : 0,
           pr.fallbacks, n_edge, mean * 255, mx * 255, mxi, mxj, n_corner, cmx * 255, n_wall_line,
           n_red);
    sw__curves_shape_free(pr.shape);
    if (vc->expect_hidden)
        return n_red == 0;
    return mean <= 2.0 / 255 && mx <= 12.0 / 255 && n_edge > 0 && n_visible > 0;
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    sw__curves_renderer *r = NULL;
    if (sw__curves_renderer_create(&r, &st) != SW_OK ||
        sw__gpu_program_link(k_wall_vs, k_wall_fs, "test wall", &g_wall_prog, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    GLuint fbo, rb[2];
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(2, rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, W, H);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);

    outline o;
    make_outline(&o);
    sw_sg_curve curves[N_CURVES];
    sw__curves_loop loops[N_LOOPS] = {{0}};
    for (int k = 0; k < N_CURVES; ++k) {
        curves[k] = (sw_sg_curve){o.c[k].deg, o.c[k].n, 3, o.c[k].knots, o.c[k].cpw};
        sw__curves_loop *L = &loops[o.loop_of[k]];
        if (!L->curves)
            L->curves = &curves[k];
        L->n_curves++;
    }
    const occluder none = {0};
    const occluder wall = {1,
                           {1, 0, 0},
                           0.2,
                           {{0.2, -50, -50}, {0.2, 50, -50}, {0.2, 50, 50}, {0.2, -50, 50}},
                           {0, 0.6f, 0, 1}};
    const occluder floor0 = {1,
                             {0, 0, 1},
                             0.0,
                             {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}},
                             {0, 0.5f, 0.5f, 1}};
    /* lifted 2e-5 (about 1e-5 of the distance along the rays: inside the decal rule's 1/4096),
     * then 3e-3 (about 1e-3: outside it) */
    const occluder floor1 = {1,
                             {0, 0, 1},
                             2e-5,
                             {{-50, -50, 2e-5}, {50, -50, 2e-5}, {50, 50, 2e-5}, {-50, 50, 2e-5}},
                             {0, 0.5f, 0.5f, 1}};
    const occluder floor2 = {1,
                             {0, 0, 1},
                             3e-3,
                             {{-50, -50, 3e-3}, {50, -50, 3e-3}, {50, 50, 3e-3}, {-50, 50, 3e-3}},
                             {0, 0.5f, 0.5f, 1}};
    const view_case cases[] = {
        {"tilted", {0.3, -2.2, 1.6}, {0.2, 0, 0}, 60, 0.05, none, 0},
        {"near", {-0.2, -0.5, 0.4}, {0.0, 0.4, 0.0}, 90, 0.35, none, 0},
        {"zoom",
         {-1.5, -3.0, 2.0},
         {-0.25 + 0.22 * cos(0.7), 0.05 + 0.22 * sin(0.7), 0},
         1.5,
         0.05,
         none,
         0},
        {"wall", {0.3, -2.2, 1.6}, {0.2, 0, 0}, 60, 0.05, wall, 0},
        {"decal", {0.3, -2.2, 1.6}, {0.2, 0, 0}, 60, 0.05, floor0, 0},
        {"lifted", {0.3, -2.2, 1.6}, {0.2, 0, 0}, 60, 0.05, floor1, 0},
        {"buried", {0.3, -2.2, 1.6}, {0.2, 0, 0}, 60, 0.05, floor2, 1},
    };
    int ok = 1;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k)
        if (!run_case(r, &o, loops, &cases[k], fbo)) {
            printf("  %s: FAIL\n", cases[k].name);
            ok = 0;
        }
    printf("placed outlines: %s\n", ok ? "ok" : "FAIL");
    sw__curves_renderer_free(r);
    glDeleteProgram(g_wall_prog);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(2, rb);
    sw_gpu_context_free(ctx);
    return ok ? 0 : 1;
}

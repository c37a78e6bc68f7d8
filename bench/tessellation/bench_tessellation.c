/* SPDX-License-Identifier: MIT */
/* bench/tessellation (Guthe et al. 2005 §9, Fig. 9): frame time of one rational bicubic patch,
 * untrimmed and trimmed (a star-shaped outer loop with a circular hole), at growing screen size,
 * rendered by splinewalk (sw_gpu_render_scene) and by Mesa's GLU NURBS tessellator (glu_nurbs.c)
 * in the same EGL context, at the same ε_img. Prints medians and the ratio GLU / splinewalk; a
 * benchmark, not a test.
 *
 * Fairness: GLU's triangles are drawn as gpu/draw.c draws splinewalk's (vbo_draw.c: clear, upload
 * to a VBO, one indexed draw shaded alike, same view-projection, glFinish), and splinewalk's
 * readback is not counted. GLU re-tessellates every frame, so splinewalk regenerates its trim
 * texture every frame too (as the paper does) unless --keep-trims is given. Whether GLU delivers
 * the accuracy asked for is measured, not assumed: the screen distance between its triangles and
 * the surface at the same (u, v) (the numerical screen-space criterion), and the pixels
 * each renderer covered.
 */
#include "cli_numbers.h"
#include "glu_nurbs.h"
#include "vbo_draw.h"
#include "wavy_patch.h"
#include "sw_gpu_internal.h"
#include "sw_sg_scene.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FRAMES 1001
#define STAR_N 7     /* star points */
#define MAX_SPLIT 64 /* --glu-trim-split */
#define N_SIZES 6
static const int k_sizes[N_SIZES] = {32, 64, 128, 256, 512, 1024};
static const int32_t k_width = 1280, k_height = 1024;

/* ---- the patch and its trim loops ----------------------------------------------------------- */
static const double k_star_c[2] = {0.5, 0.5}, k_star_ro = 0.48, k_star_ri = 0.3;
static const double k_hole_c[2] = {0.46, 0.53}, k_hole_r = 0.15;

typedef struct shape {
    double cpw[64];                    /* homogeneous, u fastest, world space */
    double star[2 * (2 * STAR_N + 1)]; /* closed polyline, counter-clockwise (outer) */
    double star_knots[2 * STAR_N + 3]; /* the same as a degree-1 B-spline */
    double hole[27];                   /* rational quadratic circle, clockwise (hole) */
    double star_box[4];                /* u0, u1, v0, v1 */
} shape;

static const double k_circle_knots[12] = {0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1};

static void make_shape(shape *s)
{
    bt_wavy_cpw(s->cpw);
    s->star_box[0] = s->star_box[2] = INFINITY;
    s->star_box[1] = s->star_box[3] = -INFINITY;
    for (int k = 0; k <= 2 * STAR_N; ++k) {
        double r = (k % 2) ? k_star_ri : k_star_ro,
               a = M_PI / 2.0 + M_PI * (k % (2 * STAR_N)) / STAR_N;
        s->star[2 * k] = k_star_c[0] + r * cos(a);
        s->star[2 * k + 1] = k_star_c[1] + r * sin(a);
        for (int c = 0; c < 2; ++c) {
            s->star_box[2 * c] = fmin(s->star_box[2 * c], s->star[2 * k + c]);
            s->star_box[2 * c + 1] = fmax(s->star_box[2 * c + 1], s->star[2 * k + c]);
        }
    }
    s->star_knots[0] = 0.0;
    for (int k = 0; k <= 2 * STAR_N; ++k)
        s->star_knots[k + 1] = (double)k / (2.0 * STAR_N);
    s->star_knots[2 * STAR_N + 2] = 1.0;
    /* Directions walked clockwise: the hole of an outer counter-clockwise loop, as GLU wants. */
    static const double dir[9][2] = {{1, 0},  {1, -1}, {0, -1}, {-1, -1}, {-1, 0},
                                     {-1, 1}, {0, 1},  {1, 1},  {1, 0}};
    for (int i = 0; i < 9; ++i) {
        double w = (i % 2) ? sqrt(0.5) : 1.0;
        s->hole[3 * i] = w * (k_hole_c[0] + k_hole_r * dir[i][0]);
        s->hole[3 * i + 1] = w * (k_hole_c[1] + k_hole_r * dir[i][1]);
        s->hole[3 * i + 2] = w;
    }
}

static sw_sg_surface shape_surface(const shape *s)
{
    return bt_wavy_surface(s->cpw);
}

/* ---- the splinewalk scene -------------------------------------------------------------------- */
static uint32_t add_loop(sw_sg_builder *b, int32_t degree, int32_t n, const double *knots,
                         const double *cpw3, uint32_t flags)
{
    sw_sg_curve_rec c = {(uint32_t)degree, (uint32_t)n, 0, 0};
    c.knots = sw_sg_builder_push_doubles(b, knots, (size_t)(n + degree + 1));
    c.cpw = sw_sg_builder_push_doubles(b, cpw3, (size_t)n * 3);
    sw_sg_loop_rec l = {sw_sg_builder_add_curve(b, &c), 1, flags, 0};
    return sw_sg_builder_add_loop(b, &l);
}

static sw_result build_scene(const shape *s, int trimmed, sw_sg_scene **out, sw_status *st)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return SW_ERR_OUT_OF_MEMORY;
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 3;
    f.n_u = f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, bt_wavy_knots, 8);
    f.knots_v = sw_sg_builder_push_doubles(b, bt_wavy_knots, 8);
    f.cpw = sw_sg_builder_push_doubles(b, s->cpw, 64);
    f.kind = SW_SG_KIND_BSPLINE;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    f.tolerance = 1e-7;
    if (trimmed) {
        double star3[3 * (2 * STAR_N + 1)];
        for (int k = 0; k <= 2 * STAR_N; ++k) {
            star3[3 * k] = s->star[2 * k];
            star3[3 * k + 1] = s->star[2 * k + 1];
            star3[3 * k + 2] = 1.0;
        }
        f.first_loop = add_loop(b, 1, 2 * STAR_N + 1, s->star_knots, star3, SW_SG_LOOP_OUTER);
        add_loop(b, 2, 9, k_circle_knots, s->hole, 0);
        f.n_loops = 2;
        f.flags = SW_SG_FACE_TRIMMED;
        memcpy(f.uv_box, s->star_box, sizeof f.uv_box);
    }
    uint32_t face = sw_sg_builder_add_face(b, &f);
    static const float white[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, white, "patch");
    return sw_sg_builder_finish(b, out, st);
}

/* ---- measurements ---------------------------------------------------------------------------- */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

typedef struct series {
    double tess[MAX_FRAMES], trim[MAX_FRAMES], draw[MAX_FRAMES], total[MAX_FRAMES];
    uint64_t triangles;
    uint64_t covered; /* pixels drawn in the first (warm-up) frame */
    double err[3];    /* GLU, first frame: max error px at vertices, parametric, along the normal */
} series;

typedef struct result {
    double tess, trim, draw, total;
    uint64_t triangles, covered;
    double err[3];
} result;

static result summarize(series *s, int frames)
{
    result r = {median(s->tess, frames),
                median(s->trim, frames),
                median(s->draw, frames),
                median(s->total, frames),
                s->triangles,
                s->covered,
                {s->err[0], s->err[1], s->err[2]}};
    return r;
}

static uint64_t covered_pixels(const sw_gpu_image *img)
{
    uint64_t n = 0;
    for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; ++i)
        n += img->rgba[4 * i + 3] != 0;
    return n;
}

typedef struct bench {
    sw_gpu_context *ctx;
    const shape *shape;
    int frames, keep_trims, glu_trim_split;
    double error_px, glu_error_px; /* ε_img of splinewalk, GLU's parametric tolerance */
    bt_glu *glu;
    bt_glu_mesh glu_mesh;
    bt_draw *draw;
    unsigned glu_gl_errors; /* GL errors GLU's own GL calls raised in the last frame */
} bench;

static sw_gpu_frame_desc frame_desc(const bench *b, double dist)
{
    sw_gpu_frame_desc d;
    memset(&d, 0, sizeof d);
    d.width = k_width;
    d.height = k_height;
    d.error_px = b->error_px;
    d.camera = bt_wavy_camera_at(dist);
    return d;
}

/* splinewalk: frame 0 is a warm-up (shaders, buffers) whose image gives the coverage. */
static int run_splinewalk(bench *b, const sw_sg_scene *scene, double dist, series *s)
{
    sw_gpu_frame_desc desc = frame_desc(b, dist);
    for (int i = -1; i < b->frames; ++i) {
        if (!b->keep_trims)
            sw__gpu_atlas_invalidate(b->ctx);
        sw_gpu_image img;
        sw_gpu_frame_stats fs;
        sw_status st = {0};
        if (sw_gpu_render_scene(b->ctx, scene, &desc, &img, &fs, &st) != SW_OK) {
            fprintf(stderr, "splinewalk frame: %s\n", st.message);
            return 0;
        }
        if (i < 0)
            s->covered = covered_pixels(&img);
        sw_gpu_image_free(&img);
        s->triangles = fs.triangles;
        if (i >= 0) {
            s->tess[i] = fs.ms_tessellate;
            s->trim[i] = fs.ms_trim;
            s->draw[i] = fs.ms_draw;
            s->total[i] = fs.ms_tessellate + fs.ms_trim + fs.ms_draw;
        }
    }
    return 1;
}

/* The patch's control points relative to the eye, in float, as the frame sends them. */
static void eye_relative(const shape *sh, const double eye[3], float cpw[64])
{
    for (int i = 0; i < 16; ++i) {
        const double *p = sh->cpw + 4 * i;
        for (int k = 0; k < 3; ++k)
            cpw[4 * i + k] = (float)(p[k] - p[3] * eye[k]);
        cpw[4 * i + 3] = (float)p[3];
    }
}

typedef struct glu_input {
    float knots[8], cpw[64];
    float star[2 * (2 * STAR_N * MAX_SPLIT + 1)], hole[27], hole_knots[12];
    bt_glu_curve curves[2];
    bt_glu_loop loops[2];
    bt_glu_surface surf;
} glu_input;

/* The star for gluPwlCurve, each edge cut into `split` pieces: GLU does not refine a polyline's
 * edges, and a long straight trim edge in (u, v) is a curve on the surface that its triangles cut
 * across (see the error columns). */
static int32_t star_polyline(const shape *sh, int split, float *out)
{
    int32_t n = 0;
    for (int e = 0; e < 2 * STAR_N; ++e)
        for (int j = 0; j < split; ++j, ++n)
            for (int c = 0; c < 2; ++c) {
                double a = sh->star[2 * e + c], z = sh->star[2 * (e + 1) + c];
                out[2 * n + c] = (float)(a + (z - a) * j / split);
            }
    out[2 * n] = (float)sh->star[0]; /* closed bit for bit */
    out[2 * n + 1] = (float)sh->star[1];
    return n + 1;
}

static void glu_input_init(glu_input *in, const shape *sh, int trimmed, int split)
{
    for (int i = 0; i < 8; ++i)
        in->knots[i] = (float)bt_wavy_knots[i];
    int32_t n_star = star_polyline(sh, split, in->star);
    for (int i = 0; i < 27; ++i)
        in->hole[i] = (float)sh->hole[i];
    for (int i = 0; i < 12; ++i)
        in->hole_knots[i] = (float)k_circle_knots[i];
    in->curves[0] = (bt_glu_curve){0, n_star, NULL, in->star};
    in->curves[1] = (bt_glu_curve){3, 9, in->hole_knots, in->hole};
    in->loops[0] = (bt_glu_loop){&in->curves[0], 1};
    in->loops[1] = (bt_glu_loop){&in->curves[1], 1};
    in->surf =
        (bt_glu_surface){4, 4, 4, 4, in->knots, in->knots, in->cpw, in->loops, trimmed ? 2 : 0};
}

/* The view sw_gpu_render_scene sets up for this camera (near plane from the control-net box). */
static sw_result glu_view(const bench *b, const sw_gpu_camera *cam, sw__gpu_view *v)
{
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < 16; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = b->shape->cpw[4 * i + k] / b->shape->cpw[4 * i + 3];
            box[k] = fmin(box[k], x);
            box[3 + k] = fmax(box[3 + k], x);
        }
    return sw__gpu_view_init(v, cam, k_width, k_height, sw__gpu_near_plane(cam->eye, box), NULL);
}

/* One GLU frame: tessellate (timed with the eye-relative conversion), then draw. */
static int glu_frame(bench *b, glu_input *in, const sw__gpu_view *v, double *ms_tess,
                     double *ms_draw)
{
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    int32_t vp[4] = {0, 0, v->width, v->height};
    bt_glu_mesh *m = &b->glu_mesh;
    double t0 = sw__clock_ms();
    eye_relative(b->shape, v->eye, in->cpw);
    int rc = bt_glu_tessellate(b->glu, &in->surf, identity, v->view_proj, vp, m);
    double t1 = sw__clock_ms();
    if (rc != 0) {
        fprintf(stderr, "GLU: %s\n", bt_glu_error_str(rc));
        return 0;
    }
    b->glu_gl_errors = bt_draw_drain_errors();
    unsigned e =
        bt_draw_mesh(b->draw, v->view_proj, m->v, m->n_v, BT_GLU_VERTEX_FLOATS, m->idx, m->n_idx);
    double t2 = sw__clock_ms();
    if (e != 0) {
        fprintf(stderr, "GLU draw: GL error 0x%04x\n", e);
        return 0;
    }
    *ms_tess = t1 - t0;
    *ms_draw = t2 - t1;
    return 1;
}

/* Pixel position of an eye-relative point. */
static void project(const sw__gpu_view *v, const double p[3], double px[2])
{
    double x = 0.0, y = 0.0, w = 0.0;
    for (int k = 0; k < 3; ++k) {
        x += v->right[k] * p[k];
        y += v->up[k] * p[k];
        w += v->fwd[k] * p[k];
    }
    px[0] = (x / (w * v->tan_x) + 1.0) * 0.5 * v->width;
    px[1] = (y / (w * v->tan_y) + 1.0) * 0.5 * v->height;
}

/* Screen-space error of a point of GLU's mesh (barycentric bc in triangle t) against the surface
 * point at the same (u, v), interpolated from the triangle's vertices: the whole distance
 * (parametric error, what GLU_PARAMETRIC_ERROR bounds) and its component along the surface normal
 * (what moves silhouettes and depth; sliding along the surface only shifts shading). */
static void point_error_px(const bench *b, const sw__gpu_view *v, const uint32_t *t,
                           const double bc[3], double *param, double *normal)
{
    const bt_glu_mesh *m = &b->glu_mesh;
    double x[3] = {0, 0, 0}, uv[2] = {0, 0};
    for (int c = 0; c < 3; ++c) {
        const float *q = m->v + (size_t)t[c] * BT_GLU_VERTEX_FLOATS;
        for (int k = 0; k < 3; ++k)
            x[k] += bc[c] * q[k];
        uv[0] += bc[c] * q[6];
        uv[1] += bc[c] * q[7];
    }
    sw_sg_surface srf = shape_surface(b->shape);
    sw_sg_surface_d2 d;
    sw_sg_surface_eval_d2(&srf, fmin(fmax(uv[0], 0.0), 1.0), fmin(fmax(uv[1], 0.0), 1.0), &d);
    double n[3] = {d.du[1] * d.dv[2] - d.du[2] * d.dv[1], d.du[2] * d.dv[0] - d.du[0] * d.dv[2],
                   d.du[0] * d.dv[1] - d.du[1] * d.dv[0]};
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), s[3], along = 0.0;
    for (int k = 0; k < 3; ++k) {
        s[k] = d.p[k] - v->eye[k];
        n[k] = nn > 0.0 ? n[k] / nn : 0.0;
        along += (x[k] - s[k]) * n[k];
    }
    double sn[3] = {s[0] + along * n[0], s[1] + along * n[1], s[2] + along * n[2]};
    double px_x[2], px_s[2], px_n[2];
    project(v, x, px_x);
    project(v, s, px_s);
    project(v, sn, px_n);
    *param = hypot(px_x[0] - px_s[0], px_x[1] - px_s[1]);
    *normal = hypot(px_n[0] - px_s[0], px_n[1] - px_s[1]);
}

/* Largest screen-space errors of GLU's last mesh (see point_error_px) at its vertices (a check
 * of the (u, v) it passed) and at edge midpoints and centroids, in pixels. */
static void measure_glu_error(const bench *b, const sw__gpu_view *v, double err[3])
{
    static const double k_bc[7][3] = {{1, 0, 0},
                                      {0, 1, 0},
                                      {0, 0, 1},
                                      {.5, .5, 0},
                                      {0, .5, .5},
                                      {.5, 0, .5},
                                      {1. / 3, 1. / 3, 1. / 3}};
    const bt_glu_mesh *m = &b->glu_mesh;
    err[0] = err[1] = err[2] = 0.0; /* vertices, parametric, normal */
    for (size_t i = 0; i + 2 < m->n_idx; i += 3)
        for (int k = 0; k < 7; ++k) {
            double e, en;
            point_error_px(b, v, m->idx + i, k_bc[k], &e, &en);
            if (k < 3) {
                err[0] = fmax(err[0], e);
            } else {
                err[1] = fmax(err[1], e);
                err[2] = fmax(err[2], en);
            }
        }
}

static int run_glu(bench *b, int trimmed, double dist, series *s)
{
    static glu_input in;
    glu_input_init(&in, b->shape, trimmed, b->glu_trim_split);
    sw_gpu_camera cam = bt_wavy_camera_at(dist);
    sw__gpu_view v;
    if (glu_view(b, &cam, &v) != SW_OK)
        return 0;
    for (int i = -1; i < b->frames; ++i) {
        double tess, draw;
        if (!glu_frame(b, &in, &v, &tess, &draw))
            return 0;
        s->triangles = b->glu_mesh.n_idx / 3;
        if (i < 0) {
            s->covered = bt_draw_covered(b->draw);
            measure_glu_error(b, &v, s->err);
            continue;
        }
        s->tess[i] = tess;
        s->trim[i] = 0.0;
        s->draw[i] = draw;
        s->total[i] = tess + draw;
    }
    return 1;
}

/* ---- report ---------------------------------------------------------------------------------- */
static void print_legend(void)
{
    printf("size: the patch's width on screen (camera distance fitted); tess / trim / draw: "
           "tessellation, trim texture, upload + draw until glFinish; total: their frame time "
           "(splinewalk's readback excluded); GLU/sw: ratio of the totals (> 1: splinewalk "
           "faster); GLU error: largest screen distance, at edge midpoints and centroids of GLU's "
           "triangles, to the surface at the same (u, v) (param.) and its part along the surface "
           "normal (normal); covered px: pixels drawn, a check that both drew the same shape\n");
}

static void print_table_head(const char *what)
{
    printf("\n%s\n", what);
    printf("  size |          splinewalk (median ms)         |      GLU (median ms)           | "
           "GLU/sw | GLU error px  | covered px\n");
    printf("    px | triangles   tess   trim   draw  total | triangles   tess   draw  total | "
           " total | param. normal | sw / GLU\n");
}

static void print_row(int size, const result *sw, const result *gl)
{
    printf("  %4d | %9llu %6.2f %6.2f %6.2f %6.2f | %9llu %6.2f %6.2f %6.2f | %6.2f | %6.2f %6.2f "
           "| %llu / %llu\n",
           size, (unsigned long long)sw->triangles, sw->tess, sw->trim, sw->draw, sw->total,
           (unsigned long long)gl->triangles, gl->tess, gl->draw, gl->total, gl->total / sw->total,
           gl->err[1], gl->err[2], (unsigned long long)sw->covered,
           (unsigned long long)gl->covered);
}

/* Sanity checks of one row (warnings; the benchmark is no test). 0 = fatal. */
static int check_row(int size, const result *sw, const result *gl)
{
    if (sw->triangles == 0 || gl->triangles == 0) {
        fprintf(stderr, "error: size %d: no triangles (splinewalk %llu, GLU %llu)\n", size,
                (unsigned long long)sw->triangles, (unsigned long long)gl->triangles);
        return 0;
    }
    if (gl->err[0] > 0.05)
        printf("  warning: size %d: GLU's vertices are %.2f px off the surface at the (u, v) it "
               "passed: its error column is not meaningful\n",
               size, gl->err[0]);
    double a = (double)sw->covered, c = (double)gl->covered;
    if (fabs(a - c) > 0.05 * fmax(a, c) + 4.0 * size)
        printf("  warning: size %d: splinewalk covers %llu pixels, GLU %llu: not the same shape?\n",
               size, (unsigned long long)sw->covered, (unsigned long long)gl->covered);
    return 1;
}

static void check_growth(const uint64_t glu_tris[N_SIZES])
{
    if ((double)glu_tris[N_SIZES - 1] <= 1.5 * (double)glu_tris[0])
        printf("  warning: GLU's triangle count hardly grows with screen size (%llu at %d px, %llu "
               "at %d px): are the sampling matrices loaded (GLU_AUTO_LOAD_MATRIX trap)?\n",
               (unsigned long long)glu_tris[0], k_sizes[0],
               (unsigned long long)glu_tris[N_SIZES - 1], k_sizes[N_SIZES - 1]);
}

static int run_scene(bench *b, int trimmed)
{
    sw_status st = {0};
    sw_sg_scene *scene = NULL;
    if (build_scene(b->shape, trimmed, &scene, &st) != SW_OK) {
        fprintf(stderr, "scene: %s\n", st.message);
        return 0;
    }
    print_table_head(trimmed ? "trimmed (star-shaped outer loop, circular hole)" : "untrimmed");
    static series sw_s, gl_s;
    uint64_t glu_tris[N_SIZES];
    double worst = 0.0; /* GLU's largest error along the normal, px */
    int worst_size = 0;
    int ok = 1;
    for (int k = 0; k < N_SIZES && ok; ++k) {
        double across,
            dist = bt_wavy_fit_distance(b->shape->cpw, k_sizes[k], k_width, k_height, &across);
        if (fabs(across - k_sizes[k]) > 0.5)
            printf("  warning: the patch is %.1f px across, not %d\n", across, k_sizes[k]);
        ok = run_splinewalk(b, scene, dist, &sw_s) && run_glu(b, trimmed, dist, &gl_s);
        if (!ok)
            break;
        result sw = summarize(&sw_s, b->frames), gl = summarize(&gl_s, b->frames);
        print_row(k_sizes[k], &sw, &gl);
        ok = check_row(k_sizes[k], &sw, &gl);
        glu_tris[k] = gl.triangles;
        if (gl.err[2] > worst) {
            worst = gl.err[2];
            worst_size = k_sizes[k];
        }
    }
    if (ok)
        check_growth(glu_tris);
    if (ok && worst > 1.5 * b->error_px)
        printf("  warning: GLU's mesh leaves the surface by up to %.2f px along its normal (at %d "
               "px), eps_img is %.3g px: it is coarser than asked, which flatters its times\n",
               worst, worst_size, b->error_px);
    sw_sg_scene_free(scene);
    return ok;
}

/* ---- main ------------------------------------------------------------------------------------ */
static void usage(FILE *f, const char *argv0)
{
    fprintf(
        f,
        "usage: %s [--frames N] [--error PX] [--glu-error PX] [--glu-trim-split K]\n"
        "       [--keep-trims]\n"
        "Guthe et al. 2005 Fig. 9: one rational bicubic patch, untrimmed and trimmed, drawn\n"
        "%d, %d, %d, %d, %d and %d pixels across in a %dx%d frame by splinewalk\n"
        "(sw_gpu_render_scene) and by GLU's NURBS tessellator (GLU_NURBS_TESSELLATOR,\n"
        "GLU_PARAMETRIC_ERROR, output drawn from a VBO) in one headless EGL context.\n"
        "Prints per size the triangles and median frame times in ms (splinewalk: tessellate,\n"
        "trim texture, draw, total without readback; GLU: tessellate, draw, total) and the\n"
        "ratio GLU / splinewalk of the totals (> 1: splinewalk faster), GLU's measured\n"
        "screen-space error, and the pixels each covered.\n"
        "  --frames N     frames per measurement, median reported (default 21, max %d)\n"
        "  --error PX     screen-space error ε_img in pixels (default 0.5)\n"
        "  --glu-error PX GLU_PARAMETRIC_TOLERANCE in pixels (default: the --error value);\n"
        "                 lower it to match the accuracy splinewalk reaches\n"
        "  --glu-trim-split K  cut each edge of the star-shaped trim polyline into K pieces\n"
        "                 for GLU (1..%d, default 1): GLU does not refine polyline trim edges,\n"
        "                 so long ones leave its mesh off the surface (see the error columns)\n"
        "  --keep-trims   keep splinewalk's trim texture across frames (default: regenerated\n"
        "                 every frame, as in the paper and as GLU re-tessellates)\n"
        "Environment: LP_NUM_THREADS (llvmpipe's raster threads) is set to 2 unless already\n"
        "set. The context is sw_gpu_context_create_headless's (EGL, surfaceless first).\n",
        argv0, k_sizes[0], k_sizes[1], k_sizes[2], k_sizes[3], k_sizes[4], k_sizes[5], k_width,
        k_height, MAX_FRAMES, MAX_SPLIT);
}

/* Returns 1 to run, 0 to exit successfully (--help), -1 on a usage error. */
static int parse_args(int argc, char **argv, bench *b)
{
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout, argv[0]);
            return 0;
        } else if (strcmp(a, "--keep-trims") == 0) {
            b->keep_trims = 1;
        } else if (strcmp(a, "--frames") == 0 && i + 1 < argc) {
            b->frames = atoi(argv[++i]);
        } else if (strcmp(a, "--error") == 0 && i + 1 < argc &&
                   !sw_cli_parse_error_px(argv[i + 1], &b->error_px)) {
            i++;
        } else if (strcmp(a, "--glu-trim-split") == 0 && i + 1 < argc) {
            b->glu_trim_split = atoi(argv[++i]);
        } else if (strcmp(a, "--glu-error") == 0 && i + 1 < argc &&
                   !sw_cli_parse_positive(argv[i + 1], &b->glu_error_px)) {
            i++;
        } else {
            fprintf(stderr, "unknown or incomplete argument '%s'\n", a);
            return -1;
        }
    }
    if (b->glu_error_px == 0.0)
        b->glu_error_px = b->error_px;
    if (b->frames < 1 || b->frames > MAX_FRAMES || !(b->error_px > 0.0) || !(b->error_px < 1e3) ||
        !(b->glu_error_px > 0.0) || !(b->glu_error_px < 1e3) || b->glu_trim_split < 1 ||
        b->glu_trim_split > MAX_SPLIT) {
        fprintf(stderr,
                "--frames must be in 1..%d, --error and --glu-error in (0, 1000), "
                "--glu-trim-split in 1..%d\n",
                MAX_FRAMES, MAX_SPLIT);
        return -1;
    }
    return 1;
}

int main(int argc, char **argv)
{
    shape sh;
    make_shape(&sh);
    bench b = {NULL, &sh, 21, 0, 1, 0.5, 0.0, NULL, {0}, NULL, 0};
    int pa = parse_args(argc, argv, &b);
    if (pa <= 0) {
        if (pa < 0)
            usage(stderr, argv[0]);
        return pa < 0 ? 2 : 0;
    }
    int lp_user = getenv("LP_NUM_THREADS") != NULL;
    if (!lp_user)
        setenv("LP_NUM_THREADS", "2", 0);
    sw_status st = {0};
    if (sw_gpu_context_create_headless(&b.ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    char err[512] = "";
    b.glu = bt_glu_create((float)b.glu_error_px);
    b.draw = bt_draw_create(k_width, k_height, err, sizeof err);
    if (!b.glu || !b.draw) {
        fprintf(stderr, "%s\n", b.glu ? err : "GLU: gluNewNurbsRenderer failed");
        bt_glu_free(b.glu);
        bt_draw_free(b.draw);
        sw_gpu_context_free(b.ctx);
        return 1;
    }
    printf("bench_tessellation: %s | LP_NUM_THREADS=%s (%s) | frame %dx%d | eps_img %.3g px "
           "(GLU tolerance %.3g px, star edges cut in %d for GLU) | medians of %d frames | trim "
           "texture %s\n",
           sw_gpu_context_description_ptr(b.ctx), getenv("LP_NUM_THREADS"),
           lp_user ? "from the environment" : "set by the bench", k_width, k_height, b.error_px,
           b.glu_error_px, b.glu_trim_split, b.frames,
           b.keep_trims ? "kept across frames" : "regenerated every frame");
    print_legend();
    int ok = run_scene(&b, 0) && run_scene(&b, 1);
    if (ok && b.glu_gl_errors)
        printf("\nnote: GLU's own fixed-function GL calls (glPushAttrib, glEnable(GL_MAP2_*), ...) "
               "leave %u GL error flag(s) set after each tessellation in the core context; drained "
               "(outside the timing), they change no state\n",
               b.glu_gl_errors);
    bt_glu_mesh_free(&b.glu_mesh);
    bt_glu_free(b.glu);
    bt_draw_free(b.draw);
    sw_gpu_context_free(b.ctx);
    return ok ? 0 : 1;
}

/* SPDX-License-Identifier: MIT */
/* Rendering, analytic: a planar NURBS square with a circular hole (an exact rational
 * quadratic circle as trim curve) and a star-shaped hole (a degree-1 loop), rendered at 512x512
 * looking straight at it. Every pixel whose centre is more than 1 pixel from a boundary (computed
 * here by projecting the analytic shape) must be covered exactly when the analytic shape says so,
 * and covered pixels must carry the plane's depth. Also writes the frame as PNG and EXR.
 *
 * Then close-ups, by trim textures and by exact trim edges (desc.trim_edges): the bolt hole
 * filling the screen, and its edge at 10x and 200x that, each with and without fat borders. The
 * edge displacement of a view is the largest distance, in pixels, from the exact boundary of a
 * pixel centre classified wrongly. Exact edges must keep it within 0.25 px without fat borders
 * (the loops are flattened to 1/8 px; what is left is float), and within 0.5 px with them (their
 * outer sliver reaches k_outer x width = 0.25 px beyond the loop by design, gpu/crack_fill.c);
 * they must also be what drew the trims (no trim texture in those views). Trim textures are
 * reported beside them (a texel is up to ε_img on screen, and boundary texels count as inside).
 * Planted fault seen failing: the shader's crossing test without its second condition (the
 * path's ends on either side of the segment's line) → 9,065 pixels misclassified beyond 1 px,
 * 26 px from the boundary.
 *
 * Usage: test_gpu_analytic OUTDIR
 */
#include <splinewalk/sw_image.h>
#include "sw_gpu.h"
#include "sw_gpu_internal.h"
#include "sw_sg_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define W 512
#define H 512
static const double k_dist = 3.0, k_fovy = 40.0;
static const double k_circle_c[2] = {0.3, 0.62}, k_circle_r = 0.17;
static const double k_star_c[2] = {0.64, 0.34}, k_star_ro = 0.22, k_star_ri = 0.09;
#define STAR_N 5

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "FAIL: %s: %s\n", what, st ? st->message : "");
    return 1;
}

static void star_vertex(int k, double out[2])
{
    double r = (k % 2) ? k_star_ri : k_star_ro, a = M_PI / 2.0 + M_PI * k / STAR_N;
    out[0] = k_star_c[0] + r * cos(a);
    out[1] = k_star_c[1] + r * sin(a);
}

static uint32_t add_curve(sw_sg_builder *b, int32_t degree, const double *knots, int32_t n,
                          const double *cpw)
{
    sw_sg_curve_rec c = {(uint32_t)degree, (uint32_t)n, 0, 0};
    c.knots = sw_sg_builder_push_doubles(b, knots, (size_t)(n + degree + 1));
    c.cpw = sw_sg_builder_push_doubles(b, cpw, (size_t)n * 3);
    return sw_sg_builder_add_curve(b, &c);
}

/* Degree-1 closed loop through pts (count points; the closing point is appended). */
static uint32_t add_polygon_loop(sw_sg_builder *b, const double *pts, int count, uint32_t flags)
{
    double knots[64], cpw[3 * 32];
    int n = count + 1;
    knots[0] = 0.0;
    for (int i = 0; i < n; ++i)
        knots[i + 1] = (double)i / (double)(n - 1);
    knots[n + 1] = 1.0;
    for (int i = 0; i < n; ++i) {
        cpw[3 * i] = pts[2 * (i % count)];
        cpw[3 * i + 1] = pts[2 * (i % count) + 1];
        cpw[3 * i + 2] = 1.0;
    }
    uint32_t c = add_curve(b, 1, knots, n, cpw);
    sw_sg_loop_rec l = {c, 1, flags, 0};
    return sw_sg_builder_add_loop(b, &l);
}

static uint32_t add_circle_loop(sw_sg_builder *b, const double centre[2], double r)
{
    static const double knots[12] = {0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1};
    static const double dir[9][2] = {{1, 0},   {1, 1},  {0, 1},  {-1, 1}, {-1, 0},
                                     {-1, -1}, {0, -1}, {1, -1}, {1, 0}};
    double cpw[27];
    for (int i = 0; i < 9; ++i) {
        double w = (i % 2) ? sqrt(0.5) : 1.0;
        cpw[3 * i] = w * (centre[0] + r * dir[i][0]);
        cpw[3 * i + 1] = w * (centre[1] + r * dir[i][1]);
        cpw[3 * i + 2] = w;
    }
    uint32_t c = add_curve(b, 2, knots, 9, cpw);
    sw_sg_loop_rec l = {c, 1, 0, 0};
    return sw_sg_builder_add_loop(b, &l);
}

/* The square [-1,1]^2 (z = 0) over the domain [0,1]^2: biquadratic with two spans each way. */
static int build_scene(sw_sg_scene **out, sw_status *st)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return 0;
    static const double knots[7] = {0, 0, 0, 0.5, 1, 1, 1};
    static const double greville[4] = {0.0, 0.25, 0.75, 1.0};
    double cpw[4 * 4 * 4];
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            double *p = cpw + (j * 4 + i) * 4;
            p[0] = -1.0 + 2.0 * greville[i];
            p[1] = -1.0 + 2.0 * greville[j];
            p[2] = 0.0;
            p[3] = 1.0;
        }
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 2;
    f.n_u = f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, knots, 7);
    f.knots_v = sw_sg_builder_push_doubles(b, knots, 7);
    f.cpw = sw_sg_builder_push_doubles(b, cpw, 64);
    static const double square[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    double star[2 * 2 * STAR_N];
    for (int k = 0; k < 2 * STAR_N; ++k)
        star_vertex(k, star + 2 * k);
    f.first_loop = add_polygon_loop(b, square, 4, SW_SG_LOOP_OUTER);
    add_circle_loop(b, k_circle_c, k_circle_r);
    add_polygon_loop(b, star, 2 * STAR_N, 0);
    f.n_loops = 3;
    f.kind = SW_SG_KIND_PLANE;
    f.flags = SW_SG_FACE_TRIMMED;
    f.uv_box[0] = f.uv_box[2] = 0.0;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    f.tolerance = 1e-7;
    uint32_t face = sw_sg_builder_add_face(b, &f);
    static const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, white, "square");
    return sw_sg_builder_finish(b, out, st) == SW_OK;
}

static double seg_dist(const double p[2], const double a[2], const double b[2])
{
    double d[2] = {b[0] - a[0], b[1] - a[1]}, e[2] = {p[0] - a[0], p[1] - a[1]};
    double t = (d[0] * e[0] + d[1] * e[1]) / (d[0] * d[0] + d[1] * d[1]);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return hypot(e[0] - t * d[0], e[1] - t * d[1]);
}

/* Inside the trimmed face (1/0) and the distance in uv to the nearest boundary. */
static int analytic(const double uv[2], double *dist)
{
    double sq[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, star[2 * STAR_N][2];
    double d = INFINITY;
    for (int k = 0; k < 4; ++k)
        d = fmin(d, seg_dist(uv, sq[k], sq[(k + 1) % 4]));
    double rc = hypot(uv[0] - k_circle_c[0], uv[1] - k_circle_c[1]);
    d = fmin(d, fabs(rc - k_circle_r));
    int in_star = 0;
    for (int k = 0; k < 2 * STAR_N; ++k)
        star_vertex(k, star[k]);
    for (int k = 0, j = 2 * STAR_N - 1; k < 2 * STAR_N; j = k++) {
        d = fmin(d, seg_dist(uv, star[k], star[j]));
        if ((star[k][1] > uv[1]) != (star[j][1] > uv[1]) &&
            uv[0] < (star[j][0] - star[k][0]) * (uv[1] - star[k][1]) / (star[j][1] - star[k][1]) +
                        star[k][0])
            in_star = !in_star;
    }
    *dist = d;
    int in_square = uv[0] >= 0 && uv[0] <= 1 && uv[1] >= 0 && uv[1] <= 1;
    return in_square && rc > k_circle_r && !in_star;
}

/* A view straight down at the square from (cx, cy, dist), looking along -z. */
typedef struct front_view {
    double cx, cy, dist;
} front_view;

/* Misclassified pixels: beyond 1 px from a boundary, and the largest distance of any. */
typedef struct frame_check {
    long checked, band, covered, wrong, bad_depth;
    double max_wrong_px;
} frame_check;

static frame_check check_view(const sw_gpu_image *img, const front_view *v)
{
    double tan_y = tan(k_fovy * M_PI / 360.0), half = v->dist * tan_y; /* world half-height */
    double px_per_uv = 2.0 * (H / 2.0) / half; /* the square spans 2 world units per uv unit */
    frame_check c = {0, 0, 0, 0, 0, 0.0};
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            double wx = v->cx + ((x + 0.5) / (W / 2.0) - 1.0) * half;
            double wy = v->cy + (1.0 - (y + 0.5) / (H / 2.0)) * half;
            double uv[2] = {(wx + 1.0) / 2.0, (wy + 1.0) / 2.0}, d;
            int want = analytic(uv, &d);
            size_t i = (size_t)y * W + (size_t)x;
            int got = img->rgba[4 * i + 3] != 0;
            c.covered += got;
            if (got != want)
                c.max_wrong_px = fmax(c.max_wrong_px, d * px_per_uv);
            if (d * px_per_uv <= 1.0) {
                ++c.band;
                continue;
            }
            ++c.checked;
            if (got && fabs(img->depth[i] - v->dist) > 1e-5 * v->dist)
                ++c.bad_depth;
            if (got != want) {
                if (c.wrong < 10)
                    fprintf(stderr,
                            "pixel (%d,%d) uv (%.4f,%.4f) %.2f px from a boundary: "
                            "covered %d, expected %d\n",
                            x, y, uv[0], uv[1], d * px_per_uv, got, want);
                ++c.wrong;
            }
        }
    }
    return c;
}

static int check_frame(const sw_gpu_image *img)
{
    const front_view v = {0.0, 0.0, k_dist};
    frame_check c = check_view(img, &v);
    printf("analytic: %ld pixels checked (%ld within 1 px of a boundary skipped), %ld covered, "
           "%ld misclassified, %ld with wrong depth\n",
           c.checked, c.band, c.covered, c.wrong, c.bad_depth);
    return c.wrong == 0 && c.bad_depth == 0 && c.covered > W * H / 4;
}

/* The close-ups: the bolt hole filling the screen, its edge at 10x and 200x (the camera over the
 * circle's point at 30 degrees), by trim textures and exact edges, fat borders off and on. */
static int check_close_ups(sw_gpu_context *ctx, const sw_sg_scene *scene)
{
    const double centre[2] = {-1.0 + 2.0 * k_circle_c[0], -1.0 + 2.0 * k_circle_c[1]};
    const double r = 2.0 * k_circle_r, a = M_PI / 6.0;
    const double fill = 1.15 * r / tan(k_fovy * M_PI / 360.0); /* the hole's diameter in view */
    const front_view views[3] = {{centre[0], centre[1], fill},
                                 {centre[0] + r * cos(a), centre[1] + r * sin(a), fill / 10.0},
                                 {centre[0] + r * cos(a), centre[1] + r * sin(a), fill / 200.0}};
    static const char *names[3] = {"hole fills the screen", "its edge at 10x", "its edge at 200x"};
    int ok = 1;
    printf("close-ups (edge displacement: the farthest misclassified pixel centre from the exact "
           "boundary):\n");
    for (int exact = 0; exact < 2; ++exact)
        for (int borders = 0; borders < 2; ++borders)
            for (int k = 0; k < 3; ++k) {
                sw__gpu_set_crack_fill(ctx, borders);
                sw_gpu_frame_desc desc;
                memset(&desc, 0, sizeof desc);
                desc.width = W;
                desc.height = H;
                desc.want_depth = 1;
                desc.trim_edges = exact;
                desc.camera = (sw_gpu_camera){{views[k].cx, views[k].cy, views[k].dist},
                                              {views[k].cx, views[k].cy, 0.0},
                                              {0, 1, 0},
                                              k_fovy};
                sw_gpu_image img;
                sw_gpu_frame_stats fs;
                sw_status st = {0};
                if (sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st) != SW_OK)
                    return !fail("close-up render", &st);
                frame_check c = check_view(&img, &views[k]);
                const double limit = exact ? (borders ? 0.5 : 0.25) : INFINITY;
                printf("  %-8s borders %-3s %-22s: %5.3f px (%ld wrong beyond 1 px), %llu trim "
                       "textures (%llu texels), %llu exact\n",
                       exact ? "exact" : "texture", borders ? "on" : "off", names[k],
                       c.max_wrong_px, c.wrong, (unsigned long long)fs.trim_textures,
                       (unsigned long long)fs.trim_texels, (unsigned long long)fs.trim_exact);
                if (c.wrong != 0 || c.bad_depth != 0 || !(c.max_wrong_px <= limit) ||
                    (exact && (fs.trim_exact == 0 || fs.trim_textures != 0)) ||
                    (!exact && fs.trim_exact != 0)) {
                    printf("  FAIL: %s %s\n", exact ? "exact" : "texture", names[k]);
                    ok = 0;
                }
                sw_gpu_image_free(&img);
            }
    sw__gpu_set_crack_fill(ctx, 1);
    return ok;
}

/* A quarter cylinder of radius k_cyl_r about the y axis (x = R cos t, z = R sin t, t in [0, 90°],
 * rational quadratic in u; y = -1 + 2 v, linear in v) with a round hole of radius k_hole_r about
 * (0.5, 0.5) in (u, v): a curved face whose trim edge's image is known by ray casting. */
static const double k_cyl_r = 2.0, k_hole_c[2] = {0.5, 0.5}, k_hole_r = 0.2;

static int build_cylinder(sw_sg_scene **out, sw_status *st)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return 0;
    static const double knots_u[6] = {0, 0, 0, 1, 1, 1}, knots_v[4] = {0, 0, 1, 1};
    const double w = sqrt(0.5),
                 arc[3][3] = {{k_cyl_r, 0, 1}, {k_cyl_r, k_cyl_r, w}, {0, k_cyl_r, 1}};
    double cpw[2 * 3 * 4];
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) {
            double *p = cpw + (j * 3 + i) * 4, wi = arc[i][2];
            p[0] = wi * arc[i][0];
            p[1] = wi * (j ? 1.0 : -1.0);
            p[2] = wi * arc[i][1];
            p[3] = wi;
        }
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = 2;
    f.deg_v = 1;
    f.n_u = 3;
    f.n_v = 2;
    f.knots_u = sw_sg_builder_push_doubles(b, knots_u, 6);
    f.knots_v = sw_sg_builder_push_doubles(b, knots_v, 4);
    f.cpw = sw_sg_builder_push_doubles(b, cpw, 24);
    static const double square[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    f.first_loop = add_polygon_loop(b, square, 4, SW_SG_LOOP_OUTER);
    add_circle_loop(b, k_hole_c, k_hole_r);
    f.n_loops = 2;
    f.kind = SW_SG_KIND_CYLINDER;
    f.flags = SW_SG_FACE_TRIMMED;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    f.tolerance = 1e-7;
    uint32_t face = sw_sg_builder_add_face(b, &f);
    static const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, white, "cylinder");
    return sw_sg_builder_finish(b, out, st) == SW_OK;
}

/* The cylinder's point at (u, v), and u of the angle t (bisection: the arc's angle grows with u).
 */
static void cyl_point(double u, double v, double p[3])
{
    const double w = sqrt(0.5), a = (1 - u) * (1 - u), m = 2 * u * (1 - u) * w, c = u * u;
    const double d = a + m + c;
    p[0] = (a * k_cyl_r + m * k_cyl_r) / d;
    p[1] = -1.0 + 2.0 * v;
    p[2] = (m * k_cyl_r + c * k_cyl_r) / d;
}

static double cyl_u_of_angle(double t)
{
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < 60; ++k) {
        double mid = 0.5 * (lo + hi), p[3];
        cyl_point(mid, 0.0, p);
        if (atan2(p[2], p[0]) < t)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

typedef struct cam_basis {
    double eye[3], fwd[3], right[3], up[3], tan_y;
} cam_basis;

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k)
        v[k] /= l;
}

static cam_basis basis_of(const sw_gpu_camera *c)
{
    cam_basis b;
    for (int k = 0; k < 3; ++k) {
        b.eye[k] = c->eye[k];
        b.fwd[k] = c->target[k] - c->eye[k];
    }
    normalize3(b.fwd);
    const double *u = c->up;
    b.right[0] = b.fwd[1] * u[2] - b.fwd[2] * u[1];
    b.right[1] = b.fwd[2] * u[0] - b.fwd[0] * u[2];
    b.right[2] = b.fwd[0] * u[1] - b.fwd[1] * u[0];
    normalize3(b.right);
    b.up[0] = b.right[1] * b.fwd[2] - b.right[2] * b.fwd[1];
    b.up[1] = b.right[2] * b.fwd[0] - b.right[0] * b.fwd[2];
    b.up[2] = b.right[0] * b.fwd[1] - b.right[1] * b.fwd[0];
    b.tan_y = tan(c->fovy_deg * M_PI / 360.0);
    return b;
}

/* Pixel position (x right, y down, pixel centres at +0.5) of an eye-relative point. */
static void pixel_of(const cam_basis *b, const double p[3], double out[2])
{
    double r[3] = {p[0] - b->eye[0], p[1] - b->eye[1], p[2] - b->eye[2]};
    double z = r[0] * b->fwd[0] + r[1] * b->fwd[1] + r[2] * b->fwd[2];
    double x = (r[0] * b->right[0] + r[1] * b->right[1] + r[2] * b->right[2]) / (z * b->tan_y);
    double y = (r[0] * b->up[0] + r[1] * b->up[1] + r[2] * b->up[2]) / (z * b->tan_y);
    out[0] = (x + 1.0) * (W / 2.0);
    out[1] = (1.0 - y) * (H / 2.0);
}

/* Where the pixel's ray meets the face (inside its (u, v) square; the hole ignored): 1 and its
 * (u, v), else 0. The nearer intersection with the cylinder comes first. */
static int cyl_hit(const cam_basis *b, int x, int y, double uv[2])
{
    double nx = (x + 0.5) / (W / 2.0) - 1.0, ny = 1.0 - (y + 0.5) / (H / 2.0), d[3];
    for (int k = 0; k < 3; ++k)
        d[k] = b->fwd[k] + nx * b->tan_y * b->right[k] + ny * b->tan_y * b->up[k];
    const double *o = b->eye;
    double qa = d[0] * d[0] + d[2] * d[2], qb = 2 * (o[0] * d[0] + o[2] * d[2]);
    double qc = o[0] * o[0] + o[2] * o[2] - k_cyl_r * k_cyl_r, disc = qb * qb - 4 * qa * qc;
    if (disc < 0)
        return 0;
    for (int s = -1; s <= 1; s += 2) {
        double t = (-qb + s * sqrt(disc)) / (2 * qa);
        double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        double ang = atan2(p[2], p[0]);
        if (t > 0 && ang >= 0 && ang <= M_PI / 2 && p[1] >= -1 && p[1] <= 1) {
            uv[0] = cyl_u_of_angle(ang);
            uv[1] = (p[1] + 1.0) / 2.0;
            return 1;
        }
    }
    return 0;
}

/* A pixel's distance to the hole's edge on screen: its (u, v) distance to the circle times the
 * screen length of a unit step across the circle there (by a difference of the exact surface). */
static double hole_distance_px(const cam_basis *b, const double uv[2], int *in_hole)
{
    double du = uv[0] - k_hole_c[0], dv = uv[1] - k_hole_c[1], rc = hypot(du, dv);
    *in_hole = rc < k_hole_r;
    double n[2] = {rc > 0 ? du / rc : 1.0, rc > 0 ? dv / rc : 0.0}, h = 1e-6, p0[3], p1[3], s0[2],
           s1[2];
    cyl_point(uv[0], uv[1], p0);
    cyl_point(uv[0] + h * n[0], uv[1] + h * n[1], p1);
    pixel_of(b, p0, s0);
    pixel_of(b, p1, s1);
    return fabs(rc - k_hole_r) * hypot(s1[0] - s0[0], s1[1] - s0[1]) / h;
}

/* The curved face: the hole filling the screen and its edge at 10x, by trim textures and exact
 * edges, fat borders off and on. A pixel is wrong when its coverage differs from the ray cast's
 * (the face hit, outside the hole); pixels within 1 px of the face's outer edges are left out.
 * Exact edges, borders off: within ε_img + 0.25 px (the surface itself is drawn within ε_img). */
static int check_cylinder(sw_gpu_context *ctx)
{
    sw_status st = {0};
    sw_sg_scene *scene = NULL;
    if (!build_cylinder(&scene, &st))
        return !fail("cylinder scene", &st);
    double hole[3];
    cyl_point(k_hole_c[0], k_hole_c[1], hole);
    const double out_dir[3] = {hole[0] / k_cyl_r, 0.0, hole[2] / k_cyl_r};
    const double dists[2] = {1.4, 0.14}; /* the hole across the screen; its edge at 10x */
    const double edge_u = k_hole_c[0] + k_hole_r, aim_v = 0.5;
    int ok = 1;
    printf("curved face (quarter cylinder, round hole; edge displacement as above):\n");
    for (int exact = 0; exact < 2; ++exact)
        for (int borders = 0; borders < 2; ++borders)
            for (int k = 0; k < 2; ++k) {
                double target[3];
                cyl_point(k ? edge_u : k_hole_c[0], aim_v, target);
                sw_gpu_camera cam = {{target[0] + dists[k] * out_dir[0], target[1],
                                      target[2] + dists[k] * out_dir[2]},
                                     {target[0], target[1], target[2]},
                                     {0, 1, 0},
                                     k_fovy};
                sw__gpu_set_crack_fill(ctx, borders);
                sw_gpu_frame_desc desc;
                memset(&desc, 0, sizeof desc);
                desc.width = W;
                desc.height = H;
                desc.trim_edges = exact;
                desc.camera = cam;
                sw_gpu_image img;
                sw_gpu_frame_stats fs;
                if (sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st) != SW_OK) {
                    sw_sg_scene_free(scene);
                    return !fail("cylinder render", &st);
                }
                const cam_basis b = basis_of(&cam);
                double worst = 0.0;
                long far_wrong = 0;
                for (int y = 0; y < H; ++y)
                    for (int x = 0; x < W; ++x) {
                        double uv[2];
                        int hit = cyl_hit(&b, x, y, uv), in_hole = 0;
                        if (!hit || fmin(fmin(uv[0], 1 - uv[0]), fmin(uv[1], 1 - uv[1])) < 0.01)
                            continue; /* off the face or near its outer edges: not the hole's */
                        double d = hole_distance_px(&b, uv, &in_hole);
                        int got = img.rgba[4 * ((size_t)y * W + (size_t)x) + 3] != 0;
                        if (got == in_hole) {
                            worst = fmax(worst, d);
                            far_wrong += d > 1.0 + 0.5;
                        }
                    }
                const double limit = exact && !borders ? 0.5 + 0.25 : INFINITY;
                printf("  %-8s borders %-3s %-22s: %5.3f px (%ld wrong beyond 1.5 px), %llu trim "
                       "textures, %llu exact\n",
                       exact ? "exact" : "texture", borders ? "on" : "off",
                       k ? "its edge at 10x" : "hole fills the screen", worst, far_wrong,
                       (unsigned long long)fs.trim_textures, (unsigned long long)fs.trim_exact);
                if (far_wrong != 0 || !(worst <= limit) || (exact && fs.trim_exact == 0)) {
                    printf("  FAIL: cylinder %s\n", exact ? "exact" : "texture");
                    ok = 0;
                }
                sw_gpu_image_free(&img);
            }
    sw__gpu_set_crack_fill(ctx, 1);
    sw_sg_scene_free(scene);
    return ok;
}

static int check_writes(const sw_gpu_image *img, const char *dir)
{
    char png[1024], exr[1024], bad[1024];
    snprintf(png, sizeof png, "%s/analytic.png", dir);
    snprintf(exr, sizeof exr, "%s/analytic.exr", dir);
    snprintf(bad, sizeof bad, "%s/analytic.bmpx", dir);
    sw_status st = {0};
    if (sw_gpu_image_write(img, png, &st) != SW_OK)
        return fail("png write", &st);
    if (sw_gpu_image_write(img, exr, &st) != SW_OK)
        return fail("exr write", &st);
    if (sw_gpu_image_write(img, bad, &st) != SW_ERR_UNSUPPORTED)
        return fail("unsupported extension accepted", &st);
    struct stat sb;
    if (stat(png, &sb) != 0 || sb.st_size < 100 || stat(exr, &sb) != 0 || sb.st_size < 100)
        return fail("image files missing", NULL);
    return 0;
}

int main(int argc, char **argv)
{
    (void)sw_image_install(); /* .exr frames */
    const char *dir = argc > 1 ? argv[1] : ".";
    sw_status st = {0};
    sw_sg_scene *scene = NULL;
    if (!build_scene(&scene, &st))
        return fail("scene build", &st);
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK)
        return fail("context", &st);
    printf("context: %s\n", sw_gpu_context_description_ptr(ctx));
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = W;
    desc.height = H;
    desc.want_depth = 1;
    desc.camera = (sw_gpu_camera){{0, 0, k_dist}, {0, 0, 0}, {0, 1, 0}, k_fovy};
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    if (sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st) != SW_OK)
        return fail("render", &st);
    printf("stats: faces %llu drawn / %llu culled, patches %llu trimmed / %llu untrimmed / %llu "
           "culled, %llu triangles, %llu trim textures (%llu texels); ms: tessellate %.2f trim "
           "%.2f draw %.2f readback %.2f\n",
           (unsigned long long)fs.faces_drawn, (unsigned long long)fs.faces_culled,
           (unsigned long long)fs.patches_trimmed, (unsigned long long)fs.patches_untrimmed,
           (unsigned long long)fs.patches_culled, (unsigned long long)fs.triangles,
           (unsigned long long)fs.trim_textures, (unsigned long long)fs.trim_texels,
           fs.ms_tessellate, fs.ms_trim, fs.ms_draw, fs.ms_readback);
    /* One trim texture for the face, or one per tile when its trim box needs more than
     * k_tile_texels (512) texels per direction: 4 x 4 tiles at most at this distance. */
    int ok = check_frame(&img) && fs.patches_trimmed == 4 && fs.trim_textures >= 1 &&
             fs.trim_textures <= 16;
    if (check_writes(&img, dir))
        ok = 0;
    if (!check_close_ups(ctx, scene))
        ok = 0;
    if (!check_cylinder(ctx))
        ok = 0;
    sw_gpu_image_free(&img);
    sw_gpu_context_free(ctx);
    sw_sg_scene_free(scene);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

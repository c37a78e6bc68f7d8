/* SPDX-License-Identifier: MIT */
/* tests/api: the immediate API (sw_immediate.h, Guthe et al. 2005 §8), against the shared library.
 *
 * usage: test_api_immediate WORKDIR   (EGL)
 *
 * scene: four draws of three objects — a bicubic plane with a square hole (twice: identity and
 *   a translation with another colour), a rational quarter cylinder (exact circle, weights
 *   1/sqrt 2) under a rotation, a bumpy bicubic patch trimmed by an octagon under a scale — drawn
 *   by sw_renderer_draw_nurbs must match sw_renderer_draw of a node scene holding the same
 *   surfaces as NURBS nodes under the same transforms and colours, same camera: at most 0.1 % of
 *   pixels differ at all. Moving one draw by 10 % of its size differs in more than 0.5 % (the
 *   check can fail). Drawn again with a matrix changed and then back: the renderer kept its
 *   scene (same image as the first). A zero camera fits the drawn objects. sw_nurbs_update of
 *   the plane to a tilted one changes the image as the node scene with the tilted plane does.
 * shading: a host sw_shade returning the fragment's uv as colour (Bézier and exact paths), on
 *   the plane S(u, v) = (10u, 10v, 0) seen from above: at sampled pixel centres the colour is
 *   (u, v) of the point the pixel's ray meets (analytic), within 3/255; pixels inside the hole
 *   are background (trimmed before shading). The normal as colour: (0.5, 0.5, 1) for the plane,
 *   (0.5, 0.5, 0) for the same plane with reversed = 1. A host uniform (glProgramUniform4f on the
 *   listed programs) times sw_shade_library: the library's colour scaled per channel. A host
 *   texture on unit 1 is what its shading samples, and stays bound (the active unit too).
 *   library_shading = 1 draws the library's image again, byte for byte.
 * misuse: NULL desc, no draws, NULL draws, a stale sw_nurbs in the list (nothing drawn), stale
 *   update and double destroy, NaN control point, decreasing knots, a degenerate trim loop (all
 *   SW_ERR_INVALID_GEOMETRY with nothing changed: the object draws as before), a singular model
 *   matrix, a negative colour, a draw while a prepared frame waits and calls from another
 *   thread (SW_ERR_INVALID_ARGUMENT), a shading source that does not compile
 *   (SW_ERR_INVALID_ARGUMENT, the shading before stays), the GLSL parts (every kind non-NULL,
 *   out of range NULL) and a host vertex stage built from them.
 * threads: another thread updates, creates and destroys objects while this one draws them.
 */
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <splinewalk/splinewalk.h>

#include "test_check.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "api_test_image.h"

static const char *g_work;

#define EXPECT_RESULT(call, want)                                                                  \
    do {                                                                                           \
        sw_result got_ = (call);                                                                   \
        CHECK(got_ == (want), "line %d: %s -> %s, expected %s", __LINE__, #call,                   \
              sw_result_id_str(got_), sw_result_id_str(want));                                     \
    } while (0)

enum { W = 320, H = 240 };

/* ---- geometry ---------------------------------------------------------------------------------
 */
static const double k_knots4[8] = {0, 0, 0, 0, 1, 1, 1, 1};
static const double k_knots3[6] = {0, 0, 0, 1, 1, 1};
static const double k_knots2[4] = {0, 0, 1, 1};
static const double k_poly_knots[7] = {0, 0, 1, 2, 3, 4, 4};
static const double k_outer_pts[10] = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0};
static const double k_hole_pts[10] = {0.4, 0.4, 0.4, 0.6, 0.6, 0.6, 0.6, 0.4, 0.4, 0.4};
static const double k_oct_knots[11] = {0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 8};
static double g_oct_pts[18];
static sw_trim_curve g_curves[3];
static sw_trim_loop g_loops[3];
static double g_plane[48], g_tilted[48], g_bumps[48], g_cyl[18], g_cyl_w[6];

/* The bicubic plane S(u, v) = (10u, 10v, tilt * 10u) (evenly spaced control points), trimmed by
 * the domain's boundary and the hole [0.4, 0.6]^2. */
static sw_nurbs_desc plane_desc(double *pts, double tilt)
{
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            pts[3 * (4 * j + i)] = 10.0 * i / 3.0;
            pts[3 * (4 * j + i) + 1] = 10.0 * j / 3.0;
            pts[3 * (4 * j + i) + 2] = tilt * 10.0 * i / 3.0;
        }
    }
    g_curves[0] = (sw_trim_curve){1, 5, k_poly_knots, k_outer_pts, NULL};
    g_curves[1] = (sw_trim_curve){1, 5, k_poly_knots, k_hole_pts, NULL};
    g_loops[0] = (sw_trim_loop){&g_curves[0], 1};
    g_loops[1] = (sw_trim_loop){&g_curves[1], 1};
    sw_nurbs_desc d = {3, 3, 4, 4, k_knots4, k_knots4, pts, NULL, g_loops, 2, 0};
    return d;
}

/* A quarter of the cylinder x^2 + y^2 = 9, 0 <= z <= 6: a rational quadratic arc in u (middle
 * weight 1/sqrt 2), linear in v; untrimmed. */
static sw_nurbs_desc cylinder_desc(void)
{
    const double arc[3][2] = {{3, 0}, {3, 3}, {0, 3}};
    for (int j = 0; j < 2; j++) {
        for (int i = 0; i < 3; i++) {
            g_cyl[3 * (3 * j + i)] = arc[i][0];
            g_cyl[3 * (3 * j + i) + 1] = arc[i][1];
            g_cyl[3 * (3 * j + i) + 2] = 6.0 * j;
            g_cyl_w[3 * j + i] = i == 1 ? sqrt(0.5) : 1.0;
        }
    }
    sw_nurbs_desc d = {2, 1, 3, 2, k_knots3, k_knots2, g_cyl, g_cyl_w, NULL, 0, 0};
    return d;
}

/* A bicubic patch with bumps, trimmed by an octagon inside its domain. */
static sw_nurbs_desc bumps_desc(void)
{
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            g_bumps[3 * (4 * j + i)] = 4.0 * i / 3.0;
            g_bumps[3 * (4 * j + i) + 1] = 4.0 * j / 3.0;
            g_bumps[3 * (4 * j + i) + 2] = ((i + j) % 2 ? 1.2 : -0.6);
        }
    }
    for (int k = 0; k < 9; k++) {
        double a = 2.0 * M_PI * (k % 8) / 8.0 + M_PI / 8.0;
        g_oct_pts[2 * k] = 0.5 + 0.45 * cos(a);
        g_oct_pts[2 * k + 1] = 0.5 + 0.45 * sin(a);
    }
    g_curves[2] = (sw_trim_curve){1, 9, k_oct_knots, g_oct_pts, NULL};
    g_loops[2] = (sw_trim_loop){&g_curves[2], 1};
    sw_nurbs_desc d = {3, 3, 4, 4, k_knots4, k_knots4, g_bumps, NULL, &g_loops[2], 1, 0};
    return d;
}

/* ---- the four draws ----------------------------------------------------------------------------
 */
static const double k_identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
static const double k_shift[12] = {1, 0, 0, 12, 0, 1, 0, 1, 0, 0, 1, 0};
static const double k_rot[12] = {0, -1, 0, -2, 1, 0, 0, 2, 0, 0, 1, 0}; /* 90° about z */
static const double k_scale[12] = {1.5, 0, 0, 4, 0, 1.5, 0, 12, 0, 0, 1.5, 1};
static const float k_colors[4][4] = {
    {0.8f, 0.3f, 0.2f, 1}, {0.2f, 0.6f, 0.8f, 1}, {0.3f, 0.8f, 0.3f, 1}, {0.9f, 0.8f, 0.2f, 1}};

static sw_camera scene_camera(void)
{
    sw_camera c = {{30, -25, 28}, {8, 6, 1}, {0, 0, 1}, 40};
    return c;
}

static void set_draw(sw_nurbs_draw *d, sw_nurbs n, const double m[12], const float c[4])
{
    memset(d, 0, sizeof *d);
    d->nurbs = n;
    memcpy(d->model, m, sizeof d->model);
    memcpy(d->color, c, sizeof d->color);
}

static void path_of(const char *name, char *path)
{
    snprintf(path, 1024, "%s/%s.png", g_work, name);
}

static int g_exact; /* draws evaluated by the exact path (eval_exact) */

static int draw_immediate(sw_renderer r, const sw_nurbs_draw *draws, uint32_t n,
                          const sw_camera *cam, const char *name, int library_shading)
{
    char path[1024];
    path_of(name, path);
    sw_immediate_desc d = {0};
    d.draws = draws;
    d.draw_count = n;
    d.camera = *cam;
    d.width = W;
    d.height = H;
    d.output_path = path;
    d.library_shading = library_shading;
    d.eval_exact = g_exact;
    sw_status st = {0};
    sw_result res = sw_renderer_draw_nurbs(r, &d, NULL, &st);
    CHECK(res == SW_OK, "immediate %s: %s", name, st.message);
    return res == SW_OK;
}

/* Percent of pixels whose colour differs at all. */
static double differ_percent(const char *name_a, const char *name_b)
{
    char a[1024], b[1024];
    path_of(name_a, a);
    path_of(name_b, b);
    int wa = 0, ha = 0, wb = 0, hb = 0;
    unsigned char *pa = sw_test_read_rgba(a, &wa, &ha), *pb = sw_test_read_rgba(b, &wb, &hb);
    double percent = 100.0;
    if (pa && pb && wa == wb && ha == hb && wa > 0) {
        size_t n = (size_t)wa * ha, differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += memcmp(pa + 4 * i, pb + 4 * i, 3) != 0;
        percent = 100.0 * (double)differ / (double)n;
    }
    free(pa);
    free(pb);
    return percent;
}

static unsigned char *read_image(const char *name)
{
    char path[1024];
    path_of(name, path);
    int w = 0, h = 0;
    unsigned char *p = sw_test_read_rgba(path, &w, &h);
    CHECK(p && w == W && h == H, "read %s", path);
    return p && w == W && h == H ? p : (free(p), NULL);
}

/* The reference: a node scene with one NURBS node per draw. */
static void draw_reference(sw_renderer r, const sw_nurbs_desc *const *descs, const double *const *m,
                           const float (*colors)[4], int n, const sw_camera *cam, const char *name)
{
    sw_scene s;
    sw_status st = {0};
    CHECK(sw_scene_create(NULL, &s, &st) == SW_OK, "scene_create: %s", st.message);
    for (int i = 0; i < n; i++) {
        sw_node_desc nd = {0};
        nd.kind = SW_NODE_NURBS;
        nd.nurbs = descs[i];
        memcpy(nd.transform, m[i], sizeof nd.transform);
        memcpy(nd.color, colors[i], sizeof nd.color);
        sw_node node;
        CHECK(sw_node_add(s, &nd, &node, &st) == SW_OK, "node_add %d: %s", i, st.message);
    }
    char path[1024];
    path_of(name, path);
    sw_frame_desc f = {.scene = s, .camera = *cam, .width = W, .height = H, .output_path = path};
    CHECK(sw_renderer_draw(r, &f, NULL, &st) == SW_OK, "reference %s: %s", name, st.message);
    sw_scene_destroy(s);
}

typedef struct objects {
    sw_nurbs plane, cyl, bumps;
    sw_nurbs_desc plane_d, cyl_d, bumps_d;
} objects;

static void make_objects(objects *o)
{
    o->plane_d = plane_desc(g_plane, 0.0);
    o->cyl_d = cylinder_desc();
    o->bumps_d = bumps_desc();
    sw_status st = {0};
    CHECK(sw_nurbs_create(&o->plane_d, &o->plane, &st) == SW_OK, "plane: %s", st.message);
    CHECK(sw_nurbs_create(&o->cyl_d, &o->cyl, &st) == SW_OK, "cylinder: %s", st.message);
    CHECK(sw_nurbs_create(&o->bumps_d, &o->bumps, &st) == SW_OK, "bumps: %s", st.message);
}

static void four_draws(const objects *o, sw_nurbs_draw d[4])
{
    set_draw(&d[0], o->plane, k_identity, k_colors[0]);
    set_draw(&d[1], o->plane, k_shift, k_colors[1]);
    set_draw(&d[2], o->cyl, k_rot, k_colors[2]);
    set_draw(&d[3], o->bumps, k_scale, k_colors[3]);
}

static void test_scene_match(sw_renderer r, objects *o)
{
    sw_camera cam = scene_camera();
    sw_nurbs_draw d[4];
    four_draws(o, d);
    const sw_nurbs_desc *descs[4] = {&o->plane_d, &o->plane_d, &o->cyl_d, &o->bumps_d};
    const double *m[4] = {k_identity, k_shift, k_rot, k_scale};
    draw_reference(r, descs, m, k_colors, 4, &cam, "ref");
    if (!draw_immediate(r, d, 4, &cam, "imm", 0))
        return;
    double same = differ_percent("imm", "ref");
    printf("immediate vs node scene: %.4f %% of pixels differ\n", same);
    CHECK(same <= 0.1, "immediate draw differs from the node scene in %.4f %% of pixels", same);

    /* control: one draw moved by 1 (10 % of the plane) */
    double moved[12];
    memcpy(moved, k_shift, sizeof moved);
    moved[3] += 1.0;
    sw_nurbs_draw dm[4];
    memcpy(dm, d, sizeof dm);
    memcpy(dm[1].model, moved, sizeof moved);
    draw_immediate(r, dm, 4, &cam, "imm_moved", 0);
    double control = differ_percent("imm_moved", "ref");
    printf("control (one draw moved by 10 %% of its size): %.4f %% differ\n", control);
    CHECK(control > 0.5, "a moved draw differs in only %.4f %% of pixels", control);
    /* back again: the renderer kept its scene; the image is the first one */
    draw_immediate(r, d, 4, &cam, "imm_again", 0);
    double again = differ_percent("imm_again", "imm");
    CHECK(again == 0.0, "the same draws again differ in %.4f %% of pixels", again);

    /* a zero camera: the iso preset fitted to the drawn objects, which then cover the frame's
     * middle (their box's centre is the target) */
    sw_camera zero = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, 0};
    if (draw_immediate(r, d, 4, &zero, "imm_fitted", 0)) {
        unsigned char *img = read_image("imm_fitted");
        size_t covered = 0;
        for (size_t i = 0; img && i < (size_t)W * H; i++)
            covered += img[4 * i] != 255 || img[4 * i + 1] != 255 || img[4 * i + 2] != 255;
        printf("fitted camera: %.1f %% of the frame covered\n", 100.0 * covered / (W * H));
        CHECK(covered > (size_t)W * H / 20, "fitted camera: %zu pixels covered", covered);
        free(img);
    }

    /* update: the plane becomes a tilted one, in both of its draws */
    sw_nurbs_desc tilted = plane_desc(g_tilted, 0.3);
    sw_status st = {0};
    CHECK(sw_nurbs_update(o->plane, &tilted, &st) == SW_OK, "update: %s", st.message);
    const sw_nurbs_desc *descs_t[4] = {&tilted, &tilted, &o->cyl_d, &o->bumps_d};
    draw_reference(r, descs_t, m, k_colors, 4, &cam, "ref_tilted");
    draw_immediate(r, d, 4, &cam, "imm_tilted", 0);
    double tilted_same = differ_percent("imm_tilted", "ref_tilted");
    double tilted_old = differ_percent("imm_tilted", "ref");
    printf("after sw_nurbs_update: %.4f %% differ from the tilted reference, %.4f %% from the "
           "flat one\n",
           tilted_same, tilted_old);
    CHECK(tilted_same <= 0.1, "updated draw differs from its reference in %.4f %%", tilted_same);
    CHECK(tilted_old > 0.5, "the update changed only %.4f %% of pixels", tilted_old);
    o->plane_d = plane_desc(g_plane, 0.0);
    CHECK(sw_nurbs_update(o->plane, &o->plane_d, &st) == SW_OK, "update back: %s", st.message);
}

/* ---- host shading -----------------------------------------------------------------------------
 */
static const char *const k_shade_uv =
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  return vec4(uv, 0.0, 1.0);\n"
    "}\n";
static const char *const k_shade_normal =
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  return vec4(0.5 * normal + 0.5, 1.0);\n"
    "}\n";
static const char *const k_shade_tint =
    "uniform vec4 host_tint;\n"
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  vec4 c = sw_shade_library(pos, normal, uv, color);\n"
    "  return vec4(c.rgb * host_tint.rgb, c.a);\n"
    "}\n";

static const char *const k_shade_texture =
    "layout(binding = 1) uniform sampler2D host_texture;\n"
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  return texture(host_texture, uv);\n"
    "}\n";

/* The plane seen straight from above: eye (5, 5, 20), 40° (square pixels). */
static sw_camera top_camera(void)
{
    sw_camera c = {{5, 5, 20}, {5, 5, 0}, {0, 1, 0}, 40};
    return c;
}

/* The (u, v) of the plane point at the centre of pixel (x, y) (rows top first). */
static void pixel_uv(int x, int y, double uv[2])
{
    double ty = tan(20.0 * M_PI / 180.0), tx = ty * W / H;
    double nx = (x + 0.5) / W * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / H * 2.0;
    uv[0] = (5.0 + 20.0 * nx * tx) / 10.0;
    uv[1] = (5.0 + 20.0 * ny * ty) / 10.0;
}

/* uv as colour on the plane, by the Bézier path or (g_exact) the exact one */
static void check_uv_image(sw_renderer r, const objects *o, const char *name)
{
    sw_camera cam = top_camera();
    sw_nurbs_draw d;
    set_draw(&d, o->plane, k_identity, k_colors[0]);
    if (!draw_immediate(r, &d, 1, &cam, name, 0))
        return;
    unsigned char *img = read_image(name);
    if (!img)
        return;
    int checked = 0, worst = 0, holes = 0, hole_bg = 0;
    for (int y = 4; y < H; y += 9) {
        for (int x = 4; x < W; x += 11) {
            double uv[2];
            pixel_uv(x, y, uv);
            const unsigned char *p = img + 4 * ((size_t)y * W + x);
            int in_hole = uv[0] > 0.41 && uv[0] < 0.59 && uv[1] > 0.41 && uv[1] < 0.59;
            int inside = uv[0] > 0.01 && uv[0] < 0.99 && uv[1] > 0.01 && uv[1] < 0.99;
            if (in_hole) {
                holes++;
                hole_bg += p[0] == 255 && p[1] == 255 && p[2] == 255;
            } else if (inside && !(uv[0] > 0.39 && uv[0] < 0.61 && uv[1] > 0.39 && uv[1] < 0.61)) {
                int du = abs((int)p[0] - (int)lround(255.0 * uv[0]));
                int dv = abs((int)p[1] - (int)lround(255.0 * uv[1]));
                worst = du > worst ? du : worst;
                worst = dv > worst ? dv : worst;
                checked++;
            }
        }
    }
    printf("uv shading (%s): %d pixels checked against the analytic (u, v), worst %d/255; %d "
           "of %d hole pixels background\n",
           g_exact ? "exact path" : "Bezier path", checked, worst, hole_bg, holes);
    CHECK(checked > 200 && worst <= 3, "uv as colour: worst %d/255 over %d pixels", worst, checked);
    CHECK(holes > 0 && hole_bg == holes, "hole: %d of %d pixels trimmed", hole_bg, holes);
    free(img);
}

static void test_uv_shading(sw_renderer r, const objects *o)
{
    sw_status st = {0};
    CHECK(sw_renderer_set_shading(r, k_shade_uv, &st) == SW_OK, "uv shading: %s", st.message);
    check_uv_image(r, o, "shade_uv");
    g_exact = 1;
    check_uv_image(r, o, "shade_uv_exact");
    g_exact = 0;
    sw_camera cam = top_camera();
    sw_nurbs_draw d;
    set_draw(&d, o->plane, k_identity, k_colors[0]);
    /* the library's shading on request, and again after NULL: byte for byte the same */
    draw_immediate(r, &d, 1, &cam, "shade_library_flag", 1);
    CHECK(sw_renderer_set_shading(r, NULL, &st) == SW_OK, "NULL shading: %s", st.message);
    draw_immediate(r, &d, 1, &cam, "shade_library", 0);
    CHECK(differ_percent("shade_library_flag", "shade_library") == 0.0,
          "library_shading = 1 is not the library's image");
    CHECK(differ_percent("shade_library", "shade_uv") > 30.0, "uv shading changed nothing");
}

static void center_pixel(const char *name, unsigned char out[3])
{
    unsigned char *img = read_image(name);
    /* (u, v) = (0.25, 0.25): inside the plane, outside the hole */
    int x = (int)(W * (0.5 + (2.5 - 5.0) / (20.0 * tan(20.0 * M_PI / 180.0) * W / H) / 2.0));
    int y = (int)(H * (0.5 - (2.5 - 5.0) / (20.0 * tan(20.0 * M_PI / 180.0)) / 2.0));
    memset(out, 0, 3);
    if (img)
        memcpy(out, img + 4 * ((size_t)y * W + x), 3);
    free(img);
}

static void test_normal_and_uniform(sw_renderer r, const objects *o)
{
    sw_status st = {0};
    sw_camera cam = top_camera();
    sw_nurbs_draw d;
    set_draw(&d, o->plane, k_identity, k_colors[0]);
    CHECK(sw_renderer_set_shading(r, k_shade_normal, &st) == SW_OK, "normal: %s", st.message);
    unsigned char up[3], down[3], lib[3], tinted[3];
    draw_immediate(r, &d, 1, &cam, "shade_normal", 0);
    center_pixel("shade_normal", up);
    sw_nurbs_desc rev = o->plane_d;
    rev.reversed = 1;
    sw_nurbs flipped;
    CHECK(sw_nurbs_create(&rev, &flipped, &st) == SW_OK, "reversed: %s", st.message);
    d.nurbs = flipped;
    draw_immediate(r, &d, 1, &cam, "shade_normal_reversed", 0);
    center_pixel("shade_normal_reversed", down);
    printf("normal as colour: front (%d, %d, %d), reversed (%d, %d, %d)\n", up[0], up[1], up[2],
           down[0], down[1], down[2]);
    CHECK(abs(up[0] - 128) <= 2 && abs(up[1] - 128) <= 2 && up[2] == 255,
          "plane normal (%d, %d, %d), expected (128, 128, 255)", up[0], up[1], up[2]);
    CHECK(abs(down[0] - 128) <= 2 && abs(down[1] - 128) <= 2 && down[2] <= 1,
          "reversed normal (%d, %d, %d), expected (128, 128, 0)", down[0], down[1], down[2]);
    EXPECT_RESULT(sw_nurbs_destroy(flipped), SW_OK);
    d.nurbs = o->plane;

    draw_immediate(r, &d, 1, &cam, "shade_lib_ref", 1);
    center_pixel("shade_lib_ref", lib);
    CHECK(sw_renderer_set_shading(r, k_shade_tint, &st) == SW_OK, "tint: %s", st.message);
    uint32_t progs[3] = {0, 0, 0};
    EXPECT_RESULT(sw_renderer_shading_programs(r, progs, NULL), SW_OK);
    CHECK(progs[0] && progs[1] && progs[2], "programs %u %u %u", progs[0], progs[1], progs[2]);
    for (int k = 0; k < 3; k++)
        glProgramUniform4f(progs[k], glGetUniformLocation(progs[k], "host_tint"), 1.0f, 0.5f, 0.0f,
                           1.0f);
    draw_immediate(r, &d, 1, &cam, "shade_tint", 0);
    center_pixel("shade_tint", tinted);
    printf("library colour (%d, %d, %d), host tint (1, 0.5, 0) -> (%d, %d, %d)\n", lib[0], lib[1],
           lib[2], tinted[0], tinted[1], tinted[2]);
    CHECK(tinted[0] == lib[0] && abs((int)tinted[1] - (int)lround(lib[1] * 0.5)) <= 1 &&
              tinted[2] == 0,
          "tinted (%d, %d, %d) from (%d, %d, %d)", tinted[0], tinted[1], tinted[2], lib[0], lib[1],
          lib[2]);
    /* a host texture on unit 1 (the host's unit active during the draw): sampled by the host's
     * shading, still bound afterwards, and the active unit given back */
    static const unsigned char k_texel[4] = {40, 200, 90, 255};
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, k_texel);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    CHECK(sw_renderer_set_shading(r, k_shade_texture, &st) == SW_OK, "texture: %s", st.message);
    EXPECT_RESULT(sw_renderer_shading_programs(r, progs, NULL), SW_OK);
    for (int k = 0; k < 3; k++)
        glProgramUniform1i(progs[k], glGetUniformLocation(progs[k], "host_texture"), 1);
    unsigned char sampled[3];
    draw_immediate(r, &d, 1, &cam, "shade_texture", 0);
    center_pixel("shade_texture", sampled);
    GLint active = 0, bound = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
    printf("host texture on unit 1: (%d, %d, %d); active unit after the draw %#x, bound %d\n",
           sampled[0], sampled[1], sampled[2], (unsigned)active, bound);
    CHECK(memcmp(sampled, k_texel, 3) == 0, "host texture sampled as (%d, %d, %d)", sampled[0],
          sampled[1], sampled[2]);
    CHECK(active == GL_TEXTURE1 && bound == (GLint)tex, "host texture state not kept");
    glActiveTexture(GL_TEXTURE0);
    glDeleteTextures(1, &tex);
    /* a source that does not compile: refused with its log, the shading before stays */
    EXPECT_RESULT(sw_renderer_set_shading(r, "vec4 sw_shade(float x) { return y; }", &st),
                  SW_ERR_INVALID_ARGUMENT);
    CHECK(strstr(st.message, "compile") || strstr(st.message, "link"), "message: %s", st.message);
    uint32_t after[3];
    EXPECT_RESULT(sw_renderer_shading_programs(r, after, NULL), SW_OK);
    CHECK(memcmp(after, progs, sizeof after) == 0, "a failed set_shading replaced the programs");
    CHECK(sw_renderer_set_shading(r, NULL, &st) == SW_OK, "reset: %s", st.message);
    EXPECT_RESULT(sw_renderer_shading_programs(r, after, NULL), SW_OK);
    CHECK(after[0] == 0 && after[1] == 0 && after[2] == 0, "programs after reset");
}

/* The exported parts make a host's own vertex stage: the library's Bézier evaluation shader
 * compiles and links with the library's fragment parts and a host sw_shade, as the host's
 * program. */
static void test_glsl_parts(void)
{
    for (int k = 0; k < SW_GLSL_KIND_COUNT; k++)
        CHECK(sw_glsl_source_ptr((sw_glsl_kind)k) != NULL, "GLSL kind %d is NULL", k);
    CHECK(sw_glsl_source_ptr(SW_GLSL_KIND_COUNT) == NULL, "out of range kind not NULL");
    CHECK(strstr(sw_glsl_source_ptr(SW_GLSL_FRAGMENT_LIBRARY), "sw_trim_inside"), "no trim lookup");
    const char *fs[4] = {sw_glsl_source_ptr(SW_GLSL_FRAGMENT_INTERFACE),
                         sw_glsl_source_ptr(SW_GLSL_FRAGMENT_LIBRARY), k_shade_uv,
                         sw_glsl_source_ptr(SW_GLSL_FRAGMENT_MAIN)};
    const char *vs = sw_glsl_source_ptr(SW_GLSL_VERTEX_BEZIER);
    GLuint v = glCreateShader(GL_VERTEX_SHADER), f = glCreateShader(GL_FRAGMENT_SHADER);
    glShaderSource(v, 1, &vs, NULL);
    glShaderSource(f, 4, fs, NULL);
    glCompileShader(v);
    glCompileShader(f);
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    CHECK(ok, "a host program from the exported parts does not link");
    glDeleteProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
}

/* ---- misuse -----------------------------------------------------------------------------------
 */
typedef struct thread_call {
    sw_renderer r;
    const sw_immediate_desc *desc;
    sw_result draw, shading;
} thread_call;

static void *other_thread(void *arg)
{
    thread_call *c = arg;
    c->draw = sw_renderer_draw_nurbs(c->r, c->desc, NULL, NULL);
    c->shading = sw_renderer_set_shading(c->r, k_shade_uv, NULL);
    return NULL;
}

static void test_misuse(sw_renderer r, objects *o)
{
    sw_status st = {0};
    sw_camera cam = top_camera();
    sw_nurbs_draw d;
    set_draw(&d, o->plane, k_identity, k_colors[0]);
    draw_immediate(r, &d, 1, &cam, "misuse_before", 0);
    sw_immediate_desc desc = {0};
    desc.draws = &d;
    desc.draw_count = 1;
    desc.camera = cam;
    desc.width = W;
    desc.height = H;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, NULL, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_immediate_desc none = desc;
    none.draw_count = 0;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &none, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    none = desc;
    none.draws = NULL;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &none, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_renderer stale_r = {0};
    EXPECT_RESULT(sw_renderer_draw_nurbs(stale_r, &desc, NULL, NULL), SW_ERR_STALE_HANDLE);

    /* create / update / destroy */
    sw_nurbs n = {99};
    EXPECT_RESULT(sw_nurbs_create(NULL, &n, NULL), SW_ERR_INVALID_ARGUMENT);
    CHECK(n.id == 0, "out not zeroed");
    EXPECT_RESULT(sw_nurbs_create(&o->plane_d, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    double nan_pts[48];
    sw_nurbs_desc bad = plane_desc(nan_pts, 0.0);
    nan_pts[3 * 5 + 2] = NAN;
    EXPECT_RESULT(sw_nurbs_create(&bad, &n, &st), SW_ERR_INVALID_GEOMETRY);
    printf("NaN control point: %s\n", st.message);
    EXPECT_RESULT(sw_nurbs_update(o->plane, &bad, NULL), SW_ERR_INVALID_GEOMETRY);
    double bad_pts[48];
    bad = plane_desc(bad_pts, 0.0);
    static const double k_decreasing[8] = {0, 0, 0, 0, 1, 0.5, 1, 1};
    bad.knots_u = k_decreasing;
    EXPECT_RESULT(sw_nurbs_create(&bad, &n, &st), SW_ERR_INVALID_GEOMETRY);
    printf("decreasing knots: %s\n", st.message);
    EXPECT_RESULT(sw_nurbs_update(o->plane, &bad, NULL), SW_ERR_INVALID_GEOMETRY);
    bad = plane_desc(bad_pts, 0.0);
    static const double k_flat_pts[10] = {0.2, 0.5, 0.8, 0.5, 0.6, 0.5, 0.4, 0.5, 0.2, 0.5};
    sw_trim_curve flat_curve = {1, 5, k_poly_knots, k_flat_pts, NULL};
    sw_trim_loop flat = {&flat_curve, 1};
    bad.loops = &flat;
    bad.loop_count = 1;
    EXPECT_RESULT(sw_nurbs_create(&bad, &n, &st), SW_ERR_INVALID_GEOMETRY);
    printf("degenerate loop: %s\n", st.message);
    EXPECT_RESULT(sw_nurbs_update(o->plane, &bad, NULL), SW_ERR_INVALID_GEOMETRY);
    EXPECT_RESULT(sw_nurbs_update(o->plane, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    /* nothing changed: the plane draws as before */
    draw_immediate(r, &d, 1, &cam, "misuse_after", 0);
    CHECK(differ_percent("misuse_before", "misuse_after") == 0.0,
          "failed updates changed the object");

    /* bad draws */
    sw_nurbs_draw bd = d;
    memset(bd.model, 0, sizeof bd.model);
    bd.model[0] = 1; /* singular */
    desc.draws = &bd;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &desc, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    bd = d;
    bd.color[1] = -1.0f;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &desc, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    bd = d;
    desc.error_px = -1.0;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &desc, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    desc.error_px = 0.0;

    /* a stale object among live ones: nothing drawn */
    sw_nurbs gone;
    CHECK(sw_nurbs_create(&o->cyl_d, &gone, &st) == SW_OK, "create: %s", st.message);
    EXPECT_RESULT(sw_nurbs_destroy(gone), SW_OK);
    EXPECT_RESULT(sw_nurbs_destroy(gone), SW_ERR_STALE_HANDLE);
    EXPECT_RESULT(sw_nurbs_update(gone, &o->cyl_d, NULL), SW_ERR_STALE_HANDLE);
    sw_nurbs_draw two[2];
    two[0] = d;
    set_draw(&two[1], gone, k_rot, k_colors[2]);
    desc.draws = two;
    desc.draw_count = 2;
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &desc, NULL, &st), SW_ERR_STALE_HANDLE);
    printf("stale object: %s\n", st.message);
    sw_nurbs never = {0};
    EXPECT_RESULT(sw_nurbs_destroy(never), SW_ERR_STALE_HANDLE);

    /* a prepared frame waits: refused before anything changes, then drawn as before */
    desc.draws = &d;
    desc.draw_count = 1;
    sw_scene ns;
    CHECK(sw_scene_create(NULL, &ns, &st) == SW_OK, "scene: %s", st.message);
    sw_node_desc nd = {0};
    nd.kind = SW_NODE_NURBS;
    nd.nurbs = &o->cyl_d;
    sw_node node;
    CHECK(sw_node_add(ns, &nd, &node, &st) == SW_OK, "node: %s", st.message);
    sw_frame_desc pf = {.scene = ns, .camera = cam, .width = W, .height = H};
    CHECK(sw_renderer_prepare(r, &pf, &st) == SW_OK, "prepare: %s", st.message);
    EXPECT_RESULT(sw_renderer_draw_nurbs(r, &desc, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    CHECK(sw_renderer_submit(r, NULL, &st) == SW_OK, "submit: %s", st.message);
    sw_scene_destroy(ns);
    draw_immediate(r, &d, 1, &cam, "misuse_after_prepare", 0);
    CHECK(differ_percent("misuse_before", "misuse_after_prepare") == 0.0,
          "a refused draw changed what the next one draws");

    /* another thread */
    thread_call c = {r, &desc, SW_OK, SW_OK};
    pthread_t t;
    pthread_create(&t, NULL, other_thread, &c);
    pthread_join(t, NULL);
    CHECK(c.draw == SW_ERR_INVALID_ARGUMENT, "draw from another thread: %s",
          sw_result_id_str(c.draw));
    CHECK(c.shading == SW_ERR_INVALID_ARGUMENT, "set_shading from another thread: %s",
          sw_result_id_str(c.shading));
    uint32_t progs[3] = {1, 1, 1};
    EXPECT_RESULT(sw_renderer_shading_programs(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_renderer_shading_programs(r, progs, NULL), SW_OK);
    CHECK(progs[0] == 0, "another thread's set_shading took effect");
}

/* Another thread updates, creates and destroys objects while this one draws them (walkthrough
 * frames): every call returns SW_OK, and the objects stay usable (run under TSan / ASan too). */
typedef struct editor {
    const objects *o;
    const sw_nurbs_desc *shapes[2];
    int edits, failures;
} editor;

static void *edit_objects(void *arg)
{
    editor *e = arg;
    for (int i = 0; i < 120; i++) {
        sw_nurbs scratch;
        e->failures += sw_nurbs_update(e->o->plane, e->shapes[i % 2], NULL) != SW_OK;
        e->failures += sw_nurbs_create(&e->o->cyl_d, &scratch, NULL) != SW_OK;
        e->failures += sw_nurbs_destroy(scratch) != SW_OK;
        e->edits++;
    }
    return NULL;
}

static void test_concurrent_edits(sw_renderer r, objects *o)
{
    sw_nurbs_desc tilted = plane_desc(g_tilted, 0.3);
    o->plane_d = plane_desc(g_plane, 0.0);
    editor e = {o, {&tilted, &o->plane_d}, 0, 0};
    sw_nurbs_draw d[4];
    four_draws(o, d);
    sw_immediate_desc desc = {0};
    desc.draws = d;
    desc.draw_count = 4;
    desc.camera = scene_camera();
    desc.width = W;
    desc.height = H;
    desc.walkthrough = 1;
    pthread_t t;
    pthread_create(&t, NULL, edit_objects, &e);
    int frames = 0, failed = 0;
    for (; frames < 20; frames++) {
        sw_status st = {0};
        if (sw_renderer_draw_nurbs(r, &desc, NULL, &st) != SW_OK) {
            failed++;
            printf("  concurrent frame %d: %s\n", frames, st.message);
        }
    }
    pthread_join(t, NULL);
    printf("concurrent edits: %d frames drawn while another thread made %d edits\n", frames,
           e.edits);
    CHECK(failed == 0 && e.failures == 0, "%d frames and %d edits failed", failed, e.failures);
    sw_status st = {0};
    CHECK(sw_nurbs_update(o->plane, &o->plane_d, &st) == SW_OK, "update: %s", st.message);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_api_immediate WORKDIR\n");
        return 2;
    }
    g_work = argv[1];
    sw_renderer r;
    sw_status st = {0};
    sw_renderer_desc rd = {.worker_threads = 2};
    if (sw_renderer_create(&rd, &r, &st) != SW_OK) {
        fprintf(stderr, "no renderer: %s\n", st.message);
        return 1;
    }
    objects o;
    make_objects(&o);
    test_scene_match(r, &o);
    test_uv_shading(r, &o);
    test_normal_and_uniform(r, &o);
    test_glsl_parts();
    test_misuse(r, &o);
    test_concurrent_edits(r, &o);
    EXPECT_RESULT(sw_nurbs_destroy(o.plane), SW_OK);
    EXPECT_RESULT(sw_nurbs_destroy(o.cyl), SW_OK);
    EXPECT_RESULT(sw_nurbs_destroy(o.bumps), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
    if (g_failures) {
        fprintf(stderr, "%d failures\n", g_failures);
        return 1;
    }
    printf("all immediate checks passed\n");
    return 0;
}

/* SPDX-License-Identifier: MIT */
/* tests/api: depth compositing of the renderer's surfaces with a host's own 3D drawing
 * (sw_frame_desc.present_depth, sw_camera_matrices, sw_frame_stats.view / proj / near_plane).
 *
 *   test_api_compose [SCENE]
 *
 * The test is the host: its own EGL context (surfaceless, 4.5 core) and framebuffer (RGBA8 and a
 * 24-bit depth buffer, not the renderer's 32F format), and a renderer drawing in that context
 * (use_current_context). The scene is analytic: a NURBS plane z = x / 2 over [-1, 1]^2 (green,
 * drawn through the immediate API), the host's red quad z = -x / 2 over [-1.6, 1.6] x [-0.5, 0.5]
 * crossing it along x = 0, a camera on the z axis. Every pixel's expected owner (surface, quad or
 * nothing) comes from intersecting its centre's ray with both planes; pixels whose neighbours'
 * rays disagree (edges, the crossing line) are skipped. Checked:
 *  - quad drawn before the present, with sw_camera_matrices and a fixed near plane: each pixel
 *    shows the nearer of the two, the background keeps the host's clear colour, and the host's
 *    depth buffer holds near / distance of the winner (0 where nothing is);
 *  - quad drawn after the present, with the matrices the frame's stats give back (near plane
 *    chosen by the renderer): the same picture;
 *  - present_depth off: today's copy, background included (the renderer's white), over the quad,
 *    and the host's depth buffer untouched bit for bit;
 *  - the host's state the depth pass could touch beyond what host_state.c saves (unit 1's texture
 *    and sampler, the active unit) and its depth function and program are left as they were;
 *  - the matrices: proj's entries against the formula, stats equal to sw_camera_matrices, bad
 *    arguments refused;
 *  - with SCENE, the scene paths (sw_renderer_draw, and prepare + submit): where the host's depth
 *    buffer stayed 0 its clear colour stayed, elsewhere a surface was written; both paths give the
 *    same host framebuffer, and stats matrices equal to sw_camera_matrices of their near plane. */
#include <splinewalk/splinewalk.h>

#define SW_API_TEST_HOST_CONTEXT
#include "api_test_expect.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 160, H = 120 };
static const double k_eye_z = 5.0, k_fovy = 40.0;

/* ---- the analytic scene ------------------------------------------------------------------------
 */
enum { NOTHING = 0, SURFACE = 1, QUAD = 2 };

/* Distance along the view axis (-z) to the plane z = k x hit by the ray of window point (wx, wy),
 * or 0 when the hit is outside the rectangle |x| <= hx, |y| <= hy. */
static double plane_hit(double wx, double wy, double k, double hx, double hy)
{
    double ty = tan(k_fovy * M_PI / 360.0), tx = ty * W / H;
    double a = (2.0 * wx / W - 1.0) * tx, b = (2.0 * wy / H - 1.0) * ty;
    double t = k_eye_z / (1.0 + k * a); /* eye + t (a, b, -1) on z = k x */
    return t > 0.0 && fabs(a * t) <= hx && fabs(b * t) <= hy ? t : 0.0;
}

static int owner_at(double wx, double wy, double *dist)
{
    double s = plane_hit(wx, wy, 0.5, 1.0, 1.0), q = plane_hit(wx, wy, -0.5, 1.6, 0.5);
    int o = s > 0.0 && (q == 0.0 || s < q) ? SURFACE : q > 0.0 ? QUAD : NOTHING;
    if (dist)
        *dist = o == SURFACE ? s : o == QUAD ? q : 0.0;
    return o;
}

/* The owner of pixel (x, y) (GL rows, bottom first), or -1 when a ray one pixel away disagrees. */
static int expected_owner(int x, int y, double *dist)
{
    double cx = x + 0.5, cy = y + 0.5;
    int o = owner_at(cx, cy, dist);
    static const double d[4][2] = {{-1.25, 0}, {1.25, 0}, {0, -1.25}, {0, 1.25}};
    for (int k = 0; k < 4; k++)
        if (owner_at(cx + d[k][0], cy + d[k][1], NULL) != o)
            return -1;
    return o;
}

/* 1 when the surface covers pixel (x, y) whatever the quad, 0 when not, -1 near its edge. */
static int surface_covers(int x, int y)
{
    static const double d[5][2] = {{0, 0}, {-1.25, 0}, {1.25, 0}, {0, -1.25}, {0, 1.25}};
    int in[5];
    for (int k = 0; k < 5; k++)
        in[k] = plane_hit(x + 0.5 + d[k][0], y + 0.5 + d[k][1], 0.5, 1.0, 1.0) > 0.0;
    for (int k = 1; k < 5; k++)
        if (in[k] != in[0])
            return -1;
    return in[0];
}

/* ---- the host -----------------------------------------------------------------------------------
 */
typedef struct host {
    GLuint fbo, rb[2], program, vao, vbo, unit1_tex, unit1_sampler;
    GLint loc_mvp;
} host;

static void make_host(host *h)
{
    glGenRenderbuffers(2, h->rb);
    glBindRenderbuffer(GL_RENDERBUFFER, h->rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindRenderbuffer(GL_RENDERBUFFER, h->rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, W, H);
    glGenFramebuffers(1, &h->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, h->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, h->rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, h->rb[1]);
    EXPECT(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);

    GLuint vs = sw_test_compile_shader(GL_VERTEX_SHADER,
                                       "#version 450 core\nlayout(location=0) in vec3 p;\n"
                                       "uniform mat4 u_mvp;\n"
                                       "void main() { gl_Position = u_mvp * vec4(p, 1); }\n");
    GLuint fs =
        sw_test_compile_shader(GL_FRAGMENT_SHADER, "#version 450 core\nout vec4 c;\n"
                                                   "void main() { c = vec4(1, 0, 0, 1); }\n");
    h->program = glCreateProgram();
    glAttachShader(h->program, vs);
    glAttachShader(h->program, fs);
    glLinkProgram(h->program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    h->loc_mvp = glGetUniformLocation(h->program, "u_mvp");

    const float quad[4][3] = {
        {-1.6f, -0.5f, 0.8f}, {1.6f, -0.5f, -0.8f}, {-1.6f, 0.5f, 0.8f}, {1.6f, 0.5f, -0.8f}};
    glGenVertexArrays(1, &h->vao);
    glBindVertexArray(h->vao);
    glGenBuffers(1, &h->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, h->vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, (void *)0);
    glEnableVertexAttribArray(0);

    /* state on texture unit 1 that the depth pass must give back */
    glGenTextures(1, &h->unit1_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, h->unit1_tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
    glGenSamplers(1, &h->unit1_sampler);
    glBindSampler(1, h->unit1_sampler);
    glActiveTexture(GL_TEXTURE2);
}

/* The host's frame set-up: the renderer's depth convention, its clear colour blue. */
static void host_begin(const host *h)
{
    glBindFramebuffer(GL_FRAMEBUFFER, h->fbo);
    glViewport(0, 0, W, H);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glClearColor(0.0f, 0.0f, 1.0f, 1.0f);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(h->program);
    glBindVertexArray(h->vao);
}

static void host_draw_quad(const host *h, const double view[16], const double proj[16])
{
    float mvp[16];
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += proj[k * 4 + r] * view[c * 4 + k];
            mvp[c * 4 + r] = (float)s;
        }
    glUseProgram(h->program);
    glBindVertexArray(h->vao);
    glUniformMatrix4fv(h->loc_mvp, 1, GL_FALSE, mvp);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

static void read_host(uint8_t *rgba, float *depth)
{
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    glReadPixels(0, 0, W, H, GL_DEPTH_COMPONENT, GL_FLOAT, depth);
}

/* ---- checks -------------------------------------------------------------------------------------
 */
enum { SEEN_SURFACE = 1, SEEN_QUAD = 2, SEEN_CLEAR = 3, SEEN_WHITE = 4, SEEN_OTHER = 0 };

static int seen(const uint8_t *p)
{
    if (p[1] > p[0] + 25 && p[1] > p[2] + 25)
        return SEEN_SURFACE; /* the green surface, however lit */
    if (p[0] == 255 && p[1] == 0 && p[2] == 0)
        return SEEN_QUAD;
    if (p[0] == 0 && p[1] == 0 && p[2] == 255)
        return SEEN_CLEAR;
    if (p[0] == 255 && p[1] == 255 && p[2] == 255)
        return SEEN_WHITE;
    return SEEN_OTHER;
}

/* Composited: every decided pixel shows its owner (nothing: the host's clear colour) and the
 * host's depth buffer holds near / distance of the owner (0 for nothing). */
static void check_composite(const char *what, const uint8_t *rgba, const float *depth,
                            double near_plane)
{
    int counts[3] = {0, 0, 0}, wrong = 0, wrong_depth = 0;
    double worst = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dist = 0.0;
            int o = expected_owner(x, y, &dist);
            if (o < 0)
                continue;
            counts[o]++;
            static const int want[3] = {SEEN_CLEAR, SEEN_SURFACE, SEEN_QUAD};
            size_t i = (size_t)y * W + (size_t)x;
            if (seen(rgba + 4 * i) != want[o]) {
                if (wrong++ < 5)
                    fprintf(stderr, "%s: pixel (%d, %d) owner %d shows %u %u %u\n", what, x, y, o,
                            rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]);
            }
            double expect = o == NOTHING ? 0.0 : near_plane / dist;
            double err = fabs(depth[i] - expect);
            worst = fmax(worst, err);
            if (err > 1e-5 + 1e-4 * expect)
                wrong_depth++;
        }
    printf("%s: %d surface, %d quad, %d background pixels decided; %d wrong colours, %d wrong "
           "depths (worst %.3g)\n",
           what, counts[SURFACE], counts[QUAD], counts[NOTHING], wrong, wrong_depth, worst);
    EXPECT(counts[SURFACE] > 1000 && counts[QUAD] > 1000 && counts[NOTHING] > 1000);
    EXPECT(wrong == 0);
    EXPECT(wrong_depth == 0);
}

/* ---- the renderer -------------------------------------------------------------------------------
 */
static const double k_knots2[4] = {0, 0, 1, 1};

static sw_camera camera(void)
{
    sw_camera c = {{0, 0, k_eye_z}, {0, 0, 0}, {0, 1, 0}, k_fovy};
    return c;
}

static sw_result draw_surface(sw_renderer r, sw_nurbs plane, int present_depth, double near_plane,
                              sw_frame_stats *stats)
{
    sw_nurbs_draw d = {plane, {0}, {0.1f, 0.9f, 0.1f, 1.0f}};
    sw_immediate_desc desc = {0};
    desc.draws = &d;
    desc.draw_count = 1;
    desc.camera = camera();
    desc.width = W;
    desc.height = H;
    desc.present = 1;
    desc.present_depth = present_depth;
    desc.near_plane = near_plane;
    sw_status st = {0};
    sw_result res = sw_renderer_draw_nurbs(r, &desc, stats, &st);
    if (res != SW_OK)
        fprintf(stderr, "draw: %s\n", st.message);
    return res;
}

/* The host's state the call must give back, beyond host_state.c's list: unit 1, the active unit. */
static void check_host_state(const host *h)
{
    GLint v = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &v);
    EXPECT(v == GL_TEXTURE2);
    glActiveTexture(GL_TEXTURE1);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &v);
    EXPECT(v == (GLint)h->unit1_tex);
    glGetIntegerv(GL_SAMPLER_BINDING, &v);
    EXPECT(v == (GLint)h->unit1_sampler);
    glActiveTexture(GL_TEXTURE2);
    glGetIntegerv(GL_DEPTH_FUNC, &v);
    EXPECT(v == GL_GREATER);
    glGetIntegerv(GL_CURRENT_PROGRAM, &v);
    EXPECT(v == (GLint)h->program);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &v);
    EXPECT(v == (GLint)h->fbo);
    EXPECT(glGetError() == GL_NO_ERROR);
}

static void check_matrices(void)
{
    sw_camera c = camera();
    double view[16], proj[16];
    sw_status st = {0};
    EXPECT(sw_camera_matrices(&c, W, H, 0.75, view, proj, &st) == SW_OK);
    double fy = 1.0 / tan(k_fovy * M_PI / 360.0), fx = fy * H / W;
    EXPECT(fabs(proj[0] - fx) < 1e-12 && fabs(proj[5] - fy) < 1e-12);
    EXPECT(proj[11] == -1.0 && proj[14] == 0.75 && proj[10] == 0.0 && proj[15] == 0.0);
    /* a camera on +z looking at the origin, up +y: view is the translation by -eye */
    static const double k_view[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -5, 1};
    for (int i = 0; i < 16; i++)
        EXPECT(fabs(view[i] - k_view[i]) < 1e-12);
    sw_camera zero = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, 0};
    EXPECT(sw_camera_matrices(&zero, W, H, 1.0, view, proj, &st) == SW_ERR_INVALID_ARGUMENT);
    EXPECT(sw_camera_matrices(&c, W, H, 0.0, view, proj, &st) == SW_ERR_INVALID_ARGUMENT);
    EXPECT(sw_camera_matrices(&c, W, H, NAN, view, proj, &st) == SW_ERR_INVALID_ARGUMENT);
    EXPECT(sw_camera_matrices(&c, -1, H, 1.0, view, proj, &st) == SW_ERR_INVALID_ARGUMENT);
    sw_camera flat = c;
    flat.up[1] = 0.0;
    flat.up[2] = 1.0; /* parallel to the view */
    EXPECT(sw_camera_matrices(&flat, W, H, 1.0, view, proj, &st) == SW_ERR_INVALID_ARGUMENT);
}

/* A scene frame composited into the host's cleared framebuffer, drawn (split = 0) or prepared
 * and submitted (1); returns the surface pixels, -1 on failure. */
static long scene_composite(sw_renderer r, const sw_frame_desc *desc, int split, const host *h,
                            uint8_t *rgba, float *depth)
{
    host_begin(h);
    sw_frame_stats stats;
    sw_status st = {0};
    sw_result res =
        split ? sw_renderer_prepare(r, desc, &st) : sw_renderer_draw(r, desc, &stats, &st);
    if (res == SW_OK && split)
        res = sw_renderer_submit(r, &stats, &st);
    if (res != SW_OK) {
        fprintf(stderr, "scene frame: %s\n", st.message);
        return -1;
    }
    double view[16], proj[16];
    EXPECT(sw_camera_matrices(&desc->camera, W, H, stats.near_plane, view, proj, &st) == SW_OK);
    EXPECT(memcmp(stats.view, view, sizeof view) == 0 &&
           memcmp(stats.proj, proj, sizeof proj) == 0);
    read_host(rgba, depth);
    long surface = 0, wrong = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        int clear = seen(rgba + 4 * i) == SEEN_CLEAR;
        surface += depth[i] > 0.0f;
        wrong += (depth[i] > 0.0f) == clear;
    }
    printf("scene %s: %ld surface pixels (near plane %g), %ld pixels whose colour disagrees with "
           "the depth written\n",
           split ? "prepare + submit" : "draw", surface, stats.near_plane, wrong);
    EXPECT(surface > 100 && surface < (long)W * H - 100 && wrong == 0);
    return surface;
}

static void check_scene(sw_renderer r, const char *path, const host *h)
{
    sw_scene scene;
    sw_scene_load_desc load = {.path = path};
    sw_status st = {0};
    if (sw_scene_load(&load, &scene, &st) != SW_OK) {
        fprintf(stderr, "%s: %s\n", path, st.message);
        g_failures++;
        return;
    }
    sw_frame_desc desc = {0};
    desc.scene = scene;
    EXPECT(sw_camera_fit(scene, SW_VIEW_ISO, &desc.camera, &st) == SW_OK);
    desc.width = W;
    desc.height = H;
    desc.present = 1;
    desc.present_depth = 1;
    size_t n = (size_t)W * H;
    uint8_t *rgba[2] = {malloc(n * 4), malloc(n * 4)};
    float *depth[2] = {malloc(n * sizeof(float)), malloc(n * sizeof(float))};
    desc.near_plane = -1.0;
    EXPECT(sw_renderer_draw(r, &desc, NULL, &st) == SW_ERR_INVALID_ARGUMENT);
    desc.near_plane = 0.0;
    long drawn = scene_composite(r, &desc, 0, h, rgba[0], depth[0]);
    long split = scene_composite(r, &desc, 1, h, rgba[1], depth[1]);
    EXPECT(drawn > 0 && split == drawn);
    EXPECT(memcmp(rgba[0], rgba[1], n * 4) == 0 && memcmp(depth[0], depth[1], n * 4) == 0);
    for (int k = 0; k < 2; k++) {
        free(rgba[k]);
        free(depth[k]);
    }
    EXPECT(sw_scene_destroy(scene) == SW_OK);
}

int main(int argc, char **argv)
{
    if (sw_test_host_context() != 0) {
        fprintf(stderr, "no EGL 4.5 core context\n");
        return 1;
    }
    check_matrices();
    host h;
    make_host(&h);
    sw_renderer_desc rd = {0};
    rd.use_current_context = 1;
    sw_renderer r;
    sw_status st = {0};
    if (sw_renderer_create(&rd, &r, &st) != SW_OK) {
        fprintf(stderr, "renderer: %s\n", st.message);
        return 1;
    }
    double pts[12];
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            double *p = pts + 3 * (2 * j + i);
            p[0] = -1.0 + 2.0 * i;
            p[1] = -1.0 + 2.0 * j;
            p[2] = 0.5 * p[0];
        }
    sw_nurbs_desc nd = {1, 1, 2, 2, k_knots2, k_knots2, pts, NULL, NULL, 0, 0};
    sw_nurbs plane;
    if (sw_nurbs_create(&nd, &plane, &st) != SW_OK) {
        fprintf(stderr, "plane: %s\n", st.message);
        return 1;
    }
    uint8_t *rgba = malloc((size_t)W * H * 4);
    float *depth = malloc((size_t)W * H * sizeof *depth), *before = malloc((size_t)W * H * 4);
    sw_camera cam = camera();
    double view[16], proj[16];
    sw_frame_stats stats;

    /* 1. the quad first, with matrices known before the frame (near plane fixed) */
    const double near_fixed = 1.0;
    EXPECT(sw_camera_matrices(&cam, W, H, near_fixed, view, proj, &st) == SW_OK);
    host_begin(&h);
    host_draw_quad(&h, view, proj);
    EXPECT(draw_surface(r, plane, 1, near_fixed, &stats) == SW_OK);
    check_host_state(&h);
    EXPECT(stats.near_plane == near_fixed);
    EXPECT(memcmp(stats.view, view, sizeof view) == 0 &&
           memcmp(stats.proj, proj, sizeof proj) == 0);
    read_host(rgba, depth);
    check_composite("quad before", rgba, depth, near_fixed);

    /* 2. the frame first (its own near plane), the quad after with the stats' matrices */
    host_begin(&h);
    EXPECT(draw_surface(r, plane, 1, 0.0, &stats) == SW_OK);
    check_host_state(&h);
    printf("near plane chosen for the frame: %g\n", stats.near_plane);
    EXPECT(stats.near_plane > 0.0 && stats.near_plane < k_eye_z - 0.5);
    EXPECT(sw_camera_matrices(&cam, W, H, stats.near_plane, view, proj, &st) == SW_OK);
    EXPECT(memcmp(stats.view, view, sizeof view) == 0 &&
           memcmp(stats.proj, proj, sizeof proj) == 0);
    host_draw_quad(&h, stats.view, stats.proj);
    read_host(rgba, depth);
    check_composite("quad after", rgba, depth, stats.near_plane);

    /* 3. present_depth off: today's copy of the whole image over the host's drawing */
    EXPECT(sw_camera_matrices(&cam, W, H, near_fixed, view, proj, &st) == SW_OK);
    host_begin(&h);
    host_draw_quad(&h, view, proj);
    read_host(rgba, before);
    EXPECT(draw_surface(r, plane, 0, near_fixed, &stats) == SW_OK);
    check_host_state(&h);
    read_host(rgba, depth);
    EXPECT(memcmp(before, depth, (size_t)W * H * sizeof *depth) == 0);
    int wrong = 0, n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int covered = surface_covers(x, y);
            if (covered < 0)
                continue;
            n++;
            wrong += seen(rgba + 4 * ((size_t)y * W + (size_t)x)) !=
                     (covered ? SEEN_SURFACE : SEEN_WHITE);
        }
    printf("present without depth: %d pixels decided, %d not the renderer's\n", n, wrong);
    EXPECT(n > 3000 && wrong == 0);

    if (argc > 1)
        check_scene(r, argv[1], &h);
    check_host_state(&h);

    sw_nurbs_destroy(plane);
    EXPECT(sw_renderer_destroy(r) == SW_OK);
    free(rgba);
    free(depth);
    free(before);
    if (g_failures)
        fprintf(stderr, "%d failures\n", g_failures);
    return g_failures ? 1 : 0;
}

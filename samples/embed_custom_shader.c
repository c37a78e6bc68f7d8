/* SPDX-License-Identifier: MIT */
/* embed_custom_shader: a host that owns its GL context (EGL, headless) and framebuffer, and draws
 * trimmed NURBS objects through the immediate API (sw_immediate.h, Guthe et al. 2005 §8) with
 * its own shading function: stripes along the surface parameter u, lit by the library's shading,
 * their count a uniform the host sets. The library evaluates the surfaces on the GPU and trims
 * them by trim textures; the host's sw_shade only colours what is left. The frame is composited
 * by depth into the host's framebuffer (present_depth), and the host then draws a floor of its
 * own through the surfaces with the matrices the frame used (sw_frame_stats.view / proj).
 *
 * usage: embed_custom_shader [OUT.png]   (default custom_shader.png; exit 0 on success)
 * build: cc embed_custom_shader.c $(pkg-config --cflags --libs splinewalk egl opengl) -lm
 */
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <splinewalk/splinewalk.h>

#include <math.h>
#include <stdio.h>

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "embed_custom_shader: %s: %s\n", what, st ? st->message : "failed");
    return 1;
}

/* The host's shading: stripes in u (host_stripes of them over the knot domain [0, 1]) over the
 * library's headlight shading of the object's colour. */
static const char *const k_shade =
    "uniform float host_stripes;\n"
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  float stripe = step(0.5, fract(uv.x * host_stripes));\n"
    "  vec4 base = mix(color, vec4(1.0, 1.0, 1.0, 1.0), 0.6 * stripe);\n"
    "  return sw_shade_library(pos, normal, uv, base);\n"
    "}\n";

/* The host's floor z = 0.6, a checkerboard of greys, cutting through the sheets and the cylinder;
 * drawn with the renderer's depth convention (zero-to-one clip depth, GL_GREATER). */
static GLuint floor_program(void)
{
    const char *vs = "#version 430 core\nlayout(location = 0) in vec2 xy;\nuniform mat4 mvp;\n"
                     "out vec2 p;\nvoid main() { p = xy; gl_Position = mvp * vec4(xy, 0.6, 1); }\n";
    const char *fs =
        "#version 430 core\nin vec2 p;\nout vec4 c;\nvoid main() {\n"
        "  c = vec4(vec3(0.5 + 0.15 * mod(floor(p.x / 2.0) + floor(p.y / 2.0), 2.0)), 1);\n}\n";
    const char *src[2] = {vs, fs};
    GLuint prog = glCreateProgram();
    for (int k = 0; k < 2; k++) {
        GLuint sh = glCreateShader(k ? GL_FRAGMENT_SHADER : GL_VERTEX_SHADER);
        glShaderSource(sh, 1, &src[k], NULL);
        glCompileShader(sh);
        glAttachShader(prog, sh);
        glDeleteShader(sh);
    }
    glLinkProgram(prog);
    return prog;
}

/* A headless OpenGL 4.5 core context of the host's own, current on this thread. */
static int host_context(void)
{
    EGLDisplay dpy =
        eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL)) {
        dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL))
            return 0;
    }
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    const EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            4,
                            EGL_CONTEXT_MINOR_VERSION,
                            5,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
    EGLConfig cfg = EGL_NO_CONFIG_KHR; /* surfaceless Mesa offers no configs: none is needed */
    EGLint n = 0;
    if (!eglBindAPI(EGL_OPENGL_API))
        return 0;
    if (!eglChooseConfig(dpy, want, &cfg, 1, &n) || n < 1)
        cfg = EGL_NO_CONFIG_KHR;
    EGLContext ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, attrs);
    return ctx != EGL_NO_CONTEXT && eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx);
}

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "custom_shader.png";
    enum { W = 800, H = 600 };
    if (!host_context())
        return fail("no OpenGL 4.5 core context through EGL", NULL);
    /* the host's framebuffer, colour and depth: the frame is composited into it */
    GLuint fbo, rb[2];
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(2, rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, W, H);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    glViewport(0, 0, W, H);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE); /* the renderer's depth convention */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glClearDepth(0.0);
    glClearColor(0.75f, 0.85f, 1.0f, 1.0f); /* the host's sky shows where no surface is */
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    sw_status st = {0};
    sw_renderer renderer;
    sw_renderer_desc rd = {.use_current_context = 1};
    if (sw_renderer_create(&rd, &renderer, &st) != SW_OK)
        return fail("renderer", &st);

    /* a bicubic sheet S(u, v) = (8u, 8v, bump) with a circular hole: the circle as a rational
     * quadratic loop of four arcs (weights 1, 1/sqrt 2, 1, ...) */
    static const double knots4[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    double sheet[48];
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            sheet[3 * (4 * j + i)] = 8.0 * i / 3.0;
            sheet[3 * (4 * j + i) + 1] = 8.0 * j / 3.0;
            sheet[3 * (4 * j + i) + 2] = (i == 1 || i == 2) && (j == 1 || j == 2) ? 2.0 : 0.0;
        }
    }
    static const double circle_knots[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    double circle[18], circle_w[9];
    for (int k = 0; k < 9; k++) {
        static const double dx[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
        static const double dy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
        circle[2 * k] = 0.5 + 0.2 * dx[k];
        circle[2 * k + 1] = 0.5 + 0.2 * dy[k];
        circle_w[k] = k % 2 ? sqrt(0.5) : 1.0;
    }
    static const double square_knots[7] = {0, 0, 1, 2, 3, 4, 4};
    static const double square[10] = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0};
    sw_trim_curve curves[2] = {{1, 5, square_knots, square, NULL},
                               {2, 9, circle_knots, circle, circle_w}};
    sw_trim_loop loops[2] = {{&curves[0], 1}, {&curves[1], 1}};
    sw_nurbs_desc sheet_d = {3, 3, 4, 4, knots4, knots4, sheet, NULL, loops, 2, 0};
    /* a quarter cylinder of radius 3, height 5: a rational quadratic arc swept in v */
    static const double knots3[6] = {0, 0, 0, 1, 1, 1}, knots2[4] = {0, 0, 1, 1};
    static const double cyl[18] = {3, 0, 0, 3, 3, 0, 0, 3, 0, 3, 0, 5, 3, 3, 5, 0, 3, 5};
    const double cyl_w[6] = {1, sqrt(0.5), 1, 1, sqrt(0.5), 1};
    sw_nurbs_desc cyl_d = {2, 1, 3, 2, knots3, knots2, cyl, cyl_w, NULL, 0, 0};
    sw_nurbs sheet_obj, cyl_obj;
    if (sw_nurbs_create(&sheet_d, &sheet_obj, &st) != SW_OK)
        return fail("sheet", &st);
    if (sw_nurbs_create(&cyl_d, &cyl_obj, &st) != SW_OK)
        return fail("cylinder", &st);

    if (sw_renderer_set_shading(renderer, k_shade, &st) != SW_OK)
        return fail("shading", &st);
    uint32_t programs[3];
    if (sw_renderer_shading_programs(renderer, programs, &st) != SW_OK)
        return fail("shading programs", &st);
    for (int k = 0; k < 3; k++)
        glProgramUniform1f(programs[k], glGetUniformLocation(programs[k], "host_stripes"), 12.0f);

    /* the sheet twice (the second turned and lifted), the cylinder behind them facing the eye */
    sw_nurbs_draw draws[3] = {
        {sheet_obj, {0}, {0.85f, 0.35f, 0.2f, 1.0f}},
        {sheet_obj, {0, -1, 0, 18, 1, 0, 0, 0, 0, 0, 1, 1}, {0.2f, 0.5f, 0.85f, 1.0f}},
        {cyl_obj, {0, 1, 0, 2, -1, 0, 0, 14, 0, 0, 1, 0}, {0.3f, 0.75f, 0.3f, 1.0f}},
    };
    sw_immediate_desc frame = {0};
    frame.draws = draws;
    frame.draw_count = 3;
    frame.camera = (sw_camera){{24, -16, 20}, {9, 5, 1}, {0, 0, 1}, 40};
    frame.width = W;
    frame.height = H;
    frame.error_px = 0.5;
    frame.present = 1;       /* into the host's framebuffer, bound above, */
    frame.present_depth = 1; /* by depth: the sky stays, the floor below can cut through */
    frame.output_path = out; /* and the renderer's own frame as a PNG */
    sw_frame_stats stats;
    if (sw_renderer_draw_nurbs(renderer, &frame, &stats, &st) != SW_OK)
        return fail("draw", &st);

    /* the floor, with the frame's matrices: mvp = proj x view (column-major) */
    float mvp[16];
    for (int k = 0; k < 16; k++) {
        double sum = 0.0;
        for (int m = 0; m < 4; m++)
            sum += stats.proj[m * 4 + k % 4] * stats.view[k / 4 * 4 + m];
        mvp[k] = (float)sum;
    }
    static const float quad[8] = {-10, -10, 30, -10, -10, 30, 30, 30};
    GLuint vao, vbo, prog = floor_program();
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
    glEnableVertexAttribArray(0);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "mvp"), 1, GL_FALSE, mvp);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);

    /* the host's framebuffer: count the surfaces' pixels (neither sky nor the floor's greys) */
    static unsigned char pixels[W * H * 4];
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
    long covered = 0;
    for (long i = 0; i < (long)W * H; i++) {
        const unsigned char *px = pixels + 4 * i;
        covered += px[2] != 255 && (px[0] != px[1] || px[1] != px[2]);
    }
    printf("%s: %llu triangles, %llu trim textures, %.1f ms; %.1f %% of the host's framebuffer "
           "covered\n",
           out, (unsigned long long)stats.triangles, (unsigned long long)stats.trim_textures,
           stats.ms_total, 100.0 * (double)covered / ((double)W * H));

    sw_nurbs_destroy(sheet_obj);
    sw_nurbs_destroy(cyl_obj);
    sw_renderer_destroy(renderer);
    glDeleteProgram(prog);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteRenderbuffers(2, rb);
    glDeleteFramebuffers(1, &fbo);
    return covered > (long)W * H / 100 ? 0 : fail("nothing presented into the framebuffer", NULL);
}

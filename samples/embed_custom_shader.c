/* embed_custom_shader: a host that owns its GL context (EGL, headless) and framebuffer, and draws
 * trimmed NURBS objects through the immediate API (sw_immediate.h, Guthe et al. 2005 §8) with
 * its own shading function: stripes along the surface parameter u, lit by the library's shading,
 * their count a uniform the host sets. The library evaluates the surfaces on the GPU and trims
 * them by trim textures; the host's sw_shade only colours what is left.
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
    /* the host's framebuffer: the frame is presented into it */
    GLuint fbo, color;
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &color);
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);

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
    frame.present = 1;       /* into the host's framebuffer, bound above */
    frame.output_path = out; /* and the same frame as a PNG */
    sw_frame_stats stats;
    if (sw_renderer_draw_nurbs(renderer, &frame, &stats, &st) != SW_OK)
        return fail("draw", &st);

    /* the host's framebuffer holds the frame: count what is not background */
    static unsigned char pixels[W * H * 4];
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
    long covered = 0;
    for (long i = 0; i < (long)W * H; i++)
        covered += pixels[4 * i] != 255 || pixels[4 * i + 1] != 255 || pixels[4 * i + 2] != 255;
    printf("%s: %llu triangles, %llu trim textures, %.1f ms; %.1f %% of the host's framebuffer "
           "covered\n",
           out, (unsigned long long)stats.triangles, (unsigned long long)stats.trim_textures,
           stats.ms_total, 100.0 * (double)covered / ((double)W * H));

    sw_nurbs_destroy(sheet_obj);
    sw_nurbs_destroy(cyl_obj);
    sw_renderer_destroy(renderer);
    glDeleteRenderbuffers(1, &color);
    glDeleteFramebuffers(1, &fbo);
    return covered > (long)W * H / 100 ? 0 : fail("nothing presented into the framebuffer", NULL);
}

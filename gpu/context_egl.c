/* SPDX-License-Identifier: MIT */
/* Headless OpenGL context through EGL (PLATFORM.md, "OpenGL without a GPU"): Mesa's surfaceless
 * platform first, then the EGL device platform (headless NVIDIA), then the default display; a
 * desktop GL 4.5 core context (4.3 accepted when glClipControl exists), no surface, rendering
 * into an FBO with RGBA8 colour and 32-bit float depth for reversed-Z.
 */
#include "sw_curves.h"
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_th_pool.h"
#include "sw_status_util.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The process's display is initialised once and never terminated: eglTerminate would end it for
 * every context of the process (several threads may own contexts), and it unloads Mesa's driver,
 * whose exit-time allocations LeakSanitizer could then no longer attribute to it. */
static pthread_mutex_t g_display_lock = PTHREAD_MUTEX_INITIALIZER;
static EGLDisplay g_display = EGL_NO_DISPLAY;
static char g_display_platform[64];

void sw__gpu_waits_since(const sw_th_wait_count *since, sw_gpu_frame_stats *st)
{
    const sw_th_wait_count now = sw_th_thread_waits();
    st->pool_waits += now.waits - since->waits;
    st->ms_pool_wait += 1e-6 * (double)(now.ns - since->ns);
}

sw_result sw__gpu_check(sw_status *status, const char *what)
{
    GLenum e = glGetError();
    if (e == GL_NO_ERROR)
        return SW_OK;
    while (glGetError() != GL_NO_ERROR) {
    }
    return sw__fail(status, SW_ERR_GL, "OpenGL error 0x%04x during %s", (unsigned)e, what);
}

static int has_extension(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n) {
        int starts = p == list || p[-1] == ' ';
        int ends = p[n] == '\0' || p[n] == ' ';
        if (starts && ends)
            return 1;
    }
    return 0;
}

static EGLDisplay try_initialize(EGLDisplay dpy)
{
    if (dpy == EGL_NO_DISPLAY)
        return EGL_NO_DISPLAY;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor))
        return EGL_NO_DISPLAY;
    return dpy;
}

static EGLDisplay open_device_display(void)
{
    PFNEGLQUERYDEVICESEXTPROC query =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    if (!query)
        return EGL_NO_DISPLAY;
    EGLDeviceEXT devices[8];
    EGLint n = 0;
    if (!query(8, devices, &n))
        return EGL_NO_DISPLAY;
    for (EGLint i = 0; i < n; ++i) {
        EGLDisplay d =
            try_initialize(eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL));
        if (d != EGL_NO_DISPLAY)
            return d;
    }
    return EGL_NO_DISPLAY;
}

/* SW_EGL_PLATFORM=surfaceless|device|default tries that platform alone: the device platform
 * (EGL_EXT_device_enumeration, what NVIDIA's driver offers without a display server) is only
 * reached here when Mesa's surfaceless platform is missing, so tests force it on Mesa's software
 * device; a host whose first choice misbehaves can pick another. NULL: all, in order. */
static int platform_wanted(const char *name)
{
    const char *forced = getenv("SW_EGL_PLATFORM");
    return !forced || !*forced || strcmp(forced, name) == 0;
}

/* Opens the process's display once. Caller holds g_display_lock. */
static EGLDisplay acquire_display(void)
{
    if (g_display != EGL_NO_DISPLAY)
        return g_display;
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    EGLDisplay d = EGL_NO_DISPLAY;
    if (platform_wanted("surfaceless") && has_extension(client, "EGL_MESA_platform_surfaceless")) {
        d = try_initialize(
            eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL));
        snprintf(g_display_platform, sizeof g_display_platform, "surfaceless");
    }
    if (d == EGL_NO_DISPLAY && platform_wanted("device") &&
        has_extension(client, "EGL_EXT_platform_device")) {
        d = open_device_display();
        snprintf(g_display_platform, sizeof g_display_platform, "device");
    }
    if (d == EGL_NO_DISPLAY && platform_wanted("default")) {
        d = try_initialize(eglGetDisplay(EGL_DEFAULT_DISPLAY));
        snprintf(g_display_platform, sizeof g_display_platform, "default");
    }
    g_display = d;
    return d;
}

static EGLContext create_gl_context(EGLDisplay dpy, int minor)
{
    EGLConfig cfg = EGL_NO_CONFIG_KHR;
    const char *ext = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_extension(ext, "EGL_KHR_no_config_context")) {
        const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(dpy, want, &cfg, 1, &n) || n < 1)
            return EGL_NO_CONTEXT;
    }
    const EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            4,
                            EGL_CONTEXT_MINOR_VERSION,
                            minor,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
    return eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, attrs);
}

static int gl_extension(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i) {
        const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
        if (e && strcmp(e, name) == 0)
            return 1;
    }
    return 0;
}

/* The GPU memory the driver reports, in bytes; 0 where it reports none (Mesa's llvmpipe). */
static uint64_t reported_memory(void)
{
    enum { DEDICATED_VIDMEM_NVX = 0x9047, TEXTURE_FREE_MEMORY_ATI = 0x87FC };
    GLint kib[4] = {0, 0, 0, 0};
    if (gl_extension("GL_NVX_gpu_memory_info"))
        glGetIntegerv(DEDICATED_VIDMEM_NVX, kib);
    else if (gl_extension("GL_ATI_meminfo"))
        glGetIntegerv(TEXTURE_FREE_MEMORY_ATI, kib); /* total free, largest block, ... */
    while (glGetError() != GL_NO_ERROR) {
    }
    return kib[0] > 0 ? (uint64_t)kib[0] << 10 : 0;
}

static sw_result check_gl_version(sw_gpu_context *ctx, sw_status *status)
{
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    const char *renderer = (const char *)glGetString(GL_RENDERER);
    const char *version = (const char *)glGetString(GL_VERSION);
    snprintf(ctx->description, sizeof ctx->description, "%s / %s", renderer ? renderer : "?",
             version ? version : "?");
    int ok = major > 4 || (major == 4 && minor >= 3);
    int clip = major > 4 || (major == 4 && minor >= 5) || gl_extension("GL_ARB_clip_control");
    if (!ok || !clip)
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "OpenGL context %s lacks 4.3 core with glClipControl (reversed-Z); "
                        "try Mesa llvmpipe (EGL_PLATFORM=surfaceless, LIBGL_ALWAYS_SOFTWARE=1)",
                        ctx->description);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &ctx->max_texture_size);
    ctx->gpu_reported_bytes = reported_memory();
    return SW_OK;
}

static sw_result make_context(sw_gpu_context *ctx, sw_status *status)
{
    pthread_mutex_lock(&g_display_lock);
    EGLDisplay dpy = acquire_display();
    pthread_mutex_unlock(&g_display_lock);
    if (dpy == EGL_NO_DISPLAY)
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "no EGL display (tried %s; EGL error 0x%04x): install "
                        "libegl-mesa0 and libgl1-mesa-dri, or set EGL_PLATFORM=surfaceless",
                        getenv("SW_EGL_PLATFORM") && *getenv("SW_EGL_PLATFORM")
                            ? "only the platform SW_EGL_PLATFORM names"
                            : "the Mesa surfaceless platform, the EGL device platform and "
                              "EGL_DEFAULT_DISPLAY",
                        (unsigned)eglGetError());
    ctx->egl_display = dpy;
    /* Each thread binds the API itself, or context creation fails with EGL_BAD_MATCH. */
    if (!eglBindAPI(EGL_OPENGL_API))
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "EGL (%s platform) cannot bind desktop OpenGL (EGL error 0x%04x)",
                        g_display_platform, (unsigned)eglGetError());
    EGLContext c = create_gl_context(dpy, 5);
    if (c == EGL_NO_CONTEXT)
        c = create_gl_context(dpy, 3);
    if (c == EGL_NO_CONTEXT)
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "EGL (%s platform) could not create an OpenGL 4.3+ core context (EGL "
                        "error 0x%04x); try LIBGL_ALWAYS_SOFTWARE=1 for Mesa llvmpipe",
                        g_display_platform, (unsigned)eglGetError());
    ctx->egl_context = c;
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, c))
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "eglMakeCurrent without a surface failed (EGL error 0x%04x): the driver "
                        "lacks EGL_KHR_surfaceless_context",
                        (unsigned)eglGetError());
    sw_result r = check_gl_version(ctx, status);
    size_t used = strlen(ctx->description);
    snprintf(ctx->description + used, sizeof ctx->description - used, " (EGL %s platform)",
             g_display_platform);
    return r;
}

/* The objects every frame uses, in the current context. Reversed-Z needs zero-to-one clip depth:
 * an owned context keeps it from here on; an adopted one gets it back (with the rest of the host's
 * state) after this and has it set again for every frame (host_state.c). */
static sw_result make_gl_objects(sw_gpu_context *ctx, sw_status *status)
{
    ctx->gl_ready = 1;
    sw_result r = sw__gpu_programs_create(ctx, status);
    if (r == SW_OK)
        r = sw__gpu_grids_create(ctx, status);
    if (r != SW_OK)
        return r;
    glGenVertexArrays(1, &ctx->vao);
    glGenFramebuffers(1, &ctx->trim_fbo);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    return sw__gpu_check(status, "context set-up");
}

/* A context made by `make` (its GL context current afterwards), then the frame's GL objects. */
static sw_result context_create(sw_result (*make)(sw_gpu_context *, sw_status *),
                                sw_gpu_context **out, sw_status *status)
{
    *out = NULL;
    sw_gpu_context *ctx = sw__calloc(1, sizeof *ctx);
    if (ctx) {
        ctx->walk_token = sw__calloc(1, sizeof *ctx->walk_token);
        ctx->stash = sw__gpu_stash_new();
        ctx->borders = sw__fr_border_cache_new();
    }
    if (!ctx || !ctx->walk_token || !ctx->stash || !ctx->borders) {
        if (ctx) {
            sw__free(ctx->walk_token);
            sw__gpu_stash_free(ctx->stash);
            sw__fr_border_cache_free(ctx->borders);
        }
        sw__free(ctx);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "GL context: out of memory");
    }
    sw_th_token_init(ctx->walk_token);
    sw_result r = make(ctx, status);
    if (r == SW_OK) {
        sw__gpu_host_state host; /* an adopted context: the host's state stays as it was */
        const int adopted = sw__gpu_context_adopted(ctx);
        if (adopted)
            sw__gpu_host_state_save(&host);
        r = make_gl_objects(ctx, status);
        if (adopted)
            sw__gpu_host_state_restore(&host);
    }
    if (r != SW_OK) {
        sw_gpu_context_free(ctx);
        return r;
    }
    sw_gpu_set_memory_budget(ctx, 0, 0);
    *out = ctx;
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_gpu_context_create_headless(sw_gpu_context **out, sw_status *status)
{
    return context_create(make_context, out, status);
}

sw_result sw_gpu_context_adopt_current(sw_gpu_context **out, sw_status *status)
{
    *out = NULL;
    /* Without a current context glvnd's dispatch answers NULL instead of failing loudly. */
    if (!glGetString(GL_VERSION))
        return sw__fail(status, SW_ERR_NO_CONTEXT,
                        "no OpenGL context is current on this thread: make the host's context "
                        "current before creating the renderer");
    return context_create(check_gl_version, out, status);
}

void sw__gpu_make_current(sw_gpu_context *ctx)
{
    /* One check per frame: a thread owning several headless contexts switches between them. */
    if (ctx->egl_context && eglGetCurrentContext() != ctx->egl_context)
        eglMakeCurrent(ctx->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx->egl_context);
}

void sw_gpu_context_free(sw_gpu_context *ctx)
{
    if (!ctx)
        return;
    sw__gpu_make_current(ctx); /* its objects are deleted in its own context */
    sw__gpu_host_state host;
    const int adopted = ctx->gl_ready && sw__gpu_context_adopted(ctx);
    if (adopted) /* deleting may bind on the way: the host's bindings come back */
        sw__gpu_host_state_save(&host);
    if (ctx->gl_ready) {
        sw__gpu_frame_complete(ctx);
        sw__gpu_programs_free(ctx);
        sw__gpu_atlas_free(ctx);
        sw__gpu_resident_free(ctx);
        sw__gpu_grid_cache_free(ctx);
        sw__curves_renderer_free(ctx->curves);
        sw__gpu_grids_free(ctx);
        glDeleteVertexArrays(1, &ctx->vao);
        glDeleteFramebuffers(1, &ctx->trim_fbo);
        glDeleteFramebuffers(1, &ctx->fbo);
        glDeleteTextures(1, &ctx->tex_color);
        glDeleteTextures(1, &ctx->tex_depth);
    }
    if (adopted)
        sw__gpu_host_state_restore(&host);
    if (ctx->egl_context) {
        eglMakeCurrent(ctx->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(ctx->egl_display, ctx->egl_context);
    }
    sw__free(ctx->walk_token);
    sw__gpu_stash_free(ctx->stash);
    sw__fr_border_cache_free(ctx->borders);
    sw__free(ctx);
}

const char *sw_gpu_context_description_ptr(const sw_gpu_context *ctx)
{
    return ctx->description;
}

sw_result sw__gpu_target_ensure(sw_gpu_context *ctx, int32_t w, int32_t h, sw_status *status)
{
    if (w < 1 || h < 1 || w > ctx->max_texture_size || h > ctx->max_texture_size)
        return sw__fail(status, SW_ERR_LIMIT, "frame size %dx%d outside 1..%d", (int)w, (int)h,
                        (int)ctx->max_texture_size);
    if (ctx->fbo && ctx->fbo_w == w && ctx->fbo_h == h)
        return SW_OK;
    if (!ctx->fbo) {
        glGenFramebuffers(1, &ctx->fbo);
        glGenTextures(1, &ctx->tex_color);
        glGenTextures(1, &ctx->tex_depth);
    }
    /* Textures, not renderbuffers: a depth-compositing present reads them (sw__gpu_present). */
    const GLuint tex[2] = {ctx->tex_color, ctx->tex_depth};
    const GLenum fmt[2][3] = {{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE},
                              {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT}};
    for (int i = 0; i < 2; i++) {
        glBindTexture(GL_TEXTURE_2D, tex[i]);
        glTexImage2D(GL_TEXTURE_2D, 0, (GLint)fmt[i][0], w, h, 0, fmt[i][1], fmt[i][2], NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, ctx->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, ctx->tex_color, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, ctx->tex_depth, 0);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return sw__fail(status, SW_ERR_GL, "render target %dx%d incomplete (0x%04x)", (int)w,
                        (int)h, (unsigned)fs);
    ctx->fbo_w = w;
    ctx->fbo_h = h;
    return sw__gpu_check(status, "render target allocation");
}

/* SPDX-License-Identifier: MIT */
/* tests/api: the failure counter, EXPECT and EXPECT_RESULT of the API test programs, and the
 * host's own EGL context (OpenGL 4.5 core, surfaceless) for the tests that play an embedding host.
 * Include once, in the program's main file; main returns g_failures != 0. */
#ifndef SW_API_TEST_EXPECT_H
#define SW_API_TEST_EXPECT_H

#include <splinewalk/splinewalk.h>

#include <stdio.h>

static int g_failures;

/* Counts and prints a failed condition; the test goes on. */
#define EXPECT(cond)                                                                               \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "line %d: expected %s\n", __LINE__, #cond);                            \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

/* Counts and prints a result other than `want` (by id, not message), naming the call and the line
 * (a helper's caller's line where a helper checks on its behalf). */
static inline void sw_test_expect_result(sw_result got, sw_result want, const char *call, int line)
{
    if (got != want) {
        fprintf(stderr, "line %d: %s returned %s, expected %s\n", line, call, sw_result_id_str(got),
                sw_result_id_str(want));
        g_failures++;
    }
}
#define EXPECT_RESULT(call, want) sw_test_expect_result((call), (want), #call, __LINE__)

#ifdef SW_API_TEST_HOST_CONTEXT
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

/* Makes the host's context current on the calling thread: 0, or -1 when EGL cannot. */
static inline int sw_test_host_context(void)
{
    EGLDisplay dpy =
        eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API))
        return -1;
    const EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            4,
                            EGL_CONTEXT_MINOR_VERSION,
                            5,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
    EGLContext c = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attrs);
    if (c == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, c))
        return -1;
    return 0;
}

/* A shader of the host's own programs, compiled (its status is the link's to report). */
static inline GLuint sw_test_compile_shader(GLenum kind, const char *src)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    return s;
}
#endif

#endif

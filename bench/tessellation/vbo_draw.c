/* SPDX-License-Identifier: MIT */
/* bench/tessellation: the GLU baseline's draw path (see vbo_draw.h). The view-projection maps
 * eye-relative world positions to clip space with reversed-Z (gpu/camera.c), so depth is cleared
 * to 0 and tested with GL_GREATER under glClipControl zero-to-one, as in gpu/draw.c.
 */
#include "vbo_draw.h"

#include <GL/glcorearb.h>
#include <stdio.h>
#include <stdlib.h>

struct bt_draw {
    int32_t w, h;
    GLuint fbo, rb_color, rb_depth, prog, vao, vbo, ibo;
    GLint loc_vp;
    int pipelined;    /* bt_draw_set_pipelined */
    GLsync in_flight; /* pipelined: the last frame's fence */
};

/* Waits for the fenced frame (if any) to complete. */
static void wait_in_flight(bt_draw *d)
{
    if (!d->in_flight)
        return;
    while (glClientWaitSync(d->in_flight, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000u) ==
           GL_TIMEOUT_EXPIRED)
        ;
    glDeleteSync(d->in_flight);
    d->in_flight = 0;
}

void bt_draw_set_pipelined(bt_draw *d, int on)
{
    wait_in_flight(d);
    d->pipelined = on;
}

/* The end of a frame: glFinish, or pipelined, its fence, then the wait for the frame before. */
static void end_frame(bt_draw *d)
{
    if (!d->pipelined) {
        glFinish();
        return;
    }
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    wait_in_flight(d);
    d->in_flight = fence;
}

static const char *const k_vs = "#version 430 core\n"
                                "layout(location = 0) in vec3 a_pos;\n"
                                "layout(location = 1) in vec3 a_nrm;\n"
                                "uniform mat4 u_view_proj;\n"
                                "out vec3 v_rel;\n"
                                "out vec3 v_nrm;\n"
                                "void main() {\n"
                                "  v_rel = a_pos;\n"
                                "  v_nrm = a_nrm;\n"
                                "  gl_Position = u_view_proj * vec4(a_pos, 1.0);\n"
                                "}\n";

static const char *const k_fs =
    "#version 430 core\n"
    "in vec3 v_rel;\n"
    "in vec3 v_nrm;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "  float ln = length(v_nrm);\n"
    "  float lambert = ln > 0.0 ? abs(dot(v_nrm / ln, normalize(-v_rel))) : 1.0;\n"
    "  vec3 c = vec3(0.8) * (0.2 + 0.8 * lambert);\n"
    "  o_color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);\n"
    "}\n";

static GLuint compile(GLenum type, const char *src, char *err, size_t n)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        glGetShaderInfoLog(s, (GLsizei)n, NULL, err);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static int make_program(bt_draw *d, char *err, size_t n)
{
    GLuint vs = compile(GL_VERTEX_SHADER, k_vs, err, n);
    GLuint fs = vs ? compile(GL_FRAGMENT_SHADER, k_fs, err, n) : 0;
    if (!fs) {
        glDeleteShader(vs);
        return 0;
    }
    d->prog = glCreateProgram();
    glAttachShader(d->prog, vs);
    glAttachShader(d->prog, fs);
    glLinkProgram(d->prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(d->prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        glGetProgramInfoLog(d->prog, (GLsizei)n, NULL, err);
        return 0;
    }
    d->loc_vp = glGetUniformLocation(d->prog, "u_view_proj");
    return 1;
}

static int make_target(bt_draw *d, char *err, size_t n)
{
    glGenRenderbuffers(1, &d->rb_color);
    glBindRenderbuffer(GL_RENDERBUFFER, d->rb_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, d->w, d->h);
    glGenRenderbuffers(1, &d->rb_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, d->rb_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, d->w, d->h);
    glGenFramebuffers(1, &d->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, d->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, d->rb_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, d->rb_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, n, "render target %dx%d incomplete", d->w, d->h);
        return 0;
    }
    return 1;
}

bt_draw *bt_draw_create(int32_t width, int32_t height, char *err, size_t err_size)
{
    bt_draw *d = calloc(1, sizeof *d);
    if (!d) {
        snprintf(err, err_size, "out of memory");
        return NULL;
    }
    d->w = width;
    d->h = height;
    if (!make_program(d, err, err_size) || !make_target(d, err, err_size)) {
        bt_draw_free(d);
        return NULL;
    }
    glGenVertexArrays(1, &d->vao);
    glGenBuffers(1, &d->vbo);
    glGenBuffers(1, &d->ibo);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        snprintf(err, err_size, "GL error 0x%04x while setting up the draw path", e);
        bt_draw_free(d);
        return NULL;
    }
    return d;
}

void bt_draw_free(bt_draw *d)
{
    if (!d)
        return;
    wait_in_flight(d);
    glDeleteBuffers(1, &d->vbo);
    glDeleteBuffers(1, &d->ibo);
    glDeleteVertexArrays(1, &d->vao);
    glDeleteFramebuffers(1, &d->fbo);
    glDeleteRenderbuffers(1, &d->rb_color);
    glDeleteRenderbuffers(1, &d->rb_depth);
    glDeleteProgram(d->prog);
    free(d);
}

static void upload(bt_draw *d, const float *v, size_t n_v, size_t stride, const uint32_t *idx,
                   size_t n_idx)
{
    glBindVertexArray(d->vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n_v * stride * sizeof *v), v, GL_STREAM_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, d->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(n_idx * sizeof *idx), idx, GL_STREAM_DRAW);
    GLsizei bytes = (GLsizei)(stride * sizeof(float));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, bytes, (const void *)0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, bytes, (const void *)(3 * sizeof(float)));
}

unsigned bt_draw_upload(bt_draw *d, const float *v, size_t n_v, size_t stride, const uint32_t *idx,
                        size_t n_idx)
{
    GLenum pending = glGetError();
    if (pending != GL_NO_ERROR)
        return pending;
    upload(d, v, n_v, stride, idx, n_idx);
    return glGetError();
}

unsigned bt_draw_uploaded(bt_draw *d, const float view_proj[16], size_t n_idx)
{
    GLenum pending = glGetError();
    if (pending != GL_NO_ERROR)
        return pending;
    glBindFramebuffer(GL_FRAMEBUFFER, d->fbo);
    glViewport(0, 0, d->w, d->h);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glDisable(GL_COLOR_LOGIC_OP);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glBindVertexArray(d->vao);
    glUseProgram(d->prog);
    glUniformMatrix4fv(d->loc_vp, 1, GL_FALSE, view_proj);
    glDrawElements(GL_TRIANGLES, (GLsizei)n_idx, GL_UNSIGNED_INT, (const void *)0);
    end_frame(d);
    return glGetError();
}

unsigned bt_draw_mesh(bt_draw *d, const float view_proj[16], const float *v, size_t n_v,
                      size_t stride, const uint32_t *idx, size_t n_idx)
{
    unsigned e = bt_draw_upload(d, v, n_v, stride, idx, n_idx);
    return e != 0 ? e : bt_draw_uploaded(d, view_proj, n_idx);
}

unsigned bt_draw_drain_errors(void)
{
    unsigned n = 0;
    while (glGetError() != GL_NO_ERROR && n < 1000)
        ++n;
    return n;
}

uint64_t bt_draw_covered(bt_draw *d)
{
    size_t n = (size_t)d->w * (size_t)d->h;
    uint8_t *px = malloc(n * 4);
    if (!px)
        return 0;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, d->w, d->h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    uint64_t c = 0;
    for (size_t i = 0; i < n; ++i)
        c += px[4 * i + 3] != 0;
    free(px);
    return c;
}

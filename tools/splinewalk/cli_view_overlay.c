/* SPDX-License-Identifier: MIT */
/* The viewer's frame-time overlay: the last frames' times as bars in the window's lower left,
 * with marks at 16.7 and 33.3 ms, drawn by the viewer itself after the renderer presented its
 * frame — the host drawing around splinewalk, as an embedding program does. Bars of frames that
 * drew something coarser than asked (fallback draws, refined later) are orange. */
#include "cli_view_overlay.h"

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/glcorearb.h>
#include <stdio.h>
#include <string.h>

enum { BAR_W = 3, HEIGHT = 120, VERTS_PER_QUAD = 6 };
static const double k_full_scale_ms = 50.0; /* the overlay's height */

static const char *k_vs = "#version 430 core\n"
                          "layout(location = 0) in vec2 pos;\n"
                          "layout(location = 1) in vec4 col;\n"
                          "out vec4 v_col;\n"
                          "void main() { v_col = col; gl_Position = vec4(pos, 0.0, 1.0); }\n";
static const char *k_fs = "#version 430 core\n"
                          "in vec4 v_col;\n"
                          "out vec4 colour;\n"
                          "void main() { colour = v_col; }\n";

static GLuint compile(GLenum kind, const char *src)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    return ok ? s : 0;
}

/* The program of a vertex and a fragment shader, 0 when they do not build. */
static GLuint build_program(const char *vs_src, const char *fs_src)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_src), fs = compile(GL_FRAGMENT_SHADER, fs_src);
    GLuint prog = vs && fs ? glCreateProgram() : 0;
    if (prog) {
        glAttachShader(prog, vs);
        glAttachShader(prog, fs);
        glLinkProgram(prog);
    }
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    if (prog)
        glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (prog && !ok) {
        glDeleteProgram(prog);
        prog = 0;
    }
    return prog;
}

int sw_cli_overlay_init(sw_cli_overlay *o)
{
    memset(o, 0, sizeof *o);
    o->program = build_program(k_vs, k_fs);
    if (!o->program)
        return -1;
    glGenVertexArrays(1, &o->vao);
    glGenBuffers(1, &o->vbo);
    glBindVertexArray(o->vao);
    glBindBuffer(GL_ARRAY_BUFFER, o->vbo);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)0);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)(2 * sizeof(float)));
    glBindVertexArray(0);
    o->enabled = 1;
    return 0;
}

void sw_cli_overlay_free(sw_cli_overlay *o)
{
    glDeleteProgram(o->program);
    glDeleteBuffers(1, &o->vbo);
    glDeleteVertexArrays(1, &o->vao);
}

void sw_cli_overlay_push(sw_cli_overlay *o, double frame_ms, int fallback)
{
    o->ms[o->next] = (float)frame_ms;
    o->fallback[o->next] = (unsigned char)(fallback != 0);
    o->next = (o->next + 1) % SW_CLI_OVERLAY_FRAMES;
    if (o->count < SW_CLI_OVERLAY_FRAMES)
        o->count++;
}

/* A quad in pixels (x0, y0)-(x1, y1) of a w x h window, as two triangles in clip space. */
static float *quad(float *v, double x0, double y0, double x1, double y1, int w, int h,
                   const float rgba[4])
{
    const double xs[6] = {x0, x1, x1, x0, x1, x0}, ys[6] = {y0, y0, y1, y0, y1, y1};
    for (int k = 0; k < 6; ++k) {
        *v++ = (float)(2.0 * xs[k] / w - 1.0);
        *v++ = (float)(2.0 * ys[k] / h - 1.0);
        memcpy(v, rgba, 4 * sizeof(float));
        v += 4;
    }
    return v;
}

void sw_cli_overlay_draw(const sw_cli_overlay *o, int w, int h)
{
    if (!o->enabled || !o->program)
        return;
    static float verts[(SW_CLI_OVERLAY_FRAMES + 3) * VERTS_PER_QUAD * 6];
    static const float back[4] = {0.1f, 0.1f, 0.1f, 0.55f}, mark[4] = {1.0f, 1.0f, 1.0f, 0.8f},
                       ok[4] = {0.35f, 0.8f, 0.35f, 0.9f}, late[4] = {0.95f, 0.55f, 0.15f, 0.9f};
    const double x0 = 8.0, y0 = 8.0, px_per_ms = HEIGHT / k_full_scale_ms;
    float *v = quad(verts, x0, y0, x0 + BAR_W * SW_CLI_OVERLAY_FRAMES, y0 + HEIGHT, w, h, back);
    for (int i = 0; i < o->count; ++i) {
        int slot = (o->next - o->count + i + SW_CLI_OVERLAY_FRAMES) % SW_CLI_OVERLAY_FRAMES;
        double top = o->ms[slot] * px_per_ms;
        top = top < HEIGHT ? top : HEIGHT;
        double x = x0 + BAR_W * i;
        v = quad(v, x, y0, x + BAR_W - 1, y0 + top, w, h, o->fallback[slot] ? late : ok);
    }
    for (int k = 1; k <= 2; ++k) { /* 60 and 30 frames per second */
        double y = y0 + k * (1000.0 / 60.0) * px_per_ms;
        v = quad(v, x0, y, x0 + BAR_W * SW_CLI_OVERLAY_FRAMES, y + 1, w, h, mark);
    }
    GLsizei n = (GLsizei)((v - verts) / 6);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_COLOR_LOGIC_OP);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(o->program);
    glBindVertexArray(o->vao);
    glBindBuffer(GL_ARRAY_BUFFER, o->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)n * 6 * sizeof(float)), verts,
                 GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, n);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
}

/* ---- the trim-atlas overlay --------------------------------------------------------------------
 * One page of the renderer's trim-texture atlas (Guthe §4.4) in the window's upper right corner,
 * texels as grey levels (white: inside the trimmed surface), on a dark frame. */

static const char *k_atlas_vs = "#version 430 core\n"
                                "layout(location = 0) in vec2 pos;\n"
                                "layout(location = 1) in vec2 uv;\n"
                                "out vec2 v_uv;\n"
                                "void main() { v_uv = uv; gl_Position = vec4(pos, 0.0, 1.0); }\n";
static const char *k_atlas_fs = "#version 430 core\n"
                                "uniform sampler2DArray atlas;\n"
                                "uniform float layer;\n"
                                "in vec2 v_uv;\n"
                                "out vec4 colour;\n"
                                "void main() {\n"
                                "  float t = texture(atlas, vec3(v_uv, layer)).r;\n"
                                "  colour = vec4(vec3(0.15 + 0.85 * t), 1.0);\n"
                                "}\n";

int sw_cli_atlas_view_init(sw_cli_atlas_view *a)
{
    memset(a, 0, sizeof *a);
    a->page = -1;
    a->program = build_program(k_atlas_vs, k_atlas_fs);
    if (!a->program)
        return -1;
    glGenVertexArrays(1, &a->vao);
    glGenBuffers(1, &a->vbo);
    glBindVertexArray(a->vao);
    glBindBuffer(GL_ARRAY_BUFFER, a->vbo);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), (void *)0);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), (void *)(2 * sizeof(float)));
    glBindVertexArray(0);
    return 0;
}

void sw_cli_atlas_view_free(sw_cli_atlas_view *a)
{
    glDeleteProgram(a->program);
    glDeleteBuffers(1, &a->vbo);
    glDeleteVertexArrays(1, &a->vao);
}

void sw_cli_atlas_view_next(sw_cli_atlas_view *a, int pages)
{
    a->page = a->page + 1 < pages ? a->page + 1 : -1;
}

void sw_cli_atlas_view_draw(const sw_cli_atlas_view *a, unsigned texture, int pages, int w, int h)
{
    if (a->page < 0 || !a->program || !texture || pages <= 0)
        return;
    const int layer = a->page < pages ? a->page : pages - 1;
    const double side = (w < h ? w : h) / 2.0, x1 = w - 8.0, y1 = h - 8.0;
    const double x0 = x1 - side, y0 = y1 - side;
    float v[6 * 4];
    const double xs[6] = {x0, x1, x1, x0, x1, x0}, ys[6] = {y0, y0, y1, y0, y1, y1};
    for (int k = 0; k < 6; ++k) {
        v[4 * k] = (float)(2.0 * xs[k] / w - 1.0);
        v[4 * k + 1] = (float)(2.0 * ys[k] / h - 1.0);
        v[4 * k + 2] = xs[k] == x0 ? 0.0f : 1.0f;
        v[4 * k + 3] = ys[k] == y0 ? 0.0f : 1.0f;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_COLOR_LOGIC_OP);
    glUseProgram(a->program);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, texture);
    glUniform1i(glGetUniformLocation(a->program, "atlas"), 0);
    glUniform1f(glGetUniformLocation(a->program, "layer"), (float)layer);
    glBindVertexArray(a->vao);
    glBindBuffer(GL_ARRAY_BUFFER, a->vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof v, v, GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glBindVertexArray(0);
}

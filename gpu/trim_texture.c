/* Trim textures on the GPU (Guthe et al. 2005 §4): a triangle fan from each trim loop's first
 * vertex toggles the texels it covers (glLogicOp(GL_INVERT) on an R8 target), so a texel centre
 * covered an odd number of times is inside: even-odd parity without caring for the loops'
 * orientation or nesting. A second pass draws every loop as a 1-pixel line loop that SETS its
 * texels (§7.1's crack filling moved into the texture: boundary texels count as inside), in a
 * separate pass because toggling them would undo the parity.
 *
 * Exactness (PLATFORM.md): fan triangles share edges bit for bit because each loop's vertices are
 * converted to clip space once, and loops arrive closed with bit-identical joins from
 * sw_sg_trim_flatten_loop; the rasteriser's fill rules then cover every texel centre once per
 * triangle layer.
 */
#include "sw_gpu_internal.h"
#include "sw_status_util.h"

#include <GL/glcorearb.h>
#include <stdlib.h>

/* Clip-space x, y of every loop vertex; first[k] / count[k] per loop. */
static float *loops_to_clip(const sw_sg_polyline *loops, uint32_t n_loops, const double uv_box[4],
                            GLint *first, GLsizei *count, size_t *n_out)
{
    size_t total = 0;
    for (uint32_t k = 0; k < n_loops; ++k)
        total += loops[k].count;
    float *xy = malloc((total ? total : 1) * 2 * sizeof *xy);
    if (!xy)
        return NULL;
    double su = 2.0 / (uv_box[1] - uv_box[0]), sv = 2.0 / (uv_box[3] - uv_box[2]);
    size_t at = 0;
    for (uint32_t k = 0; k < n_loops; ++k) {
        first[k] = (GLint)at;
        count[k] = (GLsizei)loops[k].count;
        for (uint32_t i = 0; i < loops[k].count; ++i, ++at) {
            xy[2 * at] = (float)((loops[k].uv[2 * i] - uv_box[0]) * su - 1.0);
            xy[2 * at + 1] = (float)((loops[k].uv[2 * i + 1] - uv_box[2]) * sv - 1.0);
        }
    }
    *n_out = total;
    return xy;
}

static GLuint new_r8_texture(int32_t w, int32_t h)
{
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R8, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

static void draw_passes(const GLint *first, const GLsizei *count, uint32_t n_loops)
{
    glEnable(GL_COLOR_LOGIC_OP);
    glLogicOp(GL_INVERT);
    for (uint32_t k = 0; k < n_loops; ++k)
        if (count[k] >= 3)
            glDrawArrays(GL_TRIANGLE_FAN, first[k], count[k]);
    glDisable(GL_COLOR_LOGIC_OP);
    glLineWidth(1.0f);
    for (uint32_t k = 0; k < n_loops; ++k)
        if (count[k] >= 2)
            glDrawArrays(GL_LINE_LOOP, first[k], count[k]);
}

sw_result sw__gpu_trim_texture_make(sw_gpu_context *ctx, const sw_sg_polyline *loops,
                                    uint32_t n_loops, const double uv_box[4], int32_t w, int32_t h,
                                    GLuint *tex, sw_status *status)
{
    *tex = 0;
    if (w < 1 || h < 1 || w > ctx->max_texture_size || h > ctx->max_texture_size)
        return sw__fail(status, SW_ERR_LIMIT, "trim texture %dx%d outside 1..%d", (int)w, (int)h,
                        (int)ctx->max_texture_size);
    if (!(uv_box[1] > uv_box[0]) || !(uv_box[3] > uv_box[2]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "trim texture over an empty uv box");
    GLint *first = malloc((n_loops ? n_loops : 1) * sizeof *first);
    GLsizei *count = malloc((n_loops ? n_loops : 1) * sizeof *count);
    size_t n_xy = 0;
    float *xy = first && count ? loops_to_clip(loops, n_loops, uv_box, first, count, &n_xy) : NULL;
    if (!xy) {
        free(first);
        free(count);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim texture: out of memory");
    }
    GLuint t = new_r8_texture(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, ctx->trim_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t, 0);
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (!ctx->trim_vbo)
        glGenBuffers(1, &ctx->trim_vbo);
    glBindVertexArray(ctx->vao);
    glBindBuffer(GL_ARRAY_BUFFER, ctx->trim_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n_xy * 2 * sizeof *xy), xy, GL_STREAM_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), (const void *)0);
    glDisableVertexAttribArray(1);
    glDisableVertexAttribArray(2);
    glUseProgram(ctx->prog_trim);
    draw_passes(first, count, n_loops);
    free(xy);
    free(first);
    free(count);
    sw_result r = sw__gpu_check(status, "trim texture generation");
    if (r != SW_OK) {
        glDeleteTextures(1, &t);
        return r;
    }
    *tex = t;
    return SW_OK;
}

sw_result sw__gpu_trim_texture_read(sw_gpu_context *ctx, GLuint tex, int32_t w, int32_t h,
                                    uint8_t *out, sw_status *status)
{
    (void)ctx;
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    (void)w;
    (void)h;
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_UNSIGNED_BYTE, out);
    return sw__gpu_check(status, "trim texture readback");
}

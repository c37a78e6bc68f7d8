/* SPDX-License-Identifier: MIT */
/* Trim textures on the GPU (Guthe et al. 2005 §4), one atlas page at a time (§4.4): a triangle
 * fan from each trim loop's first vertex toggles the texels it covers (glLogicOp(GL_INVERT) on an
 * R8 target), so a texel centre covered an odd number of times is inside: even-odd parity without
 * caring for the loops' orientation or nesting. A second pass draws every loop as a 1-pixel line
 * loop that SETS its texels (§7.1's crack filling moved into the texture: boundary texels count as
 * inside), in a separate pass because toggling them would undo the parity.
 *
 * All loops of all entries of a page go in one pass: the entries' footprints (rectangle plus
 * gutter) do not overlap and each loop stays inside its own footprint (trim_atlas.c clamps it), so
 * the fans of one entry never toggle another's texels and parity stays exact per entry.
 *
 * Exactness (PLATFORM.md): fan triangles share edges bit for bit because each loop's vertices are
 * converted to clip space once, and loops arrive closed with bit-identical joins from
 * sw_sg_trim_flatten_loop; the rasteriser's fill rules then cover every texel centre once per
 * triangle layer.
 */
#include "sw_gpu_internal.h"

#include <GL/glcorearb.h>

void sw__gpu_trim_page_draw(sw_gpu_context *ctx, GLuint tex, int32_t layer, int32_t side,
                            const float *xy, size_t n_xy, const GLint *first, const GLsizei *count,
                            GLsizei n_loops)
{
    glBindFramebuffer(GL_FRAMEBUFFER, ctx->trim_fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, tex, 0, layer);
    glViewport(0, 0, side, side);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
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
    /* llvmpipe (Mesa 22.3, llvmpipe_draw_vbo) returns from a multi-draw whose FIRST draw has no
     * vertices without drawing any of the others; a loop clipped away by a trim tile (trim_tiles.c)
     * is such a draw. Empty loops draw nothing anyway: start at the first non-empty one. */
    while (n_loops > 0 && count[0] == 0) {
        ++first;
        ++count;
        --n_loops;
    }

    glEnable(GL_COLOR_LOGIC_OP);
    glLogicOp(GL_INVERT);
    glMultiDrawArrays(GL_TRIANGLE_FAN, first, count, n_loops);
    glDisable(GL_COLOR_LOGIC_OP);
    glLineWidth(1.0f);
    glMultiDrawArrays(GL_LINE_LOOP, first, count, n_loops);
}

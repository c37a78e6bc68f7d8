/* SPDX-License-Identifier: MIT */
/* The host's GL state around the renderer's work in an adopted context (sw_renderer_desc.
 * use_current_context) and around a presenting frame (sw_frame_desc.present).
 *
 * On entry every piece of state below is saved and set to its GL default (zero-to-one clip depth
 * excepted: reversed-Z needs it), so the renderer draws in the host's context exactly as in a
 * fresh context of its own: a host's GL_UNPACK_ROW_LENGTH, pixel unpack buffer, scissor, colour
 * mask, depth range, polygon mode, sampler object or clip control would otherwise change what the
 * renderer uploads and draws. On exit all of it is put back. Saved: bindings (program, vertex
 * array and its element buffer, the generic buffer targets, the indexed uniform and shader
 * storage ranges below SW__GPU_HOST_INDEXED, renderbuffer, draw / read framebuffers, texture unit
 * 0's textures of every target and its sampler, the active unit), the capabilities in k_caps,
 * viewport and scissor box, blend, depth, stencil, colour and clear state, rasterisation (cull,
 * front face, polygon mode and offset, line width, point size, provoking vertex, primitive
 * restart index, patch vertices, logic op), clip control, pixel pack / unpack parameters, and the
 * transform feedback object with its generic buffer binding (the renderer evaluates kept patch
 * grids into its own object's buffers, resident_grids.c). The renderer binds textures on unit 0
 * only and touches no other unit or image unit. */
#include "sw_gpu_internal.h"

#include <string.h>

static const GLenum k_caps[] = {
    GL_BLEND,
    GL_CULL_FACE,
    GL_DEPTH_TEST,
    GL_SCISSOR_TEST,
    GL_STENCIL_TEST,
    GL_COLOR_LOGIC_OP,
    GL_POLYGON_OFFSET_FILL,
    GL_POLYGON_OFFSET_LINE,
    GL_POLYGON_OFFSET_POINT,
    GL_PRIMITIVE_RESTART,
    GL_PRIMITIVE_RESTART_FIXED_INDEX,
    GL_RASTERIZER_DISCARD,
    GL_FRAMEBUFFER_SRGB,
    GL_DEPTH_CLAMP,
    GL_DITHER,
    GL_MULTISAMPLE,
    GL_SAMPLE_ALPHA_TO_COVERAGE,
    GL_SAMPLE_ALPHA_TO_ONE,
    GL_SAMPLE_COVERAGE,
    GL_SAMPLE_MASK,
    GL_SAMPLE_SHADING,
    GL_LINE_SMOOTH,
    GL_POLYGON_SMOOTH,
    GL_PROGRAM_POINT_SIZE,
    GL_TEXTURE_CUBE_MAP_SEAMLESS,
    GL_CLIP_DISTANCE0,
    GL_CLIP_DISTANCE1,
    GL_CLIP_DISTANCE2,
    GL_CLIP_DISTANCE3,
    GL_CLIP_DISTANCE4,
    GL_CLIP_DISTANCE5,
    GL_CLIP_DISTANCE6,
    GL_CLIP_DISTANCE7,
};
_Static_assert(sizeof k_caps / sizeof k_caps[0] == SW__GPU_HOST_CAPS, "k_caps out of step");

static int cap_default(GLenum cap)
{
    return cap == GL_DITHER || cap == GL_MULTISAMPLE;
}

/* Generic buffer binding points and their binding queries. */
static const GLenum k_buffers[][2] = {
    {GL_ARRAY_BUFFER, GL_ARRAY_BUFFER_BINDING},
    {GL_UNIFORM_BUFFER, GL_UNIFORM_BUFFER_BINDING},
    {GL_SHADER_STORAGE_BUFFER, GL_SHADER_STORAGE_BUFFER_BINDING},
    {GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING},
    {GL_PIXEL_UNPACK_BUFFER, GL_PIXEL_UNPACK_BUFFER_BINDING},
    {GL_COPY_READ_BUFFER, GL_COPY_READ_BUFFER_BINDING},
    {GL_COPY_WRITE_BUFFER, GL_COPY_WRITE_BUFFER_BINDING},
    {GL_DRAW_INDIRECT_BUFFER, GL_DRAW_INDIRECT_BUFFER_BINDING},
    {GL_DISPATCH_INDIRECT_BUFFER, GL_DISPATCH_INDIRECT_BUFFER_BINDING},
    {GL_ATOMIC_COUNTER_BUFFER, GL_ATOMIC_COUNTER_BUFFER_BINDING},
    {GL_TEXTURE_BUFFER, GL_TEXTURE_BUFFER_BINDING},
};
_Static_assert(sizeof k_buffers / sizeof k_buffers[0] == SW__GPU_HOST_BUFFERS,
               "k_buffers out of step");

/* The indexed targets: binding, start and size queries. */
static const GLenum k_indexed[][4] = {
    {GL_UNIFORM_BUFFER, GL_UNIFORM_BUFFER_BINDING, GL_UNIFORM_BUFFER_START, GL_UNIFORM_BUFFER_SIZE},
    {GL_SHADER_STORAGE_BUFFER, GL_SHADER_STORAGE_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_START,
     GL_SHADER_STORAGE_BUFFER_SIZE},
};

static const GLenum k_textures[][2] = {
    {GL_TEXTURE_1D, GL_TEXTURE_BINDING_1D},
    {GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D},
    {GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D},
    {GL_TEXTURE_1D_ARRAY, GL_TEXTURE_BINDING_1D_ARRAY},
    {GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY},
    {GL_TEXTURE_RECTANGLE, GL_TEXTURE_BINDING_RECTANGLE},
    {GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BINDING_CUBE_MAP},
    {GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_BINDING_CUBE_MAP_ARRAY},
    {GL_TEXTURE_BUFFER, GL_TEXTURE_BINDING_BUFFER},
    {GL_TEXTURE_2D_MULTISAMPLE, GL_TEXTURE_BINDING_2D_MULTISAMPLE},
    {GL_TEXTURE_2D_MULTISAMPLE_ARRAY, GL_TEXTURE_BINDING_2D_MULTISAMPLE_ARRAY},
};
_Static_assert(sizeof k_textures / sizeof k_textures[0] == SW__GPU_HOST_TEXTURES,
               "k_textures out of step");

/* Pixel store parameters, pack then unpack; alignment 4 by default, the rest 0. */
static const GLenum k_pixel_store[] = {
    GL_PACK_ALIGNMENT,      GL_PACK_ROW_LENGTH,    GL_PACK_SKIP_ROWS,    GL_PACK_SKIP_PIXELS,
    GL_PACK_IMAGE_HEIGHT,   GL_PACK_SKIP_IMAGES,   GL_PACK_SWAP_BYTES,   GL_PACK_LSB_FIRST,
    GL_UNPACK_ALIGNMENT,    GL_UNPACK_ROW_LENGTH,  GL_UNPACK_SKIP_ROWS,  GL_UNPACK_SKIP_PIXELS,
    GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_IMAGES, GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST,
};
_Static_assert(sizeof k_pixel_store / sizeof k_pixel_store[0] == SW__GPU_HOST_PIXEL_STORE,
               "k_pixel_store out of step");

static GLint pixel_store_default(GLenum pname)
{
    return pname == GL_PACK_ALIGNMENT || pname == GL_UNPACK_ALIGNMENT ? 4 : 0;
}

static void save_bindings(sw__gpu_host_state *s)
{
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s->draw_fb);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s->read_fb);
    glGetIntegerv(GL_RENDERBUFFER_BINDING, &s->renderbuffer);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s->vao);
    glGetIntegerv(GL_ELEMENT_ARRAY_BUFFER_BINDING, &s->element_buffer);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BINDING, &s->xfb_object);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &s->xfb_buffer);
    for (int i = 0; i < SW__GPU_HOST_BUFFERS; i++)
        glGetIntegerv(k_buffers[i][1], &s->buffers[i]);
    static const GLenum max[2] = {GL_MAX_UNIFORM_BUFFER_BINDINGS,
                                  GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS};
    for (int t = 0; t < 2; t++) {
        glGetIntegerv(max[t], &s->n_indexed[t]);
        if (s->n_indexed[t] > SW__GPU_HOST_INDEXED)
            s->n_indexed[t] = SW__GPU_HOST_INDEXED;
    }
    for (int t = 0; t < 2; t++)
        for (GLuint i = 0; i < (GLuint)s->n_indexed[t]; i++) {
            glGetIntegeri_v(k_indexed[t][1], i, &s->indexed[t][i].buffer);
            glGetInteger64i_v(k_indexed[t][2], i, &s->indexed[t][i].start);
            glGetInteger64i_v(k_indexed[t][3], i, &s->indexed[t][i].size);
        }
    glGetIntegerv(GL_ACTIVE_TEXTURE, &s->active_texture);
    glActiveTexture(GL_TEXTURE0);
    for (int i = 0; i < SW__GPU_HOST_TEXTURES; i++)
        glGetIntegerv(k_textures[i][1], &s->textures[i]);
    glGetIntegerv(GL_SAMPLER_BINDING, &s->sampler);
}

static void save_fixed_function(sw__gpu_host_state *s)
{
    for (int i = 0; i < SW__GPU_HOST_CAPS; i++)
        s->caps[i] = glIsEnabled(k_caps[i]);
    glGetIntegerv(GL_VIEWPORT, s->viewport);
    glGetIntegerv(GL_SCISSOR_BOX, s->scissor);
    glGetIntegerv(GL_BLEND_SRC_RGB, &s->blend[0]);
    glGetIntegerv(GL_BLEND_DST_RGB, &s->blend[1]);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &s->blend[2]);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &s->blend[3]);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &s->blend[4]);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &s->blend[5]);
    glGetFloatv(GL_BLEND_COLOR, s->blend_color);
    glGetIntegerv(GL_DEPTH_FUNC, &s->depth_func);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &s->depth_mask);
    glGetDoublev(GL_DEPTH_CLEAR_VALUE, &s->depth_clear);
    glGetDoublev(GL_DEPTH_RANGE, s->depth_range);
    static const GLenum stencil[2][7] = {
        {GL_STENCIL_FUNC, GL_STENCIL_REF, GL_STENCIL_VALUE_MASK, GL_STENCIL_FAIL,
         GL_STENCIL_PASS_DEPTH_FAIL, GL_STENCIL_PASS_DEPTH_PASS, GL_STENCIL_WRITEMASK},
        {GL_STENCIL_BACK_FUNC, GL_STENCIL_BACK_REF, GL_STENCIL_BACK_VALUE_MASK,
         GL_STENCIL_BACK_FAIL, GL_STENCIL_BACK_PASS_DEPTH_FAIL, GL_STENCIL_BACK_PASS_DEPTH_PASS,
         GL_STENCIL_BACK_WRITEMASK},
    };
    for (int face = 0; face < 2; face++)
        for (int i = 0; i < 7; i++)
            glGetIntegerv(stencil[face][i], &s->stencil[face][i]);
    glGetIntegerv(GL_STENCIL_CLEAR_VALUE, &s->stencil_clear);
    glGetBooleanv(GL_COLOR_WRITEMASK, s->color_mask);
    glGetFloatv(GL_COLOR_CLEAR_VALUE, s->color_clear);
    glGetIntegerv(GL_CULL_FACE_MODE, &s->cull_face);
    glGetIntegerv(GL_FRONT_FACE, &s->front_face);
    GLint mode[2] = {GL_FILL, GL_FILL};
    glGetIntegerv(GL_POLYGON_MODE, mode); /* core: one mode for both faces */
    s->polygon_mode = mode[0];
    glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &s->polygon_offset[0]);
    glGetFloatv(GL_POLYGON_OFFSET_UNITS, &s->polygon_offset[1]);
    glGetFloatv(GL_LINE_WIDTH, &s->line_width);
    glGetFloatv(GL_POINT_SIZE, &s->point_size);
    glGetIntegerv(GL_PROVOKING_VERTEX, &s->provoking_vertex);
    glGetIntegerv(GL_PRIMITIVE_RESTART_INDEX, &s->restart_index);
    glGetIntegerv(GL_PATCH_VERTICES, &s->patch_vertices);
    glGetIntegerv(GL_LOGIC_OP_MODE, &s->logic_op);
    glGetIntegerv(GL_CLIP_ORIGIN, &s->clip_origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &s->clip_depth_mode);
    for (int i = 0; i < SW__GPU_HOST_PIXEL_STORE; i++)
        glGetIntegerv(k_pixel_store[i], &s->pixel_store[i]);
}

/* GL's initial values, with the renderer's zero-to-one clip depth; the viewport is the renderer's
 * to set (every draw does). Unit 0 stays active (saving switched to it). */
static void set_defaults(const sw__gpu_host_state *s)
{
    glBindVertexArray(0);
    glUseProgram(0);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, 0);
    for (int t = 0; t < 2; t++)
        for (GLuint i = 0; i < (GLuint)s->n_indexed[t]; i++)
            glBindBufferBase(k_indexed[t][0], i, 0);
    for (int i = 0; i < SW__GPU_HOST_BUFFERS; i++)
        glBindBuffer(k_buffers[i][0], 0);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    for (int i = 0; i < SW__GPU_HOST_TEXTURES; i++)
        glBindTexture(k_textures[i][0], 0);
    glBindSampler(0, 0);
    for (int i = 0; i < SW__GPU_HOST_CAPS; i++)
        (cap_default(k_caps[i]) ? glEnable : glDisable)(k_caps[i]);
    glBlendFuncSeparate(GL_ONE, GL_ZERO, GL_ONE, GL_ZERO);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
    glBlendColor(0, 0, 0, 0);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glDepthRange(0.0, 1.0);
    glStencilFuncSeparate(GL_FRONT_AND_BACK, GL_ALWAYS, 0, ~0u);
    glStencilOpSeparate(GL_FRONT_AND_BACK, GL_KEEP, GL_KEEP, GL_KEEP);
    glStencilMaskSeparate(GL_FRONT_AND_BACK, ~0u);
    glClearStencil(0);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0, 0, 0, 0);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glPolygonOffset(0, 0);
    glLineWidth(1.0f);
    glPointSize(1.0f);
    glProvokingVertex(GL_LAST_VERTEX_CONVENTION);
    glPrimitiveRestartIndex(0);
    glPatchParameteri(GL_PATCH_VERTICES, 3);
    glLogicOp(GL_COPY);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    for (int i = 0; i < SW__GPU_HOST_PIXEL_STORE; i++)
        glPixelStorei(k_pixel_store[i], pixel_store_default(k_pixel_store[i]));
}

void sw__gpu_host_state_save(sw__gpu_host_state *s)
{
    memset(s, 0, sizeof *s);
    save_bindings(s);
    save_fixed_function(s);
    set_defaults(s);
}

/* A saved name, or 0 when the renderer deleted that object meanwhile (the host may have bound one
 * of the renderer's: a tool showing the trim atlas binds its texture, which the atlas replaces
 * when it grows or shrinks). GL unbinds a deleted object itself; binding its name again would be
 * GL_INVALID_OPERATION. */
static GLuint alive_texture(GLint name)
{
    return name && glIsTexture((GLuint)name) ? (GLuint)name : 0;
}

static GLuint alive_buffer(GLint name)
{
    return name && glIsBuffer((GLuint)name) ? (GLuint)name : 0;
}

static void restore_bindings(const sw__gpu_host_state *s)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)s->draw_fb);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)s->read_fb);
    glBindRenderbuffer(GL_RENDERBUFFER, (GLuint)s->renderbuffer);
    glUseProgram((GLuint)s->program);
    /* The generic transform-feedback binding is the object's: bound after it. */
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, (GLuint)s->xfb_object);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, alive_buffer(s->xfb_buffer));
    /* The element buffer is the vertex array's: bound after it. */
    glBindVertexArray((GLuint)s->vao);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, alive_buffer(s->element_buffer));
    /* Indexed first: binding a range also sets the generic binding point. */
    for (int t = 0; t < 2; t++)
        for (GLuint i = 0; i < (GLuint)s->n_indexed[t]; i++) {
            const sw__gpu_host_range *r = &s->indexed[t][i];
            const GLuint buffer = alive_buffer((GLint)r->buffer);
            if (buffer && r->size > 0)
                glBindBufferRange(k_indexed[t][0], i, buffer, (GLintptr)r->start,
                                  (GLsizeiptr)r->size);
            else
                glBindBufferBase(k_indexed[t][0], i, buffer);
        }
    for (int i = 0; i < SW__GPU_HOST_BUFFERS; i++)
        glBindBuffer(k_buffers[i][0], alive_buffer(s->buffers[i]));
    glActiveTexture(GL_TEXTURE0);
    for (int i = 0; i < SW__GPU_HOST_TEXTURES; i++)
        glBindTexture(k_textures[i][0], alive_texture(s->textures[i]));
    glBindSampler(0, (GLuint)s->sampler);
    glActiveTexture((GLenum)s->active_texture);
}

static void restore_fixed_function(const sw__gpu_host_state *s)
{
    for (int i = 0; i < SW__GPU_HOST_CAPS; i++)
        (s->caps[i] ? glEnable : glDisable)(k_caps[i]);
    glViewport(s->viewport[0], s->viewport[1], s->viewport[2], s->viewport[3]);
    glScissor(s->scissor[0], s->scissor[1], s->scissor[2], s->scissor[3]);
    glBlendFuncSeparate((GLenum)s->blend[0], (GLenum)s->blend[1], (GLenum)s->blend[2],
                        (GLenum)s->blend[3]);
    glBlendEquationSeparate((GLenum)s->blend[4], (GLenum)s->blend[5]);
    glBlendColor(s->blend_color[0], s->blend_color[1], s->blend_color[2], s->blend_color[3]);
    glDepthFunc((GLenum)s->depth_func);
    glDepthMask(s->depth_mask);
    glClearDepth(s->depth_clear);
    glDepthRange(s->depth_range[0], s->depth_range[1]);
    static const GLenum faces[2] = {GL_FRONT, GL_BACK};
    for (int f = 0; f < 2; f++) {
        const GLint *st = s->stencil[f];
        glStencilFuncSeparate(faces[f], (GLenum)st[0], st[1], (GLuint)st[2]);
        glStencilOpSeparate(faces[f], (GLenum)st[3], (GLenum)st[4], (GLenum)st[5]);
        glStencilMaskSeparate(faces[f], (GLuint)st[6]);
    }
    glClearStencil(s->stencil_clear);
    glColorMask(s->color_mask[0], s->color_mask[1], s->color_mask[2], s->color_mask[3]);
    glClearColor(s->color_clear[0], s->color_clear[1], s->color_clear[2], s->color_clear[3]);
    glCullFace((GLenum)s->cull_face);
    glFrontFace((GLenum)s->front_face);
    glPolygonMode(GL_FRONT_AND_BACK, (GLenum)s->polygon_mode);
    glPolygonOffset(s->polygon_offset[0], s->polygon_offset[1]);
    glLineWidth(s->line_width);
    glPointSize(s->point_size);
    glProvokingVertex((GLenum)s->provoking_vertex);
    glPrimitiveRestartIndex((GLuint)s->restart_index);
    glPatchParameteri(GL_PATCH_VERTICES, s->patch_vertices);
    glLogicOp((GLenum)s->logic_op);
    glClipControl((GLenum)s->clip_origin, (GLenum)s->clip_depth_mode);
    for (int i = 0; i < SW__GPU_HOST_PIXEL_STORE; i++)
        glPixelStorei(k_pixel_store[i], s->pixel_store[i]);
}

void sw__gpu_host_state_restore(const sw__gpu_host_state *s)
{
    restore_bindings(s);
    restore_fixed_function(s);
}

int sw__gpu_context_adopted(const sw_gpu_context *ctx)
{
    return ctx->egl_context == NULL;
}

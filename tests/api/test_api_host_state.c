/* SPDX-License-Identifier: MIT */
/* tests/api: drawing into the host's GL context (sw_renderer_desc.use_current_context,
 * sw_frame_desc.present) leaves every piece of the host's GL state as it was.
 *
 *   test_api_host_state SCENE WORKDIR
 *
 * The test is the host: it makes its own EGL context (surfaceless, 4.5 core), binds its own
 * objects everywhere (program, vertex array with an element buffer and attributes, every buffer
 * target, indexed uniform and shader storage ranges, a transform feedback object and its ranges,
 * renderbuffer, draw and read framebuffers, textures on units 0 and 3, a sampler on unit 0, active
 * unit 3) and sets every other piece of state the renderer could touch to a value that is not GL's
 * default. It snapshots all of it with its own list of glGet queries (independent of the
 * library's), then creates a renderer in that context, draws (presenting into its framebuffer, also
 * by depth, plain, wireframe, static LODs, a split frame) and destroys it, comparing the snapshot
 * after each call: any one value not restored fails, by name. The frame presented under the host's
 * odd state (scissor, colour mask, pixel store, depth range, polygon mode, clip control, sampler,
 * ...) must equal, pixel for pixel, the one presented under GL's defaults, and must not be empty.
 */
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>
#include <splinewalk/splinewalk.h>

#define SW_API_TEST_HOST_CONTEXT
#include "api_test_expect.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPECT_OK(call)                                                                            \
    do {                                                                                           \
        sw_status st_ = {0};                                                                       \
        (void)st_;                                                                                 \
        sw_result got_ = (call);                                                                   \
        if (got_ != SW_OK) {                                                                       \
            fprintf(stderr, "line %d: %s returned %s\n", __LINE__, #call, sw_result_id_str(got_)); \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

enum { W = 200, H = 150 };

/* ---- the host's context ------------------------------------------------------------------------
 */

typedef struct host_objects {
    GLuint fbo_draw, fbo_read, rb[3], program, vao, buffers[12], tex[4], sampler, xfb;
} host_objects;

static void make_host_objects(host_objects *o)
{
    glGenRenderbuffers(3, o->rb);
    glBindRenderbuffer(GL_RENDERBUFFER, o->rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindRenderbuffer(GL_RENDERBUFFER, o->rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, W, H);
    glBindRenderbuffer(GL_RENDERBUFFER, o->rb[2]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 16, 16);
    glGenFramebuffers(1, &o->fbo_draw);
    glBindFramebuffer(GL_FRAMEBUFFER, o->fbo_draw);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, o->rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                              o->rb[1]);
    glGenFramebuffers(1, &o->fbo_read);
    glBindFramebuffer(GL_FRAMEBUFFER, o->fbo_read);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, o->rb[2]);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    GLuint vs = sw_test_compile_shader(GL_VERTEX_SHADER,
                                       "#version 450 core\nlayout(location=0) in vec4 p;\n"
                                       "void main() { gl_Position = p; }\n");
    GLuint fs = sw_test_compile_shader(GL_FRAGMENT_SHADER, "#version 450 core\nout vec4 c;\n"
                                                           "void main() { c = vec4(1); }\n");
    o->program = glCreateProgram();
    glAttachShader(o->program, vs);
    glAttachShader(o->program, fs);
    glLinkProgram(o->program);
    glDeleteShader(vs);
    glDeleteShader(fs);

    glGenBuffers(12, o->buffers);
    for (int i = 0; i < 12; i++) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, o->buffers[i]);
        glBufferData(GL_COPY_WRITE_BUFFER, 4096, NULL, GL_STATIC_DRAW);
    }
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    glGenTransformFeedbacks(1, &o->xfb);
    glGenVertexArrays(1, &o->vao);
    glBindVertexArray(o->vao);
    glBindBuffer(GL_ARRAY_BUFFER, o->buffers[0]);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 16, (void *)0);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, 8, (void *)64);
    glEnableVertexAttribArray(3);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, o->buffers[1]);

    glGenTextures(4, o->tex);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, o->tex[0]);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
    glBindTexture(GL_TEXTURE_2D_ARRAY, o->tex[1]);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA8, 4, 4, 2);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, o->tex[2]);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
    glBindTexture(GL_TEXTURE_2D_ARRAY, o->tex[3]);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA8, 4, 4, 2);
    glGenSamplers(1, &o->sampler);
    glSamplerParameteri(o->sampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glBindSampler(0, o->sampler);
}

/* Every piece of state away from its default (and from what the renderer sets). */
static void set_odd_state(const host_objects *o)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o->fbo_draw);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, o->fbo_read);
    glBindRenderbuffer(GL_RENDERBUFFER, o->rb[2]);
    glUseProgram(o->program);
    glBindVertexArray(o->vao);
    glBindBufferRange(GL_UNIFORM_BUFFER, 0, o->buffers[2], 256, 512);
    glBindBufferRange(GL_UNIFORM_BUFFER, 2, o->buffers[3], 0, 1024);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, o->buffers[4], 256, 768);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, o->buffers[5]);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, o->buffers[6], 512, 256);
    glBindBuffer(GL_ARRAY_BUFFER, o->buffers[7]);
    glBindBuffer(GL_UNIFORM_BUFFER, o->buffers[8]);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, o->buffers[9]);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, o->buffers[10]);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, o->buffers[11]);
    glBindBuffer(GL_COPY_READ_BUFFER, o->buffers[2]);
    glBindBuffer(GL_COPY_WRITE_BUFFER, o->buffers[3]);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, o->buffers[4]);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, o->buffers[5]);
    /* a transform feedback object of the host's, a range at its binding 0, another buffer at
     * its generic binding (the renderer captures kept patch grids with one of its own) */
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, o->xfb);
    glBindBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, o->buffers[6], 256, 512);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, o->buffers[7]);
    glActiveTexture(GL_TEXTURE3);

    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_DST_ALPHA);
    glBlendEquationSeparate(GL_FUNC_SUBTRACT, GL_MAX);
    glBlendColor(0.25f, 0.5f, 0.75f, 0.125f);
    glDisable(GL_DEPTH_TEST); /* the renderer enables it */
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glDepthRange(0.25, 0.75);
    glClearDepth(0.375);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    glFrontFace(GL_CW);
    glEnable(GL_SCISSOR_TEST);
    glScissor(10, 20, 30, 40);
    glViewport(5, 6, 70, 80);
    glEnable(GL_STENCIL_TEST);
    glStencilFuncSeparate(GL_FRONT, GL_EQUAL, 3, 0x0f);
    glStencilFuncSeparate(GL_BACK, GL_NOTEQUAL, 5, 0xf0);
    glStencilOpSeparate(GL_FRONT, GL_INCR, GL_DECR, GL_INVERT);
    glStencilOpSeparate(GL_BACK, GL_REPLACE, GL_ZERO, GL_INCR_WRAP);
    glStencilMaskSeparate(GL_FRONT, 0x3c);
    glStencilMaskSeparate(GL_BACK, 0xc3);
    glClearStencil(7);
    glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
    glClearColor(0.125f, 0.25f, 0.375f, 0.5f);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.5f);
    glLineWidth(1.0f); /* llvmpipe core: wide lines need not exist; the renderer sets 1 */
    glPointSize(3.0f);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_PRIMITIVE_RESTART);
    glPrimitiveRestartIndex(7);
    glEnable(GL_COLOR_LOGIC_OP); /* the renderer toggles it for trim textures */
    glLogicOp(GL_XOR);
    glProvokingVertex(GL_FIRST_VERTEX_CONVENTION);
    glPatchParameteri(GL_PATCH_VERTICES, 4);
    glDisable(GL_DITHER);
    glDisable(GL_MULTISAMPLE);
    glEnable(GL_DEPTH_CLAMP);
    glEnable(GL_CLIP_DISTANCE2);
    glEnable(GL_FRAMEBUFFER_SRGB);
    glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glPixelStorei(GL_PACK_ALIGNMENT, 2);
    glPixelStorei(GL_PACK_ROW_LENGTH, 33);
    glPixelStorei(GL_PACK_SKIP_ROWS, 1);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 2);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 8);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 37);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 3);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 4);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 9);
    glPixelStorei(GL_UNPACK_SKIP_IMAGES, 1);
}

/* ---- the snapshot: the test's own list of queries ----------------------------------------------
 */
enum kind { INT, FLOAT, DOUBLE, BOOL, CAP, INT_I, INT64_I, UNIT_INT, VAO_ATTRIB };
typedef struct query {
    const char *name;
    enum kind kind;
    GLenum pname;
    GLuint index; /* INT_I / INT64_I: binding index; UNIT_INT: texture unit; VAO_ATTRIB: attrib */
    int count;    /* values */
} query;

#define Q(kind, pname, index, count)                                                               \
    {                                                                                              \
#pname "[" #index "]", kind, pname, index, count                                           \
    }
static const query k_queries[] = {
    Q(INT, GL_DRAW_FRAMEBUFFER_BINDING, 0, 1),
    Q(INT, GL_READ_FRAMEBUFFER_BINDING, 0, 1),
    Q(INT, GL_RENDERBUFFER_BINDING, 0, 1),
    Q(INT, GL_CURRENT_PROGRAM, 0, 1),
    Q(INT, GL_VERTEX_ARRAY_BINDING, 0, 1),
    Q(INT, GL_ELEMENT_ARRAY_BUFFER_BINDING, 0, 1),
    Q(INT, GL_ARRAY_BUFFER_BINDING, 0, 1),
    Q(INT, GL_UNIFORM_BUFFER_BINDING, 0, 1),
    Q(INT, GL_SHADER_STORAGE_BUFFER_BINDING, 0, 1),
    Q(INT, GL_PIXEL_PACK_BUFFER_BINDING, 0, 1),
    Q(INT, GL_PIXEL_UNPACK_BUFFER_BINDING, 0, 1),
    Q(INT, GL_COPY_READ_BUFFER_BINDING, 0, 1),
    Q(INT, GL_COPY_WRITE_BUFFER_BINDING, 0, 1),
    Q(INT, GL_DRAW_INDIRECT_BUFFER_BINDING, 0, 1),
    Q(INT, GL_DISPATCH_INDIRECT_BUFFER_BINDING, 0, 1),
    Q(INT, GL_TRANSFORM_FEEDBACK_BINDING, 0, 1),
    Q(INT, GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, 0, 1),
    Q(INT_I, GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, 0, 1),
    Q(INT64_I, GL_TRANSFORM_FEEDBACK_BUFFER_START, 0, 1),
    Q(INT64_I, GL_TRANSFORM_FEEDBACK_BUFFER_SIZE, 0, 1),
    Q(INT_I, GL_UNIFORM_BUFFER_BINDING, 0, 1),
    Q(INT64_I, GL_UNIFORM_BUFFER_START, 0, 1),
    Q(INT64_I, GL_UNIFORM_BUFFER_SIZE, 0, 1),
    Q(INT_I, GL_UNIFORM_BUFFER_BINDING, 2, 1),
    Q(INT64_I, GL_UNIFORM_BUFFER_SIZE, 2, 1),
    Q(INT_I, GL_SHADER_STORAGE_BUFFER_BINDING, 0, 1),
    Q(INT64_I, GL_SHADER_STORAGE_BUFFER_START, 0, 1),
    Q(INT64_I, GL_SHADER_STORAGE_BUFFER_SIZE, 0, 1),
    Q(INT_I, GL_SHADER_STORAGE_BUFFER_BINDING, 1, 1),
    Q(INT_I, GL_SHADER_STORAGE_BUFFER_BINDING, 5, 1),
    Q(INT64_I, GL_SHADER_STORAGE_BUFFER_START, 5, 1),
    Q(INT64_I, GL_SHADER_STORAGE_BUFFER_SIZE, 5, 1),
    Q(INT, GL_ACTIVE_TEXTURE, 0, 1),
    Q(UNIT_INT, GL_TEXTURE_BINDING_2D, 0, 1),
    Q(UNIT_INT, GL_TEXTURE_BINDING_2D_ARRAY, 0, 1),
    Q(UNIT_INT, GL_SAMPLER_BINDING, 0, 1),
    Q(UNIT_INT, GL_TEXTURE_BINDING_2D, 3, 1),
    Q(UNIT_INT, GL_TEXTURE_BINDING_2D_ARRAY, 3, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_ENABLED, 0, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_ENABLED, 1, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_ENABLED, 2, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_ENABLED, 3, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_SIZE, 3, 1),
    Q(VAO_ATTRIB, GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING, 0, 1),
    Q(CAP, GL_BLEND, 0, 1),
    Q(CAP, GL_CULL_FACE, 0, 1),
    Q(CAP, GL_DEPTH_TEST, 0, 1),
    Q(CAP, GL_SCISSOR_TEST, 0, 1),
    Q(CAP, GL_STENCIL_TEST, 0, 1),
    Q(CAP, GL_COLOR_LOGIC_OP, 0, 1),
    Q(CAP, GL_POLYGON_OFFSET_FILL, 0, 1),
    Q(CAP, GL_PRIMITIVE_RESTART, 0, 1),
    Q(CAP, GL_PROGRAM_POINT_SIZE, 0, 1),
    Q(CAP, GL_DITHER, 0, 1),
    Q(CAP, GL_DEPTH_CLAMP, 0, 1),
    Q(CAP, GL_CLIP_DISTANCE2, 0, 1),
    Q(CAP, GL_FRAMEBUFFER_SRGB, 0, 1),
    Q(CAP, GL_SAMPLE_ALPHA_TO_COVERAGE, 0, 1),
    Q(CAP, GL_TEXTURE_CUBE_MAP_SEAMLESS, 0, 1),
    Q(CAP, GL_RASTERIZER_DISCARD, 0, 1),
    Q(CAP, GL_MULTISAMPLE, 0, 1),
    Q(INT, GL_BLEND_SRC_RGB, 0, 1),
    Q(INT, GL_BLEND_DST_RGB, 0, 1),
    Q(INT, GL_BLEND_SRC_ALPHA, 0, 1),
    Q(INT, GL_BLEND_DST_ALPHA, 0, 1),
    Q(INT, GL_BLEND_EQUATION_RGB, 0, 1),
    Q(INT, GL_BLEND_EQUATION_ALPHA, 0, 1),
    Q(FLOAT, GL_BLEND_COLOR, 0, 4),
    Q(INT, GL_DEPTH_FUNC, 0, 1),
    Q(BOOL, GL_DEPTH_WRITEMASK, 0, 1),
    Q(DOUBLE, GL_DEPTH_RANGE, 0, 2),
    Q(DOUBLE, GL_DEPTH_CLEAR_VALUE, 0, 1),
    Q(INT, GL_CULL_FACE_MODE, 0, 1),
    Q(INT, GL_FRONT_FACE, 0, 1),
    Q(INT, GL_SCISSOR_BOX, 0, 4),
    Q(INT, GL_VIEWPORT, 0, 4),
    Q(INT, GL_STENCIL_FUNC, 0, 1),
    Q(INT, GL_STENCIL_REF, 0, 1),
    Q(INT, GL_STENCIL_VALUE_MASK, 0, 1),
    Q(INT, GL_STENCIL_FAIL, 0, 1),
    Q(INT, GL_STENCIL_PASS_DEPTH_FAIL, 0, 1),
    Q(INT, GL_STENCIL_PASS_DEPTH_PASS, 0, 1),
    Q(INT, GL_STENCIL_WRITEMASK, 0, 1),
    Q(INT, GL_STENCIL_BACK_FUNC, 0, 1),
    Q(INT, GL_STENCIL_BACK_REF, 0, 1),
    Q(INT, GL_STENCIL_BACK_VALUE_MASK, 0, 1),
    Q(INT, GL_STENCIL_BACK_FAIL, 0, 1),
    Q(INT, GL_STENCIL_BACK_PASS_DEPTH_FAIL, 0, 1),
    Q(INT, GL_STENCIL_BACK_PASS_DEPTH_PASS, 0, 1),
    Q(INT, GL_STENCIL_BACK_WRITEMASK, 0, 1),
    Q(INT, GL_STENCIL_CLEAR_VALUE, 0, 1),
    Q(BOOL, GL_COLOR_WRITEMASK, 0, 4),
    Q(FLOAT, GL_COLOR_CLEAR_VALUE, 0, 4),
    Q(INT, GL_POLYGON_MODE, 0, 1),
    Q(FLOAT, GL_POLYGON_OFFSET_FACTOR, 0, 1),
    Q(FLOAT, GL_POLYGON_OFFSET_UNITS, 0, 1),
    Q(FLOAT, GL_LINE_WIDTH, 0, 1),
    Q(FLOAT, GL_POINT_SIZE, 0, 1),
    Q(INT, GL_PRIMITIVE_RESTART_INDEX, 0, 1),
    Q(INT, GL_LOGIC_OP_MODE, 0, 1),
    Q(INT, GL_PROVOKING_VERTEX, 0, 1),
    Q(INT, GL_PATCH_VERTICES, 0, 1),
    Q(INT, GL_CLIP_ORIGIN, 0, 1),
    Q(INT, GL_CLIP_DEPTH_MODE, 0, 1),
    Q(INT, GL_PACK_ALIGNMENT, 0, 1),
    Q(INT, GL_PACK_ROW_LENGTH, 0, 1),
    Q(INT, GL_PACK_SKIP_ROWS, 0, 1),
    Q(INT, GL_PACK_SKIP_PIXELS, 0, 1),
    Q(INT, GL_UNPACK_ALIGNMENT, 0, 1),
    Q(INT, GL_UNPACK_ROW_LENGTH, 0, 1),
    Q(INT, GL_UNPACK_SKIP_ROWS, 0, 1),
    Q(INT, GL_UNPACK_SKIP_PIXELS, 0, 1),
    Q(INT, GL_UNPACK_IMAGE_HEIGHT, 0, 1),
    Q(INT, GL_UNPACK_SKIP_IMAGES, 0, 1),
};
#define N_QUERIES (sizeof k_queries / sizeof k_queries[0])

typedef struct snapshot {
    double v[N_QUERIES][4];
} snapshot;

static void take(snapshot *s)
{
    memset(s, 0, sizeof *s);
    for (size_t q = 0; q < N_QUERIES; q++) {
        const query *k = &k_queries[q];
        GLint i4[4] = {0};
        GLint64 i64 = 0;
        GLfloat f4[4] = {0};
        GLdouble d4[4] = {0};
        GLboolean b4[4] = {0};
        switch (k->kind) {
        case INT:
            glGetIntegerv(k->pname, i4);
            break;
        case FLOAT:
            glGetFloatv(k->pname, f4);
            break;
        case DOUBLE:
            glGetDoublev(k->pname, d4);
            break;
        case BOOL:
            glGetBooleanv(k->pname, b4);
            break;
        case CAP:
            i4[0] = glIsEnabled(k->pname);
            break;
        case INT_I:
            glGetIntegeri_v(k->pname, k->index, i4);
            break;
        case INT64_I:
            glGetInteger64i_v(k->pname, k->index, &i64);
            i4[0] = (GLint)i64;
            break;
        case UNIT_INT: {
            GLint active;
            glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
            glActiveTexture(GL_TEXTURE0 + k->index);
            glGetIntegerv(k->pname, i4);
            glActiveTexture((GLenum)active);
            break;
        }
        case VAO_ATTRIB:
            glGetVertexAttribiv(k->index, k->pname, i4);
            break;
        }
        for (int c = 0; c < k->count; c++)
            s->v[q][c] = k->kind == FLOAT    ? f4[c]
                         : k->kind == DOUBLE ? d4[c]
                         : k->kind == BOOL   ? b4[c]
                                             : i4[c];
    }
}

/* Every value as before; returns how many differ (and names them). */
static int compare(const snapshot *before, const snapshot *after, const char *when)
{
    int differ = 0;
    for (size_t q = 0; q < N_QUERIES; q++)
        for (int c = 0; c < k_queries[q].count; c++)
            if (before->v[q][c] != after->v[q][c]) {
                fprintf(stderr, "after %s: %s value %d is %g, was %g\n", when, k_queries[q].name, c,
                        after->v[q][c], before->v[q][c]);
                differ++;
            }
    g_failures += differ;
    return differ;
}

/* Values the host's state moves; names the queries it leaves as they were. */
static int count_changed_from(const snapshot *a, const snapshot *b)
{
    int n = 0;
    for (size_t q = 0; q < N_QUERIES; q++) {
        int moved = 0;
        for (int c = 0; c < k_queries[q].count; c++)
            moved += a->v[q][c] != b->v[q][c];
        if (!moved)
            printf("  not moved by the host: %s\n", k_queries[q].name);
        n += moved;
    }
    return n;
}

/* The host framebuffer's pixels, read with a known pack state that is put back afterwards. */
static void read_host_pixels(const host_objects *o, unsigned char *rgba)
{
    GLint read_fb, pack_buffer, pack[4];
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fb);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pack_buffer);
    const GLenum names[4] = {GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_SKIP_ROWS,
                             GL_PACK_SKIP_PIXELS};
    for (int i = 0; i < 4; i++)
        glGetIntegerv(names[i], &pack[i]);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, o->fbo_draw);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    for (int i = 0; i < 4; i++)
        glPixelStorei(names[i], pack[i]);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, (GLuint)pack_buffer);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)read_fb);
}

/* Magenta everywhere (the clear obeys scissor and colour mask: both opened, then put back). */
static void clear_host_framebuffer(const host_objects *o)
{
    GLint draw_fb;
    GLboolean mask[4], scissor = glIsEnabled(GL_SCISSOR_TEST);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
    glGetBooleanv(GL_COLOR_WRITEMASK, mask);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o->fbo_draw);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const GLfloat magenta[4] = {1, 0, 1, 1};
    glClearBufferfv(GL_COLOR, 0, magenta);
    glColorMask(mask[0], mask[1], mask[2], mask[3]);
    (scissor ? glEnable : glDisable)(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)draw_fb);
}

int main(int argc, char **argv)
{
    (void)sw_import_install(), (void)sw_lod_build_install(); /* CAD files, static LODs */
    if (argc != 3) {
        fprintf(stderr, "usage: %s SCENE WORKDIR\n", argv[0]);
        return 2;
    }
    if (sw_test_host_context() != 0) {
        fprintf(stderr, "no EGL surfaceless 4.5 core context for the host\n");
        return 1;
    }
    host_objects o;
    make_host_objects(&o);
    EXPECT(glGetError() == GL_NO_ERROR);

    sw_scene scene = {0};
    sw_scene_load_desc load = {.path = argv[1]};
    EXPECT_OK(sw_scene_load(&load, &scene, NULL));
    sw_renderer renderer = {0};
    sw_renderer_desc rdesc = {.worker_threads = 2, .use_current_context = 1};
    sw_status status = {0};
    sw_result created = sw_renderer_create(&rdesc, &renderer, &status);
    if (created != SW_OK) {
        fprintf(stderr, "renderer: %s\n", status.message);
        return 1;
    }
    sw_frame_desc frame = {.scene = scene, .width = W, .height = H, .present = 1};

    /* The reference: presented with the host's state at GL's defaults (only its framebuffers
     * bound), scissor off so that the clear reaches every pixel. */
    unsigned char *reference = malloc((size_t)W * H * 4), *odd = malloc((size_t)W * H * 4);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o.fbo_draw);
    clear_host_framebuffer(&o);
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    read_host_pixels(&o, reference);
    size_t drawn = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        drawn += memcmp(reference + 4 * i, "\xff\x00\xff\xff", 4) != 0;
    EXPECT(drawn == (size_t)W * H); /* the presented frame covers the framebuffer */
    size_t unlike_corner = 0;       /* the scene is in the picture, not only the background */
    for (size_t i = 0; i < (size_t)W * H; i++)
        unlike_corner += memcmp(reference + 4 * i, reference, 4) != 0;
    EXPECT(unlike_corner > (size_t)W * H / 20);

    snapshot plain, before, after;
    take(&plain);
    set_odd_state(&o);
    EXPECT(glGetError() == GL_NO_ERROR);
    take(&before);
    const int moved = count_changed_from(&plain, &before);
    printf("the host's state moves %d of the queried values away from GL's defaults\n", moved);
    EXPECT(moved >= 100);

    /* Present under the odd state: scissor, colour mask, clip control, depth range, polygon
     * mode, sampler, pixel store and the rest must not change the picture. */
    clear_host_framebuffer(&o);
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "a presenting frame");
    read_host_pixels(&o, odd);
    size_t differ = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++)
        differ += reference[i] != odd[i];
    if (differ)
        fprintf(stderr, "the frame presented under the host's state differs in %zu bytes\n",
                differ);
    EXPECT(differ == 0);
    frame.present_depth = 1; /* the depth-compositing pass (its own program, units 0 and 1) */
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "a frame presented by depth");
    frame.present_depth = 0;

    frame.present = 0;
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "a frame that does not present");
    frame.wireframe = 1;
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "a wireframe frame");
    frame.wireframe = 0;
    frame.static_lods = 1;
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "a static-LOD frame");
    frame.static_lods = 0;
    frame.eval_exact = 1;
    EXPECT_OK(sw_renderer_draw(renderer, &frame, NULL, NULL));
    compare(&before, (take(&after), &after), "an exact-evaluation frame");
    frame.eval_exact = 0;
    frame.width = 2 * W; /* a new render target size */
    frame.walkthrough = 1;
    EXPECT_OK(sw_renderer_prepare(renderer, &frame, NULL));
    EXPECT_OK(sw_renderer_submit(renderer, NULL, NULL));
    compare(&before, (take(&after), &after), "a split walkthrough frame");
    EXPECT(sw_renderer_destroy(renderer) == SW_OK);
    compare(&before, (take(&after), &after), "sw_renderer_destroy");

    /* A renderer created under the odd state leaves it too. */
    EXPECT_OK(sw_renderer_create(&rdesc, &renderer, NULL));
    compare(&before, (take(&after), &after), "sw_renderer_create");
    EXPECT(sw_renderer_destroy(renderer) == SW_OK);
    EXPECT(sw_scene_destroy(scene) == SW_OK);
    EXPECT(glGetError() == GL_NO_ERROR);
    printf("%zu GL state values compared after 9 calls; presented frame %dx%d equal to the one "
           "under GL's defaults (%zu bytes differ)\n",
           N_QUERIES, W, H, differ);
    free(reference);
    free(odd);
    if (g_failures) {
        fprintf(stderr, "%d failure(s)\n", g_failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}

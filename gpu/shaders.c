/* SPDX-License-Identifier: MIT */
/* The GLSL programs, from the files in gpu/glsl/ (embedded at build time by
 * gpu/glsl/embed_glsl.cmake into sw_glsl_sources.h): the mesh program (grids of Bézier patches, fat
 * borders and plain triangles: reversed-Z projection of camera-relative positions, Lambert +
 * headlight shading, and the trim-texture lookup of Guthe et al. 2005 §4.3 that discards fragments
 * outside the trim region, read from the trim atlas of §4.4); the Bézier evaluation program (§4.2)
 * and the exact program that evaluates NURBS of any degree from knot vectors in the vertex shader
 * (eval_exact), both sharing the surface fragment stage; the trim program that draws fans and
 * crack-filling lines into a trim texture (§4); and the present program that composites the frame
 * into a host's framebuffer by depth. Each file says what its stage does. */
#include "sw_glsl_sources.h"
#include "sw_curves.h"
#include "sw_gpu_internal.h"
#include "sw_status_util.h"

#include <GL/glcorearb.h>
#include <stdio.h>
#include <string.h>

static const char *const k_mesh_vs = sw_glsl_mesh_vert;
/* the surface fragment stage in four parts (surface_interface.frag.glsl says why) */
static const char *const k_surface_fs_interface = sw_glsl_surface_interface_frag;
static const char *const k_surface_fs_trim = sw_glsl_surface_trim_frag;
static const char *const k_surface_fs_default_shade = sw_glsl_surface_shade_frag;
static const char *const k_surface_fs_main = sw_glsl_surface_main_frag;
static const char *const k_surface_fs_main_untrimmed = sw_glsl_surface_main_untrimmed_frag;
static const char *const k_eval_vs = sw_glsl_eval_vert;
static const char *const k_exact_vs = sw_glsl_exact_vert;
static const char *const k_grid_vs = sw_glsl_grid_vert;
static const char *const k_trim_vs = sw_glsl_trim_vert;
static const char *const k_trim_fs = sw_glsl_trim_frag;
static const char *const k_present_vs = sw_glsl_present_vert;
static const char *const k_present_fs = sw_glsl_present_frag;

/* Compiles a shader from n source strings; fails with `fail`, the message naming `what`. */
static sw_result compile(GLenum type, const char *const *src, GLsizei n, const char *what,
                         sw_result fail, GLuint *out, sw_status *status)
{
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, n, src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        return sw__fail(status, fail, "%s does not compile: %s", what, log);
    }
    *out = sh;
    return SW_OK;
}

/* Links program p (its shaders attached; vertex shader v deleted here) into *out, or deletes it
 * and fails with `fail` naming `what`. */
static sw_result link_checked(GLuint p, GLuint v, const char *what, sw_result fail, GLuint *out,
                              sw_status *status)
{
    glLinkProgram(p);
    glDeleteShader(v);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        return sw__fail(status, fail, "program %s does not link: %s", what, log);
    }
    *out = p;
    return SW_OK;
}

/* Links a vertex stage with the surface fragment stage, assembled from its parts around the
 * shading function `shade` (the library's, or a host's: its compile errors are the host's, hence
 * SW_ERR_INVALID_ARGUMENT). */
static sw_result link_parts(const char *vs, const char *const *fs, GLsizei n_fs, const char *what,
                            sw_result fail, GLuint *out, sw_status *status)
{
    GLuint v = 0, f = 0;
    char label[128];
    snprintf(label, sizeof label, "shader %s", what);
    sw_result r = compile(GL_VERTEX_SHADER, &vs, 1, label, SW_ERR_GL, &v, status);
    if (r != SW_OK)
        return r;
    snprintf(label, sizeof label, "fragment shader of %s", what);
    r = compile(GL_FRAGMENT_SHADER, fs, n_fs, label, fail, &f, status);
    if (r != SW_OK) {
        glDeleteShader(v);
        return r;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glDeleteShader(f);
    return link_checked(p, v, what, fail, out, status);
}

sw_result sw__gpu_program_link(const char *vs, const char *fs, const char *what, GLuint *out,
                               sw_status *status)
{
    return link_parts(vs, &fs, 1, what, SW_ERR_GL, out, status);
}

static void locate_uniforms(sw__gpu_surface_program *p)
{
    p->loc_view_proj = glGetUniformLocation(p->prog, "u_view_proj");
    p->loc_trim = glGetUniformLocation(p->prog, "u_trim");
    p->loc_color = glGetUniformLocation(p->prog, "u_color");
    p->loc_trim_rect = glGetUniformLocation(p->prog, "u_trim_rect");
    p->loc_trim_layer = glGetUniformLocation(p->prog, "u_trim_layer");
    p->loc_uv_map = glGetUniformLocation(p->prog, "u_uv_map");
    p->loc_model_rot = glGetUniformLocation(p->prog, "u_model_rot");
    p->loc_model_off = glGetUniformLocation(p->prog, "u_model_off");
    p->loc_grid = glGetUniformLocation(p->prog, "u_grid");
    p->loc_base = glGetUniformLocation(p->prog, "u_base");
    p->loc_capture = glGetUniformLocation(p->prog, "u_capture");
}

/* The programs of one trim variant: the vertex stages with the fragment parts `fs` (a host's
 * shading, `grids` 0, has no program of kept grids: its frames evaluate every grid). */
static sw_result link_variant(const char *const fs[4], sw_result fail, sw__gpu_surface_programs *p,
                              int variant, int grids, sw_status *status)
{
    static const char *const k_names[4] = {"mesh", "patch evaluation", "exact evaluation",
                                           "kept grids"};
    const char *const vs[4] = {k_mesh_vs, k_eval_vs, k_exact_vs, k_grid_vs};
    sw__gpu_surface_program *out[4] = {&p->mesh[variant], &p->eval[variant], &p->exact[variant],
                                       &p->grid[variant]};
    for (int k = 0; k < (grids ? 4 : 3); ++k) {
        char name[64];
        snprintf(name, sizeof name, "%s%s", k_names[k],
                 variant == SW__GPU_UNTRIMMED ? " (untrimmed)" : "");
        sw_result r = link_parts(vs[k], fs, 4, name, fail, &out[k]->prog, status);
        if (r != SW_OK)
            return r;
        locate_uniforms(out[k]);
    }
    return SW_OK;
}

/* The surface programs around one shading function, in both trim variants, or (host shading:
 * `both` = 0) the trimmed variant named twice; on failure none is left. */
static sw_result link_surfaces(const char *shade, sw_result fail, int both,
                               sw__gpu_surface_programs *p, sw_status *status)
{
    memset(p, 0, sizeof *p);
    const char *const trimmed[4] = {k_surface_fs_interface, k_surface_fs_trim, shade,
                                    k_surface_fs_main};
    const char *const untrimmed[4] = {k_surface_fs_interface, k_surface_fs_trim, shade,
                                      k_surface_fs_main_untrimmed};
    sw_result r = link_variant(trimmed, fail, p, SW__GPU_TRIMMED, both, status);
    if (r == SW_OK && both)
        r = link_variant(untrimmed, fail, p, SW__GPU_UNTRIMMED, both, status);
    if (r != SW_OK) {
        sw__gpu_shading_free(NULL, p);
        return r;
    }
    if (!both) {
        p->mesh[SW__GPU_UNTRIMMED] = p->mesh[SW__GPU_TRIMMED];
        p->eval[SW__GPU_UNTRIMMED] = p->eval[SW__GPU_TRIMMED];
        p->exact[SW__GPU_UNTRIMMED] = p->exact[SW__GPU_TRIMMED];
        p->grid[SW__GPU_UNTRIMMED] = p->grid[SW__GPU_TRIMMED]; /* none */
    }
    return SW_OK;
}

/* The Bézier evaluation's vertex stage alone, its position, unit normal and st captured by
 * transform feedback in sw__gpu_vertex's layout (resident_grids.c evaluates kept grids with it). */
static sw_result link_grid_eval(sw__gpu_surface_program *out, sw_status *status)
{
    GLuint v = 0;
    sw_result r =
        compile(GL_VERTEX_SHADER, &k_eval_vs, 1, "shader grid evaluation", SW_ERR_GL, &v, status);
    if (r != SW_OK)
        return r;
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    static const char *const k_captured[3] = {"v_rel", "v_nrm", "v_st"};
    glTransformFeedbackVaryings(p, 3, k_captured, GL_INTERLEAVED_ATTRIBS);
    memset(out, 0, sizeof *out);
    r = link_checked(p, v, "grid evaluation", SW_ERR_GL, &out->prog, status);
    if (r == SW_OK)
        locate_uniforms(out);
    return r;
}

sw_result sw__gpu_programs_create(sw_gpu_context *ctx, sw_status *status)
{
    sw_result r = link_surfaces(k_surface_fs_default_shade, SW_ERR_GL, 1, &ctx->surf, status);
    if (r != SW_OK)
        return r;
    r = link_grid_eval(&ctx->prog_grid_eval, status);
    if (r != SW_OK)
        return r;
    r = sw__gpu_program_link(k_trim_vs, k_trim_fs, "trim", &ctx->prog_trim, status);
    if (r != SW_OK)
        return r;
    r = sw__gpu_program_link(k_present_vs, k_present_fs, "present", &ctx->prog_present, status);
    if (r != SW_OK)
        return r;
    return sw__gpu_check(status, "program set-up");
}

void sw__gpu_shading_free(sw_gpu_context *ctx, sw__gpu_surface_programs *p)
{
    (void)ctx; /* the context is current: its programs are deleted with it */
    sw__gpu_surface_program *all[4] = {p->mesh, p->eval, p->exact, p->grid};
    for (int k = 0; k < 4; ++k) {
        glDeleteProgram(all[k][SW__GPU_TRIMMED].prog);
        if (all[k][SW__GPU_UNTRIMMED].prog != all[k][SW__GPU_TRIMMED].prog)
            glDeleteProgram(all[k][SW__GPU_UNTRIMMED].prog);
    }
    memset(p, 0, sizeof *p);
}

void sw__gpu_programs_free(sw_gpu_context *ctx)
{
    sw__gpu_shading_free(ctx, &ctx->surf);
    glDeleteProgram(ctx->prog_grid_eval.prog);
    ctx->prog_grid_eval.prog = 0;
    glDeleteProgram(ctx->prog_trim);
    ctx->prog_trim = 0;
    glDeleteProgram(ctx->prog_present);
    ctx->prog_present = 0;
}

sw_result sw__gpu_shading_create(sw_gpu_context *ctx, const char *shade_source,
                                 sw__gpu_surface_programs *out, sw_status *status)
{
    sw__gpu_make_current(ctx);
    while (glGetError() != GL_NO_ERROR) /* the host's errors before the call are not ours */
        ;
    sw_result r = link_surfaces(shade_source, SW_ERR_INVALID_ARGUMENT, 0, out, status);
    if (r == SW_OK && (r = sw__gpu_check(status, "host shading set-up")) != SW_OK)
        sw__gpu_shading_free(ctx, out);
    return r;
}

/* Indexed by sw_glsl_kind (sw_immediate.h). The vertex stages are whole shaders; the fragment
 * parts are what a host's sw_shade is linked between. */
const char *sw__gpu_glsl_source(int kind)
{
    static const char *const *const k_parts[SW__GPU_GLSL_KINDS] = {
        &k_surface_fs_interface, &k_surface_fs_trim, &k_surface_fs_default_shade,
        &k_surface_fs_main,      &k_eval_vs,         &k_exact_vs,
    };
    return kind >= 0 && kind < SW__GPU_GLSL_KINDS ? *k_parts[kind] : NULL;
}

/* The curve programs' sources (gpu/curves.c links them itself; sw_curves.h). */
const char *sw__gpu_curves_glsl(int which)
{
    static const char *const k_curves[3] = {sw_glsl_curves_vert, sw_glsl_curves_frag,
                                            sw_glsl_curves_composite_frag};
    return which >= 0 && which < 3 ? k_curves[which] : NULL;
}

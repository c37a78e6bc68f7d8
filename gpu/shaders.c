/* GLSL programs, embedded as C strings: the mesh program (grids of Bézier patches and plain
 * triangles: reversed-Z projection of camera-relative positions, Lambert + headlight shading, and
 * the trim-texture lookup of Guthe et al. 2005 §4.3 that discards fragments outside the trim
 * region), and the trim program that draws fans and crack-filling lines into a trim texture (§4).
 */
#include "sw_gpu_internal.h"
#include "sw_status_util.h"

#include <GL/glcorearb.h>

static const char *const k_mesh_vs =
    "#version 430 core\n"
    "layout(location = 0) in vec3 a_pos;\n" /* eye-relative world position */
    "layout(location = 1) in vec3 a_nrm;\n"
    "layout(location = 2) in vec2 a_st;\n"
    "uniform mat4 u_view_proj;\n"
    "out vec3 v_rel;\n"
    "out vec3 v_nrm;\n"
    "out vec2 v_st;\n"
    "void main() {\n"
    "  v_rel = a_pos;\n"
    "  v_nrm = a_nrm;\n"
    "  v_st = a_st;\n"
    "  gl_Position = u_view_proj * vec4(a_pos, 1.0);\n"
    "}\n";

/* The lookup is clamped half a texel inside the texture so that texelFetch never leaves it and a
 * parameter on the box's edge reads the edge texel (PLATFORM.md: trim parity exactness). Shading
 * is two-sided: the headlight lights whichever side faces the eye. Output is gamma-encoded. */
static const char *const k_mesh_fs =
    "#version 430 core\n"
    "in vec3 v_rel;\n"
    "in vec3 v_nrm;\n"
    "in vec2 v_st;\n"
    "uniform vec4 u_color;\n"
    "uniform int u_trimmed;\n"
    "uniform sampler2D u_trim;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "  if (u_trimmed != 0) {\n"
    "    vec2 size = vec2(textureSize(u_trim, 0));\n"
    "    vec2 t = clamp(v_st * size, vec2(0.5), size - vec2(0.5));\n"
    "    if (texelFetch(u_trim, ivec2(t), 0).r < 0.5) discard;\n"
    "  }\n"
    "  vec3 n = v_nrm;\n"
    "  float ln = length(n);\n"
    "  float lambert = 1.0;\n"
    "  if (ln > 0.0) lambert = abs(dot(n / ln, normalize(-v_rel)));\n"
    "  vec3 c = u_color.rgb * (0.2 + 0.8 * lambert);\n"
    "  o_color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), u_color.a);\n"
    "}\n";

static const char *const k_trim_vs = "#version 430 core\n"
                                     "layout(location = 0) in vec2 a_pos;\n"
                                     "void main() { gl_Position = vec4(a_pos, 0.0, 1.0); }\n";

static const char *const k_trim_fs = "#version 430 core\n"
                                     "layout(location = 0) out vec4 o_color;\n"
                                     "void main() { o_color = vec4(1.0); }\n";

static sw_result compile(GLenum type, const char *src, const char *what, GLuint *out,
                         sw_status *status)
{
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        return sw__fail(status, SW_ERR_GL, "shader %s does not compile: %s", what, log);
    }
    *out = sh;
    return SW_OK;
}

static sw_result link(const char *vs, const char *fs, const char *what, GLuint *out,
                      sw_status *status)
{
    GLuint v = 0, f = 0;
    sw_result r = compile(GL_VERTEX_SHADER, vs, what, &v, status);
    if (r != SW_OK)
        return r;
    r = compile(GL_FRAGMENT_SHADER, fs, what, &f, status);
    if (r != SW_OK) {
        glDeleteShader(v);
        return r;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        return sw__fail(status, SW_ERR_GL, "program %s does not link: %s", what, log);
    }
    *out = p;
    return SW_OK;
}

sw_result sw__gpu_programs_create(sw_gpu_context *ctx, sw_status *status)
{
    sw_result r = link(k_mesh_vs, k_mesh_fs, "mesh", &ctx->prog_mesh, status);
    if (r != SW_OK)
        return r;
    r = link(k_trim_vs, k_trim_fs, "trim", &ctx->prog_trim, status);
    if (r != SW_OK)
        return r;
    ctx->loc_view_proj = glGetUniformLocation(ctx->prog_mesh, "u_view_proj");
    ctx->loc_color = glGetUniformLocation(ctx->prog_mesh, "u_color");
    ctx->loc_trimmed = glGetUniformLocation(ctx->prog_mesh, "u_trimmed");
    ctx->loc_trim = glGetUniformLocation(ctx->prog_mesh, "u_trim");
    return sw__gpu_check(status, "program set-up");
}

void sw__gpu_programs_free(sw_gpu_context *ctx)
{
    glDeleteProgram(ctx->prog_mesh);
    glDeleteProgram(ctx->prog_trim);
    ctx->prog_mesh = ctx->prog_trim = 0;
}

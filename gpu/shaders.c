/* GLSL programs, embedded as C strings: the mesh program (grids of Bézier patches and plain
 * triangles: reversed-Z projection of camera-relative positions, Lambert + headlight shading, and
 * the trim-texture lookup of Guthe et al. 2005 §4.3 that discards fragments outside the trim
 * region, read from the trim atlas of §4.4), and the trim program that draws fans and crack-filling
 * lines into a trim texture (§4), and the exact program that evaluates NURBS of any degree from
 * knot vectors in the vertex shader (eval_exact), and the present program that composites the
 * frame into a host's framebuffer by depth.
 */
#include "sw_gpu_internal.h"
#include "sw_status_util.h"

#include <GL/glcorearb.h>
#include <string.h>

static const char *const k_mesh_vs =
    "#version 430 core\n"
    "layout(location = 0) in vec3 a_pos;\n" /* eye-relative world position */
    "layout(location = 1) in vec3 a_nrm;\n"
    "layout(location = 2) in vec2 a_st;\n"
    "uniform mat4 u_view_proj;\n"
    "uniform vec4 u_color;\n"
    "uniform vec4 u_trim_rect;\n"
    "uniform float u_trim_layer;\n"
    "uniform vec4 u_uv_map;\n" /* face parameters of the draw: uv = xy + st * zw */
    "out vec3 v_rel;\n"
    "out vec3 v_nrm;\n"
    "out vec2 v_st;\n"
    "out vec2 v_uv;\n"
    "flat out vec4 v_color;\n"
    "flat out vec4 v_trim_rect;\n"
    "flat out float v_trim_layer;\n"
    "void main() {\n"
    "  v_rel = a_pos;\n"
    "  v_nrm = a_nrm;\n"
    "  v_st = a_st;\n"
    "  v_uv = u_uv_map.xy + a_st * u_uv_map.zw;\n"
    "  v_color = u_color;\n"
    "  v_trim_rect = u_trim_rect;\n"
    "  v_trim_layer = u_trim_layer;\n"
    "  gl_Position = u_view_proj * vec4(a_pos, 1.0);\n"
    "}\n";

/* The fragment stage of every surface program, in four parts linked as one shader (and handed to
 * hosts by sw__gpu_glsl_source, sw_immediate.h): the interface (inputs from the library's vertex
 * stages, the atlas sampler, the output), the trim lookup (§4.3), a shading function sw_shade —
 * the library's (sw_shade_library) or a host's — and main, which trims and then shades.
 * The trim lookup reads the face's rectangle of the atlas (§4.4; rect = x0, y0, w, h in texels,
 * w = 0 untrimmed), clamped half a texel inside the rectangle so that a parameter on the box's
 * edge reads the edge texel and never the gutter (PLATFORM.md: trim parity exactness). The
 * library's shading is two-sided: the headlight lights whichever side faces the eye. Output is
 * gamma-encoded. */
static const char *const k_surface_fs_interface = "#version 430 core\n"
                                                  "in vec3 v_rel;\n"
                                                  "in vec3 v_nrm;\n"
                                                  "in vec2 v_st;\n"
                                                  "in vec2 v_uv;\n"
                                                  "flat in vec4 v_color;\n"
                                                  "flat in vec4 v_trim_rect;\n"
                                                  "flat in float v_trim_layer;\n"
                                                  "uniform sampler2DArray u_trim;\n"
                                                  "layout(location = 0) out vec4 o_color;\n";

static const char *const k_surface_fs_trim =
    "bool sw_trim_inside(sampler2DArray atlas, vec2 st, vec4 rect, float layer) {\n"
    "  if (rect.z <= 0.0) return true;\n"
    "  vec2 size = rect.zw;\n"
    "  vec2 t = rect.xy + clamp(st * size, vec2(0.5), size - vec2(0.5));\n"
    "  return texelFetch(atlas, ivec3(ivec2(t), int(layer)), 0).r >= 0.5;\n"
    "}\n"
    "vec4 sw_shade_library(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  float lambert = 1.0;\n"
    "  if (dot(normal, normal) > 0.0) lambert = abs(dot(normal, normalize(-pos)));\n"
    "  vec3 c = color.rgb * (0.2 + 0.8 * lambert);\n"
    "  return vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), color.a);\n"
    "}\n";

static const char *const k_surface_fs_default_shade =
    "vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {\n"
    "  return sw_shade_library(pos, normal, uv, color);\n"
    "}\n";

static const char *const k_surface_fs_main =
    "void main() {\n"
    "  if (!sw_trim_inside(u_trim, v_st, v_trim_rect, v_trim_layer)) discard;\n"
    "  float ln = length(v_nrm);\n"
    "  o_color = sw_shade(v_rel, ln > 0.0 ? v_nrm / ln : vec3(0.0), v_uv, v_color);\n"
    "}\n";

/* Vertex-shader evaluation of rational Bézier patches of degree <= 3 x 3 on a predefined grid
 * (§4.2): gl_VertexID gives the grid point, gl_InstanceID (plus the class's first record) the patch
 * record. Direct evaluation in the Bernstein basis of the homogeneous control points (eye-relative
 * world, so float keeps sub-pixel accuracy close up) with both first partials, then the division
 * by w; the normal is the cross product of the rational partials (their w^2-scaled forms). A
 * collapsed edge (pole) has no normal there: it is taken just inside the patch, like patch_grid.c.
 * Grid points on a patch's edges get exactly the edge parameter, so patches sharing an edge (and
 * its control points) produce bit-identical positions along it. */
static const char *const k_eval_vs =
    "#version 430 core\n"
    "struct PatchRec {\n"
    "  vec4 st; vec4 trim_map; vec4 trim_rect; vec4 color;\n"
    "  uint cp; int deg_u; int deg_v; float layer;\n"
    "  float nsign; int draw; int level_u; int level_v;\n"
    "  vec4 uv_map;\n"
    "};\n"
    "layout(std430, binding = 0) readonly buffer Patches { PatchRec recs[]; };\n"
    "layout(std430, binding = 1) readonly buffer ControlPoints { vec4 cps[]; };\n"
    "uniform mat4 u_view_proj;\n"
    "uniform ivec2 u_grid;\n"  /* segments in u, v of this draw's class */
    "uniform int u_base;\n"    /* first record of this draw */
    "uniform int u_capture;\n" /* debug: > 0 writes every evaluated vertex to Capture */
    "layout(std430, binding = 5) buffer Capture { uint n_capture; uint pad[3]; vec4 cap[]; };\n"
    "out vec3 v_rel;\n"
    "out vec3 v_nrm;\n"
    "out vec2 v_st;\n"
    "out vec2 v_uv;\n"
    "flat out vec4 v_color;\n"
    "flat out vec4 v_trim_rect;\n"
    "flat out float v_trim_layer;\n"
    "void bern(int p, float s, out float b[4], out float db[4]) {\n"
    "  float r = 1.0 - s;\n"
    "  b[0] = 1.0; b[1] = 0.0; b[2] = 0.0; b[3] = 0.0;\n"
    "  db[0] = 0.0; db[1] = 0.0; db[2] = 0.0; db[3] = 0.0;\n"
    "  if (p == 1) {\n"
    "    b[0] = r; b[1] = s; db[0] = -1.0; db[1] = 1.0;\n"
    "  } else if (p == 2) {\n"
    "    b[0] = r * r; b[1] = 2.0 * r * s; b[2] = s * s;\n"
    "    db[0] = -2.0 * r; db[1] = 2.0 * (r - s); db[2] = 2.0 * s;\n"
    "  } else if (p == 3) {\n"
    "    b[0] = r * r * r; b[1] = 3.0 * r * r * s; b[2] = 3.0 * r * s * s; b[3] = s * s * s;\n"
    "    db[0] = -3.0 * r * r; db[1] = 3.0 * r * (r - 2.0 * s);\n"
    "    db[2] = 3.0 * s * (2.0 * r - s); db[3] = 3.0 * s * s;\n"
    "  }\n"
    "}\n"
    "void eval(PatchRec p, float s, float t, out vec4 h, out vec4 hs, out vec4 ht) {\n"
    "  float bu[4], dbu[4], bv[4], dbv[4];\n"
    "  bern(p.deg_u, s, bu, dbu);\n"
    "  bern(p.deg_v, t, bv, dbv);\n"
    "  h = vec4(0.0); hs = vec4(0.0); ht = vec4(0.0);\n"
    "  uint at = p.cp;\n"
    "  for (int j = 0; j <= p.deg_v; ++j) {\n"
    "    vec4 row = vec4(0.0), rows = vec4(0.0);\n"
    "    for (int i = 0; i <= p.deg_u; ++i, ++at) {\n"
    "      vec4 c = cps[at];\n"
    "      row += bu[i] * c;\n"
    "      rows += dbu[i] * c;\n"
    "    }\n"
    "    h += bv[j] * row; hs += bv[j] * rows; ht += dbv[j] * row;\n"
    "  }\n"
    "}\n"
    "vec3 normal_of(vec4 h, vec4 hs, vec4 ht, out float ok) {\n"
    "  vec3 ds = hs.xyz * h.w - h.xyz * hs.w, dt = ht.xyz * h.w - h.xyz * ht.w;\n"
    "  vec3 n = cross(ds, dt);\n"
    "  ok = length(n) > 1e-6 * length(ds) * length(dt) ? 1.0 : 0.0;\n"
    "  return n;\n"
    "}\n"
    "void main() {\n"
    "  PatchRec p = recs[u_base + gl_InstanceID];\n"
    "  int i = gl_VertexID % (u_grid.x + 1), j = gl_VertexID / (u_grid.x + 1);\n"
    "  float s = i == u_grid.x ? p.st.y : p.st.x + (p.st.y - p.st.x) * float(i) / "
    "float(u_grid.x);\n"
    "  float t = j == u_grid.y ? p.st.w : p.st.z + (p.st.w - p.st.z) * float(j) / "
    "float(u_grid.y);\n"
    "  vec4 h, hs, ht;\n"
    "  eval(p, s, t, h, hs, ht);\n"
    "  float ok;\n"
    "  vec3 n = normal_of(h, hs, ht, ok);\n"
    "  if (ok == 0.0) {\n"
    "    vec4 h2, hs2, ht2;\n"
    "    eval(p, s + 1e-3 * (0.5 - s), t + 1e-3 * (0.5 - t), h2, hs2, ht2);\n"
    "    n = normal_of(h2, hs2, ht2, ok);\n"
    "  }\n"
    "  vec3 pos = h.xyz / h.w;\n"
    "  float ln = length(n);\n"
    "  v_nrm = ln > 0.0 ? p.nsign * n / ln : vec3(0.0);\n"
    "  v_rel = pos;\n"
    "  v_st = vec2(p.trim_map.x + s * p.trim_map.y, p.trim_map.z + t * p.trim_map.w);\n"
    "  v_uv = p.uv_map.xy + vec2(s, t) * p.uv_map.zw;\n"
    "  v_color = p.color;\n"
    "  v_trim_rect = p.trim_rect;\n"
    "  v_trim_layer = p.layer;\n"
    "  if (u_capture > 0) {\n"
    "    uint k = atomicAdd(n_capture, 1u);\n"
    "    if (k < uint(u_capture)) {\n"
    "      cap[2u * k] = vec4(uintBitsToFloat(uint(u_base + gl_InstanceID)), s, t, 0.0);\n"
    "      cap[2u * k + 1u] = vec4(pos, 0.0);\n"
    "    }\n"
    "  }\n"
    "  gl_Position = u_view_proj * vec4(pos, 1.0);\n"
    "}\n";

/* Exact evaluation (eval_exact): the same predefined grids and patch records, but a record's cp
 * names one knot span of a face occurrence (sw__gpu_exact_piece) and the vertex shader evaluates
 * the NURBS there from its knot vectors and homogeneous control points (eye-relative world): the
 * p + 1 non-zero B-spline basis functions by the Cox–de Boor triangle (Piegl & Tiller A2.2), their
 * first derivatives from the degree p - 1 functions (A2.3 with n = 1), the homogeneous point and
 * both partials (A4.3), all in double (ARB_gpu_shader_fp64, core since GL 4.0); the rational point
 * and the normal are converted to float only at the end. Degrees up to 15 per direction. */
static const char *const k_exact_vs =
    "#version 430 core\n"
    "struct PatchRec {\n"
    "  vec4 st; vec4 trim_map; vec4 trim_rect; vec4 color;\n"
    "  uint cp; int deg_u; int deg_v; float layer;\n"
    "  float nsign; int draw; int level_u; int level_v;\n"
    "  vec4 uv_map;\n"
    "};\n"
    "struct Piece {\n"
    "  double u0, u1, v0, v1;\n"
    "  uint ku, kv, cp; int stride; int deg_u, deg_v, span_u, span_v;\n"
    "};\n"
    "layout(std430, binding = 0) readonly buffer Patches { PatchRec recs[]; };\n"
    "layout(std430, binding = 2) readonly buffer Pieces { Piece pieces[]; };\n"
    "layout(std430, binding = 3) readonly buffer Knots { double knots[]; };\n"
    "layout(std430, binding = 4) readonly buffer ControlPoints { dvec4 cps[]; };\n"
    "uniform mat4 u_view_proj;\n"
    "uniform ivec2 u_grid;\n"
    "uniform int u_base;\n"
    "out vec3 v_rel;\n"
    "out vec3 v_nrm;\n"
    "out vec2 v_st;\n"
    "out vec2 v_uv;\n"
    "flat out vec4 v_color;\n"
    "flat out vec4 v_trim_rect;\n"
    "flat out float v_trim_layer;\n"
    "void basis(uint kb, int p, int span, double t, out double N[16], out double dN[16]) {\n"
    "  double left[16], right[16], Nm[16];\n"
    "  for (int r = 0; r < 16; ++r) { N[r] = 0.0LF; dN[r] = 0.0LF; Nm[r] = 0.0LF; }\n"
    "  N[0] = 1.0LF;\n"
    "  for (int j = 1; j <= p; ++j) {\n"
    "    left[j] = t - knots[kb + uint(span + 1 - j)];\n"
    "    right[j] = knots[kb + uint(span + j)] - t;\n"
    "    if (j == p) Nm = N;\n"
    "    double saved = 0.0LF;\n"
    "    for (int r = 0; r < j; ++r) {\n"
    "      double temp = N[r] / (right[r + 1] + left[j - r]);\n"
    "      N[r] = saved + right[r + 1] * temp;\n"
    "      saved = left[j - r] * temp;\n"
    "    }\n"
    "    N[j] = saved;\n"
    "  }\n"
    "  for (int r = 0; r <= p; ++r) {\n"
    "    double d = 0.0LF;\n"
    "    if (r >= 1)\n"
    "      d += Nm[r - 1] / (knots[kb + uint(span + r)] - knots[kb + uint(span - p + r)]);\n"
    "    if (r < p)\n"
    "      d -= Nm[r] / (knots[kb + uint(span + r + 1)] - knots[kb + uint(span - p + r + 1)]);\n"
    "    dN[r] = double(p) * d;\n"
    "  }\n"
    "}\n"
    "void eval(Piece q, double u, double v, out dvec4 h, out dvec4 hs, out dvec4 ht) {\n"
    "  double Nu[16], dNu[16], Nv[16], dNv[16];\n"
    "  basis(q.ku, q.deg_u, q.span_u, u, Nu, dNu);\n"
    "  basis(q.kv, q.deg_v, q.span_v, v, Nv, dNv);\n"
    "  h = dvec4(0.0LF); hs = dvec4(0.0LF); ht = dvec4(0.0LF);\n"
    "  for (int l = 0; l <= q.deg_v; ++l) {\n"
    "    uint at = q.cp + uint((q.span_v - q.deg_v + l) * q.stride + q.span_u - q.deg_u);\n"
    "    dvec4 row = dvec4(0.0LF), rows = dvec4(0.0LF);\n"
    "    for (int k = 0; k <= q.deg_u; ++k) {\n"
    "      dvec4 c = cps[at + uint(k)];\n"
    "      row += Nu[k] * c;\n"
    "      rows += dNu[k] * c;\n"
    "    }\n"
    "    h += Nv[l] * row; hs += Nv[l] * rows; ht += dNv[l] * row;\n"
    "  }\n"
    "}\n"
    "dvec3 normal_of(dvec4 h, dvec4 hs, dvec4 ht, out bool ok) {\n"
    "  dvec3 ds = hs.xyz * h.w - h.xyz * hs.w, dt = ht.xyz * h.w - h.xyz * ht.w;\n"
    "  dvec3 n = cross(ds, dt);\n"
    "  ok = length(n) > 1e-9LF * length(ds) * length(dt);\n"
    "  return n;\n"
    "}\n"
    "double param(float s, float s0, float s1, double a, double b) {\n"
    "  if (s == 0.0) return a;\n"
    "  if (s == 1.0) return b;\n"
    "  return a + (b - a) * double(s);\n"
    "}\n"
    "void main() {\n"
    "  PatchRec p = recs[u_base + gl_InstanceID];\n"
    "  Piece q = pieces[p.cp];\n"
    "  int i = gl_VertexID % (u_grid.x + 1), j = gl_VertexID / (u_grid.x + 1);\n"
    "  float s = i == u_grid.x ? p.st.y : p.st.x + (p.st.y - p.st.x) * float(i) / "
    "float(u_grid.x);\n"
    "  float t = j == u_grid.y ? p.st.w : p.st.z + (p.st.w - p.st.z) * float(j) / "
    "float(u_grid.y);\n"
    "  double u = param(s, p.st.x, p.st.y, q.u0, q.u1), v = param(t, p.st.z, p.st.w, q.v0, q.v1);\n"
    "  dvec4 h, hs, ht;\n"
    "  eval(q, u, v, h, hs, ht);\n"
    "  bool ok;\n"
    "  dvec3 n = normal_of(h, hs, ht, ok);\n"
    "  if (!ok) {\n"
    "    dvec4 h2, hs2, ht2;\n"
    "    double su = 1e-3LF * (q.u1 - q.u0), sv = 1e-3LF * (q.v1 - q.v0);\n"
    "    eval(q, u + (s < 0.5 ? su : -su), v + (t < 0.5 ? sv : -sv), h2, hs2, ht2);\n"
    "    n = normal_of(h2, hs2, ht2, ok);\n"
    "  }\n"
    "  vec3 pos = vec3(h.xyz / h.w);\n"
    "  double ln = length(n);\n"
    "  v_nrm = ln > 0.0LF ? p.nsign * vec3(n / ln) : vec3(0.0);\n"
    "  v_rel = pos;\n"
    "  v_st = vec2(p.trim_map.x + s * p.trim_map.y, p.trim_map.z + t * p.trim_map.w);\n"
    "  v_uv = vec2(u, v);\n"
    "  v_color = p.color;\n"
    "  v_trim_rect = p.trim_rect;\n"
    "  v_trim_layer = p.layer;\n"
    "  gl_Position = u_view_proj * vec4(pos, 1.0);\n"
    "}\n";

static const char *const k_trim_vs = "#version 430 core\n"
                                     "layout(location = 0) in vec2 a_pos;\n"
                                     "void main() { gl_Position = vec4(a_pos, 0.0, 1.0); }\n";

static const char *const k_trim_fs = "#version 430 core\n"
                                     "layout(location = 0) out vec4 o_color;\n"
                                     "void main() { o_color = vec4(1.0); }\n";

/* Depth-compositing present (sw__gpu_present): one triangle covering the viewport, each pixel
 * copying the render target's colour and depth; background pixels (depth 0: the reversed-Z
 * clear) are discarded so that the host's framebuffer keeps its own there. */
static const char *const k_present_vs =
    "#version 430 core\n"
    "void main() {\n"
    "  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);\n"
    "  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);\n"
    "}\n";

static const char *const k_present_fs = "#version 430 core\n"
                                        "layout(binding = 0) uniform sampler2D u_depth;\n"
                                        "layout(binding = 1) uniform sampler2D u_color;\n"
                                        "layout(location = 0) out vec4 o_color;\n"
                                        "void main() {\n"
                                        "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
                                        "  float d = texelFetch(u_depth, p, 0).r;\n"
                                        "  if (!(d > 0.0)) discard;\n"
                                        "  o_color = texelFetch(u_color, p, 0);\n"
                                        "  gl_FragDepth = d;\n"
                                        "}\n";

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

/* Links a vertex stage with the surface fragment stage, assembled from its parts around the
 * shading function `shade` (the library's, or a host's: its compile errors are the host's, hence
 * SW_ERR_INVALID_ARGUMENT). */
static sw_result link_parts(const char *vs, const char *const *fs, GLsizei n_fs, const char *what,
                            sw_result fail, GLuint *out, sw_status *status)
{
    GLuint v = 0, f = glCreateShader(GL_FRAGMENT_SHADER);
    sw_result r = compile(GL_VERTEX_SHADER, vs, what, &v, status);
    if (r != SW_OK) {
        glDeleteShader(f);
        return r;
    }
    glShaderSource(f, n_fs, fs, NULL);
    glCompileShader(f);
    GLint ok = 0;
    glGetShaderiv(f, GL_COMPILE_STATUS, &ok);
    char log[400];
    if (!ok) {
        glGetShaderInfoLog(f, sizeof log, NULL, log);
        glDeleteShader(v);
        glDeleteShader(f);
        return sw__fail(status, fail, "fragment shader of %s does not compile: %s", what, log);
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        return sw__fail(status, fail, "program %s does not link: %s", what, log);
    }
    *out = p;
    return SW_OK;
}

static sw_result link(const char *vs, const char *fs, const char *what, GLuint *out,
                      sw_status *status)
{
    return link_parts(vs, &fs, 1, what, SW_ERR_GL, out, status);
}

/* The three surface programs around one shading function; on failure none is left. */
static sw_result link_surfaces(const char *shade, sw_result fail, sw__gpu_surface_programs *p,
                               sw_status *status)
{
    memset(p, 0, sizeof *p);
    const char *fs[4] = {k_surface_fs_interface, k_surface_fs_trim, shade, k_surface_fs_main};
    sw_result r = link_parts(k_mesh_vs, fs, 4, "mesh", fail, &p->mesh, status);
    if (r == SW_OK)
        r = link_parts(k_eval_vs, fs, 4, "patch evaluation", fail, &p->eval, status);
    if (r == SW_OK)
        r = link_parts(k_exact_vs, fs, 4, "exact evaluation", fail, &p->exact, status);
    if (r != SW_OK) {
        glDeleteProgram(p->mesh);
        glDeleteProgram(p->eval);
        glDeleteProgram(p->exact);
        memset(p, 0, sizeof *p);
        return r;
    }
    p->loc_view_proj = glGetUniformLocation(p->mesh, "u_view_proj");
    p->loc_color = glGetUniformLocation(p->mesh, "u_color");
    p->loc_trim_rect = glGetUniformLocation(p->mesh, "u_trim_rect");
    p->loc_trim_layer = glGetUniformLocation(p->mesh, "u_trim_layer");
    p->loc_trim = glGetUniformLocation(p->mesh, "u_trim");
    p->loc_uv_map = glGetUniformLocation(p->mesh, "u_uv_map");
    p->loc_eval_view_proj = glGetUniformLocation(p->eval, "u_view_proj");
    p->loc_eval_grid = glGetUniformLocation(p->eval, "u_grid");
    p->loc_eval_base = glGetUniformLocation(p->eval, "u_base");
    p->loc_eval_trim = glGetUniformLocation(p->eval, "u_trim");
    p->loc_eval_capture = glGetUniformLocation(p->eval, "u_capture");
    p->loc_exact_view_proj = glGetUniformLocation(p->exact, "u_view_proj");
    p->loc_exact_grid = glGetUniformLocation(p->exact, "u_grid");
    p->loc_exact_base = glGetUniformLocation(p->exact, "u_base");
    p->loc_exact_trim = glGetUniformLocation(p->exact, "u_trim");
    return SW_OK;
}

sw_result sw__gpu_programs_create(sw_gpu_context *ctx, sw_status *status)
{
    sw_result r = link_surfaces(k_surface_fs_default_shade, SW_ERR_GL, &ctx->surf, status);
    if (r != SW_OK)
        return r;
    r = link(k_trim_vs, k_trim_fs, "trim", &ctx->prog_trim, status);
    if (r != SW_OK)
        return r;
    r = link(k_present_vs, k_present_fs, "present", &ctx->prog_present, status);
    if (r != SW_OK)
        return r;
    return sw__gpu_check(status, "program set-up");
}

void sw__gpu_shading_free(sw_gpu_context *ctx, sw__gpu_surface_programs *p)
{
    (void)ctx; /* the context is current: its programs are deleted with it */
    glDeleteProgram(p->mesh);
    glDeleteProgram(p->eval);
    glDeleteProgram(p->exact);
    memset(p, 0, sizeof *p);
}

void sw__gpu_programs_free(sw_gpu_context *ctx)
{
    sw__gpu_shading_free(ctx, &ctx->surf);
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
    sw_result r = link_surfaces(shade_source, SW_ERR_INVALID_ARGUMENT, out, status);
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

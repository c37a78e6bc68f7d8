// SPDX-License-Identifier: MIT
//  Exact evaluation (eval_exact): the same predefined grids and patch records, but a record's cp
// names one knot span of a face occurrence (sw__gpu_exact_piece) and the vertex shader evaluates
// the NURBS there from its knot vectors and homogeneous control points (eye-relative world): the
// p + 1 non-zero B-spline basis functions by the Cox-de Boor triangle (Piegl & Tiller A2.2), their
// first derivatives from the degree p - 1 functions (A2.3 with n = 1), the homogeneous point and
// both partials (A4.3), all in double (ARB_gpu_shader_fp64, core since GL 4.0); the rational point
// and the normal are converted to float only at the end. Degrees up to 15 per direction.
#version 430 core
struct PatchRec {
  vec4 st; vec4 trim_map; vec4 trim_rect; vec4 color;
  uint cp; int deg_u; int deg_v; float layer;
  float nsign; int draw; int level_u; int level_v;
  vec4 uv_map;
};
struct Piece {
  double u0, u1, v0, v1;
  uint ku, kv, cp; int stride; int deg_u, deg_v, span_u, span_v;
};
layout(std430, binding = 0) readonly buffer Patches { PatchRec recs[]; };
layout(std430, binding = 2) readonly buffer Pieces { Piece pieces[]; };
layout(std430, binding = 3) readonly buffer Knots { double knots[]; };
layout(std430, binding = 4) readonly buffer ControlPoints { dvec4 cps[]; };
uniform mat4 u_view_proj;
uniform ivec2 u_grid;
uniform int u_base;
out vec3 v_rel;
out vec3 v_nrm;
out vec2 v_st;
out vec2 v_uv;
flat out vec4 v_color;
flat out vec4 v_trim_rect;
flat out float v_trim_layer;
void basis(uint kb, int p, int span, double t, out double N[16], out double dN[16]) {
  double left[16], right[16], Nm[16];
  for (int r = 0; r < 16; ++r) { N[r] = 0.0LF; dN[r] = 0.0LF; Nm[r] = 0.0LF; }
  N[0] = 1.0LF;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - knots[kb + uint(span + 1 - j)];
    right[j] = knots[kb + uint(span + j)] - t;
    if (j == p) Nm = N;
    double saved = 0.0LF;
    for (int r = 0; r < j; ++r) {
      double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  for (int r = 0; r <= p; ++r) {
    double d = 0.0LF;
    if (r >= 1)
      d += Nm[r - 1] / (knots[kb + uint(span + r)] - knots[kb + uint(span - p + r)]);
    if (r < p)
      d -= Nm[r] / (knots[kb + uint(span + r + 1)] - knots[kb + uint(span - p + r + 1)]);
    dN[r] = double(p) * d;
  }
}
void eval(Piece q, double u, double v, out dvec4 h, out dvec4 hs, out dvec4 ht) {
  double Nu[16], dNu[16], Nv[16], dNv[16];
  basis(q.ku, q.deg_u, q.span_u, u, Nu, dNu);
  basis(q.kv, q.deg_v, q.span_v, v, Nv, dNv);
  h = dvec4(0.0LF); hs = dvec4(0.0LF); ht = dvec4(0.0LF);
  for (int l = 0; l <= q.deg_v; ++l) {
    uint at = q.cp + uint((q.span_v - q.deg_v + l) * q.stride + q.span_u - q.deg_u);
    dvec4 row = dvec4(0.0LF), rows = dvec4(0.0LF);
    for (int k = 0; k <= q.deg_u; ++k) {
      dvec4 c = cps[at + uint(k)];
      row += Nu[k] * c;
      rows += dNu[k] * c;
    }
    h += Nv[l] * row; hs += Nv[l] * rows; ht += dNv[l] * row;
  }
}
dvec3 normal_of(dvec4 h, dvec4 hs, dvec4 ht, out bool ok) {
  dvec3 ds = hs.xyz * h.w - h.xyz * hs.w, dt = ht.xyz * h.w - h.xyz * ht.w;
  dvec3 n = cross(ds, dt);
  ok = length(n) > 1e-9LF * length(ds) * length(dt);
  return n;
}
double param(float s, float s0, float s1, double a, double b) {
  if (s == 0.0) return a;
  if (s == 1.0) return b;
  return a + (b - a) * double(s);
}
void main() {
  PatchRec p = recs[u_base + gl_InstanceID];
  Piece q = pieces[p.cp];
  int i = gl_VertexID % (u_grid.x + 1), j = gl_VertexID / (u_grid.x + 1);
  float s = i == u_grid.x ? p.st.y : p.st.x + (p.st.y - p.st.x) * float(i) / float(u_grid.x);
  float t = j == u_grid.y ? p.st.w : p.st.z + (p.st.w - p.st.z) * float(j) / float(u_grid.y);
  double u = param(s, p.st.x, p.st.y, q.u0, q.u1), v = param(t, p.st.z, p.st.w, q.v0, q.v1);
  dvec4 h, hs, ht;
  eval(q, u, v, h, hs, ht);
  bool ok;
  dvec3 n = normal_of(h, hs, ht, ok);
  if (!ok) {
    dvec4 h2, hs2, ht2;
    double su = 1e-3LF * (q.u1 - q.u0), sv = 1e-3LF * (q.v1 - q.v0);
    eval(q, u + (s < 0.5 ? su : -su), v + (t < 0.5 ? sv : -sv), h2, hs2, ht2);
    n = normal_of(h2, hs2, ht2, ok);
  }
  vec3 pos = vec3(h.xyz / h.w);
  double ln = length(n);
  v_nrm = ln > 0.0LF ? p.nsign * vec3(n / ln) : vec3(0.0);
  v_rel = pos;
  v_st = vec2(p.trim_map.x + s * p.trim_map.y, p.trim_map.z + t * p.trim_map.w);
  v_uv = vec2(u, v);
  v_color = p.color;
  v_trim_rect = p.trim_rect;
  v_trim_layer = p.layer;
  gl_Position = u_view_proj * vec4(pos, 1.0);
}

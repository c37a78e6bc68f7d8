// SPDX-License-Identifier: MIT
//  Vertex-shader evaluation of rational Bezier patches of degree <= 3 x 3 on a predefined grid
// (sec. 4.2): gl_VertexID gives the grid point, gl_InstanceID (plus the class's first record) the patch
// record. Direct evaluation in the Bernstein basis of the homogeneous control points (eye-relative
// world, so float keeps sub-pixel accuracy close up) with both first partials, then the division
// by w; the normal is the cross product of the rational partials (their w^2-scaled forms). A
// collapsed edge (pole) has no normal there: it is taken just inside the patch, like patch_grid.c.
// Grid points on a patch's edges get exactly the edge parameter, so patches sharing an edge (and
// its control points) produce bit-identical positions along it.
#version 430 core
struct PatchRec {
  vec4 st; vec4 trim_map; vec4 trim_rect; vec4 color;
  uint cp; int deg_u; int deg_v; float layer;
  float nsign; int draw; int level_u; int level_v;
  vec4 uv_map;
};
layout(std430, binding = 0) readonly buffer Patches { PatchRec recs[]; };
layout(std430, binding = 1) readonly buffer ControlPoints { vec4 cps[]; };
uniform mat4 u_view_proj;
uniform ivec2 u_grid;
uniform int u_base;
uniform int u_capture;
layout(std430, binding = 5) buffer Capture { uint n_capture; uint pad[3]; vec4 cap[]; };
out vec3 v_rel;
out vec3 v_nrm;
out vec2 v_st;
out vec2 v_uv;
flat out vec4 v_color;
flat out vec4 v_trim_rect;
flat out float v_trim_layer;
void bern(int p, float s, out float b[4], out float db[4]) {
  float r = 1.0 - s;
  b[0] = 1.0; b[1] = 0.0; b[2] = 0.0; b[3] = 0.0;
  db[0] = 0.0; db[1] = 0.0; db[2] = 0.0; db[3] = 0.0;
  if (p == 1) {
    b[0] = r; b[1] = s; db[0] = -1.0; db[1] = 1.0;
  } else if (p == 2) {
    b[0] = r * r; b[1] = 2.0 * r * s; b[2] = s * s;
    db[0] = -2.0 * r; db[1] = 2.0 * (r - s); db[2] = 2.0 * s;
  } else if (p == 3) {
    b[0] = r * r * r; b[1] = 3.0 * r * r * s; b[2] = 3.0 * r * s * s; b[3] = s * s * s;
    db[0] = -3.0 * r * r; db[1] = 3.0 * r * (r - 2.0 * s);
    db[2] = 3.0 * s * (2.0 * r - s); db[3] = 3.0 * s * s;
  }
}
void eval(PatchRec p, float s, float t, out vec4 h, out vec4 hs, out vec4 ht) {
  float bu[4], dbu[4], bv[4], dbv[4];
  bern(p.deg_u, s, bu, dbu);
  bern(p.deg_v, t, bv, dbv);
  h = vec4(0.0); hs = vec4(0.0); ht = vec4(0.0);
  uint at = p.cp;
  for (int j = 0; j <= p.deg_v; ++j) {
    vec4 row = vec4(0.0), rows = vec4(0.0);
    for (int i = 0; i <= p.deg_u; ++i, ++at) {
      vec4 c = cps[at];
      row += bu[i] * c;
      rows += dbu[i] * c;
    }
    h += bv[j] * row; hs += bv[j] * rows; ht += dbv[j] * row;
  }
}
vec3 normal_of(vec4 h, vec4 hs, vec4 ht, out float ok) {
  vec3 ds = hs.xyz * h.w - h.xyz * hs.w, dt = ht.xyz * h.w - h.xyz * ht.w;
  vec3 n = cross(ds, dt);
  ok = length(n) > 1e-6 * length(ds) * length(dt) ? 1.0 : 0.0;
  return n;
}
void main() {
  PatchRec p = recs[u_base + gl_InstanceID];
  int i = gl_VertexID % (u_grid.x + 1), j = gl_VertexID / (u_grid.x + 1);
  float s = i == u_grid.x ? p.st.y : p.st.x + (p.st.y - p.st.x) * float(i) / float(u_grid.x);
  float t = j == u_grid.y ? p.st.w : p.st.z + (p.st.w - p.st.z) * float(j) / float(u_grid.y);
  vec4 h, hs, ht;
  eval(p, s, t, h, hs, ht);
  float ok;
  vec3 n = normal_of(h, hs, ht, ok);
  if (ok == 0.0) {
    vec4 h2, hs2, ht2;
    eval(p, s + 1e-3 * (0.5 - s), t + 1e-3 * (0.5 - t), h2, hs2, ht2);
    n = normal_of(h2, hs2, ht2, ok);
  }
  vec3 pos = h.xyz / h.w;
  float ln = length(n);
  v_nrm = ln > 0.0 ? p.nsign * n / ln : vec3(0.0);
  v_rel = pos;
  v_st = vec2(p.trim_map.x + s * p.trim_map.y, p.trim_map.z + t * p.trim_map.w);
  v_uv = p.uv_map.xy + vec2(s, t) * p.uv_map.zw;
  v_color = p.color;
  v_trim_rect = p.trim_rect;
  v_trim_layer = p.layer;
  if (u_capture > 0) {
    uint k = atomicAdd(n_capture, 1u);
    if (k < uint(u_capture)) {
      cap[2u * k] = vec4(uintBitsToFloat(uint(u_base + gl_InstanceID)), s, t, 0.0);
      cap[2u * k + 1u] = vec4(pos, 0.0);
    }
  }
  gl_Position = u_view_proj * vec4(pos, 1.0);
}

// SPDX-License-Identifier: MIT
// The vertex stage of patch grids kept on the GPU (gpu/resident_grids.c): each vertex was
// evaluated once by eval.vert.glsl in its patch's own space around a centre (position, unit normal,
// the patch parameters (s, t)); each draw's attributes (one instance, picked by its indirect
// command's base instance) place it: rows of the occurrence's 3 x 3 with the centre's
// eye-relative position in w (composed in double on the CPU), rows of its cofactor matrix for the
// normal (any affine map, mirrors included) with the normal sign and the atlas layer in w, then
// colour, trim map (st = map.xz + (s, t) map.yw, as eval.vert.glsl maps it), trim rectangle and
// the face's parameter map.
#version 430 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in vec2 a_st;
layout(location = 3) in vec4 a_rot0;
layout(location = 4) in vec4 a_rot1;
layout(location = 5) in vec4 a_rot2;
layout(location = 6) in vec4 a_cof0;
layout(location = 7) in vec4 a_cof1;
layout(location = 8) in vec4 a_cof2;
layout(location = 9) in vec4 a_color;
layout(location = 10) in vec4 a_trim_map;
layout(location = 11) in vec4 a_trim_rect;
layout(location = 12) in vec4 a_uv_map;
uniform mat4 u_view_proj;
out vec3 v_rel;
out vec3 v_nrm;
out vec2 v_st;
out vec2 v_uv;
flat out vec4 v_color;
flat out vec4 v_trim_rect;
flat out float v_trim_layer;
void main() {
  vec3 rel = vec3(dot(a_rot0.xyz, a_pos), dot(a_rot1.xyz, a_pos), dot(a_rot2.xyz, a_pos)) +
             vec3(a_rot0.w, a_rot1.w, a_rot2.w);
  v_rel = rel;
  v_nrm = a_cof0.w * vec3(dot(a_cof0.xyz, a_nrm), dot(a_cof1.xyz, a_nrm), dot(a_cof2.xyz, a_nrm));
  v_st = vec2(a_trim_map.x + a_st.x * a_trim_map.y, a_trim_map.z + a_st.y * a_trim_map.w);
  v_uv = a_uv_map.xy + a_st * a_uv_map.zw;
  v_color = a_color;
  v_trim_rect = a_trim_rect;
  v_trim_layer = a_cof1.w;
  gl_Position = u_view_proj * vec4(rel, 1.0);
}

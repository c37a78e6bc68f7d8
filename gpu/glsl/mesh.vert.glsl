// SPDX-License-Identifier: MIT
// The mesh program's vertex stage: CPU grids, fat borders and plain triangles, positions
// eye-relative (world minus the eye, float), reversed-Z projection by u_view_proj; st is the trim
// lookup's coordinate over the draw's rectangle, uv = u_uv_map.xy + st * u_uv_map.zw the face's
// parameters (for a host's shading). Resident static levels (gpu/resident.c) are kept around
// their unit's centre and placed by u_model_rot and u_model_off (the centre's eye-relative
// position, composed in double on the CPU); every other draw has the identity and 0.
#version 430 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in vec2 a_st;
uniform mat4 u_view_proj;
uniform vec4 u_color;
uniform vec4 u_trim_rect;
uniform float u_trim_layer;
uniform vec4 u_uv_map;
uniform mat3 u_model_rot;
uniform vec3 u_model_off;
out vec3 v_rel;
out vec3 v_nrm;
out vec2 v_st;
out vec2 v_uv;
flat out vec4 v_color;
flat out vec4 v_trim_rect;
flat out float v_trim_layer;
void main() {
  vec3 rel = u_model_rot * a_pos + u_model_off;
  v_rel = rel;
  v_nrm = u_model_rot * a_nrm;
  v_st = a_st;
  v_uv = u_uv_map.xy + a_st * u_uv_map.zw;
  v_color = u_color;
  v_trim_rect = u_trim_rect;
  v_trim_layer = u_trim_layer;
  gl_Position = u_view_proj * vec4(rel, 1.0);
}

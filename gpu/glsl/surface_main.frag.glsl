// SPDX-License-Identifier: MIT
void main() {
  if (!sw_trim_inside(u_trim, v_st, v_trim_rect, v_trim_layer)) discard;
  float ln = length(v_nrm);
  o_color = sw_shade(v_rel, ln > 0.0 ? v_nrm / ln : vec3(0.0), v_uv, v_color);
}

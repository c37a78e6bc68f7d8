// SPDX-License-Identifier: MIT
// main of the untrimmed surface programs: surface_main.frag.glsl without the trim lookup, for draws
// whose face has no trim texture (the lookup would accept every fragment).
void main() {
  float ln = length(v_nrm);
  o_color = sw_shade(v_rel, ln > 0.0 ? v_nrm / ln : vec3(0.0), v_uv, v_color);
}

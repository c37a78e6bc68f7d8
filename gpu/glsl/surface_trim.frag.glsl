// SPDX-License-Identifier: MIT
// Exact edges: the fragment's even-odd parity is its cell's reference point's, flipped by every
// segment of the cell the path from that point crosses (gpu/trim_edges.c says why that is exact;
// sw__gpu_edge_crosses is the same test on the CPU).
// The cells' reference points (trim_edges.c k_ref_candidates, the same literals).
const vec2 sw_edge_refs[5] = vec2[](vec2(0.53125, 0.47265625), vec2(0.318359375, 0.693359375),
                                    vec2(0.70703125, 0.271484375), vec2(0.141601562, 0.88671875),
                                    vec2(0.618164062, 0.577148438));
bool sw_trim_exact_inside(int grid, vec2 st) {
  SwEdgeGrid g = sw_edge_grids[grid];
  vec2 p = clamp(st, 0.0, 1.0) * vec2(g.n);
  ivec2 c = min(ivec2(p), ivec2(g.n) - 1);
  uvec2 cell = sw_edge_cells[g.first_cell + uint(c.y) * g.n.x + uint(c.x)];
  vec2 d = p - (vec2(c) + sw_edge_refs[(cell.y >> 1) & 7u]);
  uint inside = cell.y & 1u;
  uint end = cell.x + (cell.y >> 4);
  for (uint k = cell.x; k < end; ++k) {
    vec4 s = sw_edge_segs[k];
    bool ends_apart = (d.x * s.y - d.y * s.x > 0.0) != (d.x * s.w - d.y * s.z > 0.0);
    vec2 e = s.zw - s.xy;
    bool path_apart = (e.x * -s.y - e.y * -s.x > 0.0) !=
                      (e.x * (d.y - s.y) - e.y * (d.x - s.x) > 0.0);
    if (ends_apart && path_apart) inside ^= 1u;
  }
  return inside != 0u;
}
bool sw_trim_inside(sampler2DArray atlas, vec2 st, vec4 rect, float layer) {
  if (rect.z < 0.0) return sw_trim_exact_inside(int(rect.x), st);
  if (rect.z == 0.0) return true;
  vec2 size = rect.zw;
  vec2 t = rect.xy + clamp(st * size, vec2(0.5), size - vec2(0.5));
  return texelFetch(atlas, ivec3(ivec2(t), int(layer)), 0).r >= 0.5;
}
vec4 sw_shade_library(vec3 pos, vec3 normal, vec2 uv, vec4 color) {
  float lambert = 1.0;
  if (dot(normal, normal) > 0.0) lambert = abs(dot(normal, normalize(-pos)));
  vec3 c = color.rgb * (0.2 + 0.8 * lambert);
  return vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), color.a);
}

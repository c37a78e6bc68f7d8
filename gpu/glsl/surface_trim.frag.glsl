// SPDX-License-Identifier: MIT
bool sw_trim_inside(sampler2DArray atlas, vec2 st, vec4 rect, float layer) {
  if (rect.z <= 0.0) return true;
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

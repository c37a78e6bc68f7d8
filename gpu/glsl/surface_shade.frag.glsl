// SPDX-License-Identifier: MIT
vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color) {
  return sw_shade_library(pos, normal, uv, color);
}

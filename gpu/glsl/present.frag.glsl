// SPDX-License-Identifier: MIT
#version 430 core
layout(binding = 0) uniform sampler2D u_depth;
layout(binding = 1) uniform sampler2D u_color;
layout(location = 0) out vec4 o_color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float d = texelFetch(u_depth, p, 0).r;
  if (!(d > 0.0)) discard;
  o_color = texelFetch(u_color, p, 0);
  gl_FragDepth = d;
}

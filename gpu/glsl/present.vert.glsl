// SPDX-License-Identifier: MIT
//  Depth-compositing present (sw__gpu_present): one triangle covering the viewport, each pixel
// copying the render target's colour and depth; background pixels (depth 0: the reversed-Z
// clear) are discarded so that the host's framebuffer keeps its own there.
#version 430 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}

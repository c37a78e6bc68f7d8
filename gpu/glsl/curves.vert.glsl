// SPDX-License-Identifier: MIT
// Curved triangles (Santana §3.2): positions in the coverage target's pixels; k, l, m are affine
// functions of the plane (gpu/curves_split.c), so linear interpolation carries them exactly over
// any triangle near the piece, inside its control hull or in the anti-aliasing band around it.
#version 450 core
layout(location = 0) in vec2 a_pos;
layout(location = 1) in vec3 a_klm;
layout(location = 2) in vec2 a_cut;   // distances past the start and before the end cut lines
layout(location = 3) in vec3 a_flags; // kind (-1 fan, 0 line, 1 conic, 2 cubic), s_chord, s_in
uniform vec2 u_size;
out vec3 v_klm;
out vec2 v_cut;
flat out vec3 v_flags;
void main()
{
    v_klm = a_klm;
    v_cut = a_cut;
    v_flags = a_flags;
    gl_Position = vec4(a_pos / u_size * 2.0 - 1.0, 0.0, 1.0);
}

// SPDX-License-Identifier: MIT
// Curved triangles (Santana §3.2): positions in the coverage target's pixels; each piece's
// implicit form F comes as the coefficients of a bivariate polynomial (degree <= 3) in the
// piece's local coordinates uv, which are affine in the plane: linear interpolation carries them
// exactly over any triangle near the piece, inside its control hull or in the anti-aliasing band
// around it (gpu/curves.c, local_form, says why F is not evaluated as k^3 - l m here).
#version 450 core
layout(location = 0) in vec2 a_pos;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in vec3 a_cut;   // px past the start / before the end cut line, off the chord
layout(location = 3) in vec3 a_flags; // kind (-1 fan, 0 line, 1 conic, 2 cubic), s_chord, s_in
layout(location = 4) in vec4 a_c0;    // 1, u, v, u^2
layout(location = 5) in vec4 a_c1;    // u v, v^2, u^3, u^2 v
layout(location = 6) in vec4 a_c2;    // u v^2, v^3, chord strip: least, largest
uniform vec2 u_size;
out vec2 v_uv;
out vec3 v_cut;
flat out vec3 v_flags;
flat out vec4 v_c0;
flat out vec4 v_c1;
flat out vec4 v_c2;
void main()
{
    v_uv = a_uv;
    v_cut = a_cut;
    v_flags = a_flags;
    v_c0 = a_c0;
    v_c1 = a_c1;
    v_c2 = a_c2;
    gl_Position = vec4(a_pos / u_size * 2.0 - 1.0, 0.0, 1.0);
}

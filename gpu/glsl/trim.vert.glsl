// SPDX-License-Identifier: MIT
// The trim program (Guthe et al. 2005 sec. 4): fans and crack-filling lines already in the clip
// space of one atlas page, drawn in one colour into the R8 trim texture.
#version 430 core
layout(location = 0) in vec2 a_pos;
void main() { gl_Position = vec4(a_pos, 0.0, 1.0); }

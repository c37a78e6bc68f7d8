// SPDX-License-Identifier: MIT
#version 430 core
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(1.0); }

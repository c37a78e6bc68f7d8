// SPDX-License-Identifier: MIT
//  The fragment stage of every surface program, in four parts linked as one shader (and handed to
// hosts by sw__gpu_glsl_source, sw_immediate.h): the interface (inputs from the library's vertex
// stages, the atlas sampler, the output), the trim lookup (sec. 4.3), a shading function sw_shade -
// the library's (sw_shade_library) or a host's - and main, which trims and then shades.
// The trim lookup reads the face's rectangle of the atlas (sec. 4.4; rect = x0, y0, w, h in texels,
// w = 0 untrimmed; w < 0: exact edges, grid number x), clamped half a texel inside the rectangle so that a parameter on the box's
// edge reads the edge texel and never the gutter (PLATFORM.md: trim parity exactness). The
// library's shading is two-sided: the headlight lights whichever side faces the eye. Output is
// gamma-encoded.
#version 430 core
in vec3 v_rel;
in vec3 v_nrm;
in vec2 v_st;
in vec2 v_uv;
flat in vec4 v_color;
flat in vec4 v_trim_rect;
flat in float v_trim_layer;
uniform sampler2DArray u_trim;
// Exact trim edges (gpu/trim_edges.c): per grid its cells in s, t and its first cell; per cell
// its first segment, count << 4 | its reference point's number << 1 | that point's parity; per
// segment its ends (clipped to the cell) relative to the cell's reference point, in cells.
struct SwEdgeGrid { uvec2 n; uint first_cell; uint pad; };
layout(std430, binding = 6) readonly buffer SwEdgeGrids { SwEdgeGrid sw_edge_grids[]; };
layout(std430, binding = 7) readonly buffer SwEdgeCells { uvec2 sw_edge_cells[]; };
layout(std430, binding = 8) readonly buffer SwEdgeSegs { vec4 sw_edge_segs[]; };
layout(location = 0) out vec4 o_color;

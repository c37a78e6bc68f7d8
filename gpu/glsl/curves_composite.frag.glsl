// SPDX-License-Identifier: MIT
// Composites a shape's coverage over the target (premultiplied "over": what is drawn before,
// opaque 3D geometry or a background, shows through partly covered pixels in proportion). With
// u_ss > 1 the coverage was drawn u_ss times larger (Santana §5's view-based pass for small
// shapes) and is box-filtered here: the mean of a pixel's u_ss x u_ss samples is its area coverage.
#version 450 core
uniform sampler2D u_cov;
uniform vec4 u_color; // premultiplied
uniform ivec2 u_origin;
uniform int u_ss;
layout(location = 0) out vec4 o_color;
void main()
{
    ivec2 p = (ivec2(gl_FragCoord.xy) - u_origin) * u_ss;
    float sum = 0.0;
    for (int j = 0; j < u_ss; ++j)
        for (int i = 0; i < u_ss; ++i)
            sum += texelFetch(u_cov, p + ivec2(i, j), 0).r;
    float a = clamp(sum / float(u_ss * u_ss), 0.0, 1.0);
    o_color = u_color * a;
}

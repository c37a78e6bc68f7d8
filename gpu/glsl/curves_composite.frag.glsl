// SPDX-License-Identifier: MIT
// Composites a shape's coverage over the target (premultiplied "over": what is drawn before,
// opaque 3D geometry or a background, shows through partly covered pixels in proportion). With
// u_ss > 1 the coverage was drawn u_ss times larger (Santana §5's view-based pass for small
// shapes) and is box-filtered here: the mean of a pixel's u_ss x u_ss samples is its area coverage.
// An outline placed in 3D (u_depth_scale > 0) takes its plane's depth at the pixel centre: the
// inverse of the view-axis distance d is affine on the screen, and the reversed-Z window depth is
// near / d, pulled toward the eye by the decal factor folded into u_depth_scale
// (gpu/curves.c, sw__curves_draw_placed); the depth test then hides it behind the scene.
#version 450 core
uniform sampler2D u_cov;
uniform vec4 u_color; // premultiplied
uniform ivec2 u_origin;
uniform int u_ss;
uniform vec3 u_inv_d;        // 1 / d = x (px - o.x) + y (py - o.y) + z, o = u_depth_origin
uniform vec2 u_depth_origin;
uniform float u_depth_scale; // near (1 + pull); 0: a 2D outline, no depth
layout(location = 0) out vec4 o_color;
void main()
{
    if (u_depth_scale > 0.0) {
        vec2 q = gl_FragCoord.xy - u_depth_origin;
        float inv_d = u_inv_d.x * q.x + u_inv_d.y * q.y + u_inv_d.z;
        if (inv_d <= 0.0)
            discard; // the plane is behind the eye along this pixel's ray
        gl_FragDepth = min(u_depth_scale * inv_d, 1.0);
    } else {
        gl_FragDepth = gl_FragCoord.z;
    }
    ivec2 p = (ivec2(gl_FragCoord.xy) - u_origin) * u_ss;
    float sum = 0.0;
    for (int j = 0; j < u_ss; ++j)
        for (int i = 0; i < u_ss; ++i)
            sum += texelFetch(u_cov, p + ivec2(i, j), 0).r;
    float a = clamp(sum / float(u_ss * u_ss), 0.0, 1.0);
    o_color = u_color * a;
}

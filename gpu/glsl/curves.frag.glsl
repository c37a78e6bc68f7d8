// SPDX-License-Identifier: MIT
// Curved triangles and their anti-aliasing (Santana §3.2, §4; Loop & Blinn 2005 for cubics),
// drawn into a float coverage target in three modes:
//  0 stencil parity: fan triangles pass, curved triangles pass only between chord and curve
//    (s_chord F < 0), each toggling the stencil (GL_INVERT): odd = inside at the pixel centre;
//  1 cover: +1 where the stencil is odd;
//  2 edge correction: adds (coverage of the pixel square by the piece's inside half-plane) minus
//    (1 if the pixel centre is in that half-plane), whatever the stencil says. A pixel far from
//    every edge keeps the stencil's 0 or 1; one near a single edge ends with its coverage; and one
//    crossed by several edges that do not cross inside it (an acute corner seen from more than a
//    pixel away, the thin spike of a cusp, two close parts of an outline) ends with the exact area
//    too: crossing each edge flips the parity, so the area is the centre's value plus each edge's
//    (area - centre value) of its own half-plane. Subtracting the stencil's centre value instead
//    (as a first version did) is only right where the centre is inside every nearby half-plane.
//    But the stencil decides a centre within a rounding error of the curve by the rasterizer's
//    snapped hull edges (1/256 px on llvmpipe, 1/16 px allowed by GL) where the curve hugs them
//    near a piece's ends, and a centre there that the stencil and sign(d) put on opposite sides
//    would end half a pixel off (nurbs7 x1: 127/255). So within EPS of the curve the centre's
//    side is taken from the stencil (u_h: drawn once over stencil-odd pixels, once over the
//    others), which is exact for one edge, and for several unless another one also passes nearby.
// The coverage (§4 eq. 3-6) starts from the signed distance d = F / |grad F| (refined below by
// Newton steps to the nearest curve point) with grad F from the chain rule over dFdx / dFdy of
// the local coordinates (exact: they are affine), as eq. 3 does for its conic; a finite
// difference of F itself would be off by F'' times a pixel. Where §4 maps d linearly to coverage
// (eq. 4, e = 1/2 - d), which is exact only for axis-aligned edges (up to 0.043 = 11/255 off at
// 45 degrees), we take the exact area of the pixel square on the inside of the tangent line.
#version 450 core
in vec2 v_uv;
in vec3 v_cut; // px past the start cut line, before the end cut line, left of the chord
flat in vec3 v_flags;
flat in vec4 v_c0;
flat in vec4 v_c1;
flat in vec4 v_c2; // the last two coefficients, the chord strip (least, largest)
uniform int u_mode;
uniform float u_h;
const float EPS = 1.0 / 16.0; // px
// px: how far past the piece's slab and chord strip a foot point may lie and still be on it
const float FOOT_TOL_CUT = 0.75, FOOT_TOL_STRIP = 0.25;
layout(location = 0) out vec4 o_cov;

// The piece's implicit form and its gradient in local coordinates. Kinds 0-2: the polynomial
// c00 + c10 u + c01 v + c20 u^2 + c11 u v + c02 v^2 + c30 u^3 + c21 u^2 v + c12 u v^2 + c03 v^3;
// kind 3 (a cusp's branch): l + b max(k, 0)^(3/2) with k = (c0, c1, c2), l = (c3, c4, c5), b = c6.
float implicit_form(int kind, vec2 p, out vec2 grad)
{
    float u = p.x, v = p.y;
    if (kind == 3) {
        float k = max(v_c0.x + v_c0.y * u + v_c0.z * v, 0.0), r = sqrt(k);
        float l = v_c0.w + v_c1.x * u + v_c1.y * v;
        grad = vec2(v_c1.x, v_c1.y) + 1.5 * v_c1.z * r * v_c0.yz;
        return l + v_c1.z * k * r;
    }
    grad = vec2(v_c0.y + u * (2.0 * v_c0.w + 3.0 * u * v_c1.z) +
                    v * (v_c1.x + 2.0 * u * v_c1.w + v * v_c2.x),
                v_c0.z + v * (2.0 * v_c1.y + 3.0 * v * v_c2.y) +
                    u * (v_c1.x + u * v_c1.w + 2.0 * v * v_c2.x));
    return v_c0.x + u * (v_c0.y + u * (v_c0.w + u * v_c1.z)) +
           v * (v_c0.z + v * (v_c1.y + v * v_c2.y)) + u * v * (v_c1.x + u * v_c1.w + v * v_c2.x);
}

// One Newton step towards F = 0 along the gradient, from the point at offset s (px) from the
// pixel centre; g: the gradient there, in pixels.
vec2 newton_step(int kind, vec2 s, vec2 uvx, vec2 uvy, out vec2 g)
{
    vec2 G;
    float F = implicit_form(kind, v_uv + uvx * s.x + uvy * s.y, G);
    g = vec2(dot(G, uvx), dot(G, uvy));
    float g2 = dot(g, g);
    return g2 > 0.0 ? s - F / g2 * g : s;
}

// Whether the point at offset s from the centre lies in the piece's box (its slab, between the
// cut lines, and its chord strip, which holds the control points, so the curve) grown by the
// tolerances: a foot point outside lies on another branch of the implicit curve.
bool on_piece(vec2 s, vec3 cutx, vec3 cuty)
{
    vec3 c = v_cut + cutx * s.x + cuty * s.y;
    return c.x >= -FOOT_TOL_CUT && c.y >= -FOOT_TOL_CUT && c.z >= v_c2.z - FOOT_TOL_STRIP &&
           c.z <= v_c2.w + FOOT_TOL_STRIP;
}

// Area of the unit pixel square centred at the origin where dot(n, q) <= t, n a unit vector.
float halfplane_coverage(vec2 n, float t)
{
    float a = max(abs(n.x), abs(n.y)), b = min(abs(n.x), abs(n.y));
    float lo = 0.5 * (a - b), hi = 0.5 * (a + b), at = abs(t), c;
    if (at >= hi)
        c = 1.0;
    else if (at <= lo)
        c = 0.5 + at / a;
    else
        c = 1.0 - (hi - at) * (hi - at) / (2.0 * a * b);
    return t >= 0.0 ? c : 1.0 - c;
}

void main()
{
    vec2 uvx = dFdx(v_uv), uvy = dFdy(v_uv);
    vec3 cutx = dFdx(v_cut), cuty = dFdy(v_cut);
    int kind = int(round(v_flags.x));
    vec2 G;
    float F = implicit_form(kind, v_uv, G);
    if (u_mode == 0) {
        if (kind >= 1 && v_flags.y * F >= 0.0)
            discard;
        o_cov = vec4(0.0);
        return;
    }
    if (u_mode == 1) {
        o_cov = vec4(1.0);
        return;
    }
    // the piece's own slab: the cut lines at its ends are normal to its end tangents, so smooth
    // joins split the plane between neighbours without overlap or gap
    if (v_cut.x < 0.0 || v_cut.y <= 0.0)
        discard;
    vec2 g = vec2(dot(G, uvx), dot(G, uvy)); // d/dx, d/dy in pixels (the chain rule)
    float g2 = dot(g, g);
    if (!(g2 > 0.0))
        discard;
    // The edge is the tangent line at the curve point nearest the centre, found by three Newton
    // steps along the gradient: F / |grad F| alone is the distance to the curve only to first
    // order, and where |grad F| changes over a pixel (small pieces whose implicit cubic has its
    // double point or inflections a few pixels away, the cusp's neighbourhood) it was off by
    // 0.15 px at 0.5 px from the curve (nurbs7 x1: 35/255); where another branch passes a pixel
    // away, the first step overshoots twofold and two steps left the foot 0.15 px off (7/255).
    vec2 s = -F / g2 * g; // pixels
    if (dot(s, s) >= 2.25)
        discard; // beyond 1.5 px: no part of the curve in this pixel's square
    vec2 g1;
    s = newton_step(kind, s, uvx, uvy, g1);
    s = newton_step(kind, s, uvx, uvy, g1);
    // The other branches of a piece's implicit cubic (its C(t) for t far outside [0, 1]) are
    // kept out of its grown control hull (curves_split.c, other_branch_near), but not out of the
    // band around a piece a few pixels long: there the gradient at the centre can point to such a
    // branch, and the steps land on it (nurbs7 x1: a branch at t = -36, 0.3 px from a centre
    // 0.8 px from the curve, 41/255; the first-order distance is that branch's too). Such a foot
    // lies outside the piece's box; then the steps start again from the centre's projection
    // into the chord strip, a point next to the piece, from which they reach its own branch.
    // (Not the first choice: outside a strongly curved piece the strip's edge can be pixels off
    // the curve, and the tangent there is not the one at the nearest point.)
    if (!on_piece(s, cutx, cuty)) {
        vec2 gc = vec2(cutx.z, cuty.z); // the chord's unit normal in pixels
        float gc2 = dot(gc, gc);
        s = gc2 > 0.0 ? gc * ((clamp(v_cut.z, v_c2.z, v_c2.w) - v_cut.z) / gc2) : vec2(0.0);
        s = newton_step(kind, s, uvx, uvy, g1);
        s = newton_step(kind, s, uvx, uvy, g1);
    }
    float g12 = dot(g1, g1);
    if (!(g12 > 0.0))
        discard;
    vec2 n = v_flags.z * g1 * inversesqrt(g12); // unit normal, towards the outside
    float d = -dot(n, s);                          // the centre's signed distance, > 0 outside
    if (abs(d) >= 0.75) // beyond the square's half diagonal: the correction below is 0
        discard;
    // the centre's side: where it is within EPS of the curve, the stencil's (u_h) stands for it
    float side = abs(d) <= EPS ? u_h : (d < 0.0 ? 1.0 : 0.0);
    o_cov = vec4(halfplane_coverage(n, -d) - side);
}

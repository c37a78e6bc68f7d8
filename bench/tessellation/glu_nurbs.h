/* SPDX-License-Identifier: MIT */
/* bench/tessellation: Mesa's GLU NURBS tessellator as the baseline of Guthe et al. 2005 §9
 * (Fig. 9). GLU is used in GLU_NURBS_TESSELLATOR mode (its renderer mode needs immediate-mode GL,
 * absent from a core context) with the frame's matrices loaded by gluLoadSamplingMatrices
 * (GLU_AUTO_LOAD_MATRIX off), GLU_PARAMETRIC_ERROR at ε_img pixels and culling on; the fans and
 * strips it emits are turned into indexed triangles. Kept in its own translation unit because
 * <GL/glu.h> pulls in the compatibility <GL/gl.h>, which does not mix with <GL/glcorearb.h>.
 */
#ifndef BT_GLU_NURBS_H
#define BT_GLU_NURBS_H

#include <stddef.h>
#include <stdint.h>

/* A trim curve in the surface's (u, v) domain: a polyline (order 0, pts as (u, v) pairs) or a
 * rational B-spline of `order` (pts as (w*u, w*v, w), knots n + order). */
typedef struct bt_glu_curve {
    int32_t order, n;
    const float *knots;
    const float *pts;
} bt_glu_curve;

/* A closed loop; GLU wants outer loops counter-clockwise and holes clockwise. */
typedef struct bt_glu_loop {
    const bt_glu_curve *curves;
    int32_t n_curves;
} bt_glu_loop;

/* A rational B-spline surface: homogeneous control points (w*x, w*y, w*z, w), u fastest. */
typedef struct bt_glu_surface {
    int32_t order_u, order_v, n_u, n_v;
    const float *knots_u, *knots_v; /* n_u + order_u, n_v + order_v */
    const float *cpw;               /* n_u * n_v * 4 */
    const bt_glu_loop *loops;
    int32_t n_loops; /* 0 = untrimmed */
} bt_glu_surface;

/* Output: vertices of 8 floats (position, normal as GLU emits it, (u, v)), triangle indices. The
 * (u, v) is what GLU 9's evaluator leaves after the position in the array it hands to the vertex
 * callback (outside the documented API: callers check it against the surface before using it). */
enum { BT_GLU_VERTEX_FLOATS = 8 };
typedef struct bt_glu_mesh {
    float *v;
    uint32_t *idx;
    size_t n_v, cap_v, n_idx, cap_idx;
    uint64_t primitives[4]; /* triangles, strips, fans, other (quads, quad strips, polygons) */
} bt_glu_mesh;

typedef struct bt_glu bt_glu;

/* NULL when GLU could not make a NURBS object. No GL context is needed. */
bt_glu *bt_glu_create(float tolerance_px);
void bt_glu_free(bt_glu *g);

/* Tessellates `s` for a frame whose matrices (column-major, as glLoadMatrixf takes them) map the
 * control points' space to clip space, and viewport (x, y, w, h). Clears `out` first (keeping its
 * storage). Returns 0 on success, -1 when out of memory, or the GLU error code it reported. */
int bt_glu_tessellate(bt_glu *g, const bt_glu_surface *s, const float model[16],
                      const float proj[16], const int32_t viewport[4], bt_glu_mesh *out);
/* GLU's text for a code from bt_glu_tessellate. */
const char *bt_glu_error_str(int code);
void bt_glu_mesh_free(bt_glu_mesh *m);

#endif

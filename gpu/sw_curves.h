/* SPDX-License-Identifier: MIT */
/* Resolution-independent filled 2D outlines (Santana §3-§5): closed loops of lines and
 * rational NURBS curves of any degree, filled by even-odd parity, with edges that stay exact and
 * anti-aliased at any zoom. Never installed.
 *
 * Algorithm: Santana, "Resolution Independent NURBS Curves Rendering using Programmable Graphics
 * Pipeline" (shared/papers/003), with Loop & Blinn 2005 for cubics:
 *  - §3: each loop is split into Bézier pieces (knot insertion, scenegraph/knot_insert.c) drawn as
 *    "curved triangles" whose fragment shader evaluates an implicit form F = 0 of the piece
 *    (§3.2 eq. 2 for conics, done right: curves_split.c says where eq. 2 is wrong; the Loop-Blinn
 *    implicit cubic k^3 - l m for integral cubics, classified serpentine / loop / cusp and split
 *    at inflections, double points and cusps). Higher degrees and rational cubics are replaced by
 *    C1 cubic Hermite pieces with a rigorous distance bound, built to 1/256 px and re-done when
 *    the view's zoom pushes that bound above 1/32 px (sw__curves_shape_fit_view). Not at 1/8 px:
 *    that is too late: shifting an edge by 1/8 px can change a pixel's coverage by
 *    32/255, beyond the 12/255 budget (SW__CURVES_REFIT_PX below).
 *  - The interior: instead of §3.1's constrained Delaunay triangulation, a stencil fan over the
 *    pieces' end points toggled with GL_INVERT (as the trim atlas does, Guthe et al. 2005 §4), the
 *    curved triangles toggling the region between each chord and its curve.
 *  - §4 (eq. 3-6): coverage of the pixel square from the signed distance F / |grad F| with the
 *    gradient from dFdx/dFdy, as an exact half-plane box-filter coverage (not §4's linear ramp),
 *    added as a correction to the stencil's centre classification in a float coverage target,
 *    then composited over what the target already holds (premultiplied "over"). No MSAA.
 *  - §5: shapes too small on screen for edge distances to be local are drawn at 8x into the
 *    coverage target and box-filtered down (the paper's view-based AA, with a box filter, which
 *    is area coverage, where §5 blurs with a Gaussian).
 */
#ifndef SW_CURVES_H
#define SW_CURVES_H

#include "sw_sg_geom.h"

#include <GL/glcorearb.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A closed loop: curves in order, each a clamped 2D rational B-spline in homogeneous form
 * (dim 3: w x, w y, w); curve k's end point must equal curve k+1's start (and the last's end the
 * first's start) within 1e-9 of the loop's size (the joins are snapped to the start points).
 * Pointers are borrowed for the call. */
typedef struct sw__curves_loop {
    const sw_sg_curve *curves;
    uint32_t n_curves;
} sw__curves_loop;

/* What a piece's implicit form is. */
typedef enum sw__curves_kind {
    SW__CURVES_LINE = 0,  /* F = k (k: signed distance to the line) */
    SW__CURVES_CONIC = 1, /* F = k^2 - l m (rational quadratic, exact) */
    SW__CURVES_CUBIC = 2, /* F = k^3 - l m (integral cubic, Loop-Blinn) */
    /* a piece of an integral cubic with a cusp: F = l + branch max(k, 0)^(3/2), the one branch
     * of k^3 = l^2 that the piece lies on (curves_split.c, emit_cubic_piece, says why) */
    SW__CURVES_CUSP = 3
} sw__curves_kind;

/* One drawable piece, in the shape's (model) coordinates. */
typedef struct sw__curves_piece {
    int32_t kind;
    int32_t n_cp;     /* 2, 3 or 4 Euclidean control points */
    double cp[4][2];  /* for a conic, cp[1] is the off-curve point and w its normalized weight */
    double w;         /* conic only: middle weight with end weights 1 */
    double branch;    /* cusp only: +1 or -1, which branch of k^3 = l^2 */
    double klm[3][3]; /* affine functionals: value = a x + b y + c with klm[j] = {a, b, c} */
    double s_chord;   /* sign: s_chord F < 0 between the chord and the curve (near the curve) */
    double s_in;      /* sign: s_in F < 0 on the inside (fill) side of the piece */
    double tan0[2];   /* unit tangents at the start and the end (direction of travel) */
    double tan1[2];
    uint32_t loop;
    uint32_t approx; /* 1: part of a Hermite approximation of a higher-degree / rational cubic */
} sw__curves_piece;

/* A point the anti-aliasing cannot treat as one smooth edge: a corner between pieces, a cusp, a
 * self-crossing of a loop cubic. Tests report pixels within 1 px of these separately. */
typedef struct sw__curves_shape {
    sw__curves_piece *pieces;
    size_t n_pieces;
    uint32_t n_loops;
    double (*corners)[2];
    size_t n_corners;
    double box[4];       /* x0, y0, x1, y1 of the control points */
    double approx_bound; /* largest distance bound of an approximated piece (model units) */
    double approx_tol;   /* the tolerance the approximations were built for */
    uint32_t rebuilds;   /* how many times sw__curves_shape_fit_view re-approximated */
    uint32_t n_approx;   /* pieces from approximations */
    /* the input, copied, for rebuilds */
    uint32_t n_src_loops;
    uint32_t *src_loop_n; /* curves per loop */
    sw_sg_curve *src;     /* all curves, pointing into src_data */
    double *src_data;
} sw__curves_shape;

/* The approximations' bound in pixels: built to SW__CURVES_BUILD_PX at the zoom asked for, redone
 * when a zoom pushes it above SW__CURVES_REFIT_PX, not as late as 1/8 px,
 * because a displacement of e px moves a pixel's coverage by up to e: 1/8 px is 32/255,
 * beyond the 12/255 coverage budget. 1/256 px costs about 2x the pieces of 1/16 px (the Hermite
 * error falls as h^4) and is redone every 8x of zoom. */
#define SW__CURVES_BUILD_PX (1.0 / 256.0)
#define SW__CURVES_REFIT_PX (1.0 / 32.0)

/* Builds a shape from loops. `px_per_unit` (> 0) is the zoom the approximations are built for
 * (their bound is SW__CURVES_BUILD_PX there). Orientation of the loops is free: even-odd parity
 * decides the inside. Errors: SW_ERR_INVALID_GEOMETRY (a curve fails sw_sg_curve_validate, is not
 * clamped or not 2D, a loop is not closed or has no area-bounding piece), SW_ERR_OUT_OF_MEMORY. */
sw_result sw__curves_shape_create(const sw__curves_loop *loops, uint32_t n_loops,
                                  double px_per_unit, sw__curves_shape **out, sw_status *status);
void sw__curves_shape_free(sw__curves_shape *shape); /* NULL allowed */

/* Re-approximates the higher-degree pieces if the stored bound exceeds SW__CURVES_REFIT_PX at
 * `px_per_unit` (the largest singular value of the view's linear part); the new bound is
 * SW__CURVES_BUILD_PX there.
 * *rebuilt (may be NULL) says whether it happened. Errors as sw__curves_shape_create. */
sw_result sw__curves_shape_fit_view(sw__curves_shape *shape, double px_per_unit, int *rebuilt,
                                    sw_status *status);

/* Calls fn with each rational Bézier piece of a clamped curve (homogeneous, dim 3, degree p), in
 * order, by knot insertion (scenegraph/knot_insert.c). Errors: SW_ERR_OUT_OF_MEMORY. */
typedef void (*sw__curves_bezier_fn)(void *ctx, const double *h, int32_t p);
sw_result sw__curves_for_each_bezier(const sw_sg_curve *c, sw__curves_bezier_fn fn, void *ctx,
                                     sw_status *status);

/* Evaluates a piece's implicit form at a model point (F as the shader computes it). */
double sw__curves_piece_eval(const sw__curves_piece *p, double x, double y);

/* The implicit form as the shader gets it (curves.c): F(u, v) = sum c[t] u^i v^j in the order
 * 1, u, v, u^2, u v, v^2, u^3, u^2 v, u v^2, v^3 with (u, v) = ((x, y) - centre) / size. */
void sw__curves_piece_local_form(const sw__curves_piece *p, double centre[2], double *size,
                                 double c[10]);

/* ---- outlines placed in 3D (curves_place.c; GL-free) --------------------------------------------
 * A plane of the eye-relative world (the eye at the origin): plane point (x, y) is
 * origin + x ax + y ay; ax and ay independent (not necessarily unit or orthogonal). */
typedef struct sw__curves_plane {
    double origin[3], ax[3], ay[3];
} sw__curves_plane;

/* The depth of a plane at the target's pixels: its inverse is affine on the screen,
 * 1 / d = inv_d[0] px + inv_d[1] py + inv_d[2] (d along the view axis; px, py in pixels). */
typedef struct sw__curves_depth {
    double inv_d[3];
    double near_plane; /* the frame's: window depth = near / d (reversed-Z, infinite far) */
} sw__curves_depth;

typedef struct sw__curves_projected {
    sw__curves_shape *shape; /* the outline in target pixels (py up), built for 1 px per unit;
                                NULL: none of it is in front of the near plane and near the
                                target */
    sw__curves_depth depth;  /* the plane's depth at each pixel, for sw__curves_draw_placed */
    uint32_t fallbacks;      /* pieces drawn as their chord: a control point stayed behind the eye
                                after SPLIT_CAP halvings (curves_place.c) */
} sw__curves_projected;

struct sw__gpu_view;
/* Maps the loops of a planar outline (in the plane's (x, y)) through the view into an outline in
 * the view's target pixels, exactly (projective images of its rational pieces), cut to the part
 * in front of the view's near plane and to a guard band around the target; curves_place.c says
 * how. The caller frees out->shape. Errors: those of sw__curves_shape_create (the loops', or a
 * cut loop the 2D path refuses), SW_ERR_OUT_OF_MEMORY. */
sw_result sw__curves_project(const sw__curves_loop *loops, uint32_t n_loops,
                             const sw__curves_plane *plane, const struct sw__gpu_view *view,
                             sw__curves_projected *out, sw_status *status);

/* ---- drawing (curves.c; the GL context's thread) ---------------------------------------------
 * A view maps model coordinates to pixels of the target: px = m[0] x + m[1] y + m[2],
 * py = m[3] x + m[4] y + m[5] (py up, GL's window convention), target size width x height. */
typedef struct sw__curves_view {
    double m[6];
    int32_t width, height;
} sw__curves_view;

typedef struct sw__curves_renderer sw__curves_renderer;

/* Compiles the programs. The context must be current. Errors: SW_ERR_GL, SW_ERR_OUT_OF_MEMORY. */
sw_result sw__curves_renderer_create(sw__curves_renderer **out, sw_status *status);
void sw__curves_renderer_free(sw__curves_renderer *r); /* NULL allowed; context current */

/* Debug switches for tests: a planted fault (0 none; 1 the implicit form's sign flipped in the
 * anti-aliasing pass) and whether small shapes use the view-based 8x path (default on). */
void sw__curves_renderer_set_fault(sw__curves_renderer *r, int fault);
void sw__curves_renderer_set_vbaa(sw__curves_renderer *r, int on);

/* Draws `shape` filled with the non-premultiplied colour `rgba` over whatever `target_fbo` (0: the
 * default framebuffer) holds, anti-aliased, without depth. Re-approximates first if the view
 * needs it (sw__curves_shape_fit_view). Leaves blending, the stencil test and the colour mask
 * disabled / default. Errors: SW_ERR_GL, SW_ERR_OUT_OF_MEMORY, and those of fit_view. */
sw_result sw__curves_draw(sw__curves_renderer *r, sw__curves_shape *shape,
                          const sw__curves_view *view, const float rgba[4], GLuint target_fbo,
                          sw_status *status);

/* As sw__curves_draw for a projected outline (view: 1 px per unit), composited with depth into
 * target_fbo, whose depth buffer holds the opaque scene (reversed-Z): each pixel's depth is the
 * outline plane's there, pulled toward the eye by SW__CURVES_DECAL_PULL of its distance (an
 * outline laid on a surface of the scene shows on it), tested GL_GEQUAL, not written. Leaves the
 * depth test enabled with GL_GREATER and depth writes on (the frame's state); the rest as
 * sw__curves_draw. */
#define SW__CURVES_DECAL_PULL (1.0 / 4096.0)
sw_result sw__curves_draw_placed(sw__curves_renderer *r, sw__curves_shape *shape,
                                 const sw__curves_view *view, const float rgba[4],
                                 GLuint target_fbo, const sw__curves_depth *depth,
                                 sw_status *status);

/* The GLSL sources of the curve programs (shaders.c embeds gpu/glsl): 0 curves.vert, 1
 * curves.frag, 2 curves_composite.frag. NULL for other indices. */
const char *sw__gpu_curves_glsl(int which);

#ifdef __cplusplus
}
#endif
#endif

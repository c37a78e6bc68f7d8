/* SPDX-License-Identifier: MIT */
/* bench/tessellation: the draw path of the GLU baseline (Guthe et al. 2005 §9, Fig. 9): triangles
 * GLU emitted, uploaded to a VBO and drawn with a small program that shades like gpu/'s surface
 * program (Lambert + headlight, two-sided, gamma-encoded) into an RGBA8 + 32F-depth target with
 * reversed-Z, through the same view-projection matrix as splinewalk's frame. GL owner thread only.
 */
#ifndef BT_VBO_DRAW_H
#define BT_VBO_DRAW_H

#include <stddef.h>
#include <stdint.h>

typedef struct bt_draw bt_draw;

/* Needs a current 4.3+ core context. NULL on failure, with the reason in err. */
bt_draw *bt_draw_create(int32_t width, int32_t height, char *err, size_t err_size);
void bt_draw_free(bt_draw *d);

/* Clears, uploads vertices (`stride` floats apart: position at 0, normal at 3) and triangle
 * indices, draws them and waits for the GPU (glFinish; pipelined: for the frame before). Returns 0
 * or the first GL error code (also one pending from before the call: GLU must not have touched GL).
 */
unsigned bt_draw_mesh(bt_draw *d, const float view_proj[16], const float *v, size_t n_v,
                      size_t stride, const uint32_t *idx, size_t n_idx);
/* The two halves of bt_draw_mesh, for a mesh uploaded once and drawn every frame (bench/peers'
 * OCCT peer): bt_draw_upload fills the VBO and index buffer; bt_draw_uploaded clears, draws the
 * first n_idx indices of what was uploaded last and waits (glFinish). Each returns 0 or the first
 * GL error code (also one pending from before the call). */
unsigned bt_draw_upload(bt_draw *d, const float *v, size_t n_v, size_t stride, const uint32_t *idx,
                        size_t n_idx);
unsigned bt_draw_uploaded(bt_draw *d, const float view_proj[16], size_t n_idx);
/* on = 1: a draw ends with a fence and waits for the frame before it instead of glFinish (one
 * frame in flight), so the time between successive draws' returns is the interval between frames'
 * completions, as for splinewalk's renderer (bench/peers). Waits for a pending frame first. */
void bt_draw_set_pipelined(bt_draw *d, int on);
/* Clears pending GL errors and returns how many there were. GLU issues a few fixed-function calls
 * (glPushAttrib, glEnable(GL_MAP2_VERTEX_4), ...) even in tessellator mode; in a core context they
 * only raise errors, which the caller drains and reports. */
unsigned bt_draw_drain_errors(void);
/* Pixels of the last frame that were drawn (alpha != 0). */
uint64_t bt_draw_covered(bt_draw *d);

#endif

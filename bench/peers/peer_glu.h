/* SPDX-License-Identifier: MIT */
/* bench/peers: Mesa's GLU NURBS tessellator as a peer (bench/tessellation's bt_glu wrapper:
 * GLU_NURBS_TESSELLATOR mode, GLU_AUTO_LOAD_MATRIX off with each frame's matrices passed by
 * gluLoadSamplingMatrices, GLU_SAMPLING_METHOD = GLU_PARAMETRIC_ERROR at ε_img pixels,
 * GLU_CULLING on, the *_DATA callbacks collecting fans and strips as indexed triangles). Every face
 * occurrence of the splinewalk scene (sw_sg_scene_traverse: instance transforms applied to the
 * homogeneous control points, made eye-relative per frame in float) is tessellated every frame
 * with its trim loops (gluBeginTrim, gluNurbsCurve with GLU_MAP1_TRIM_3), the triangles uploaded
 * to one VBO and drawn with splinewalk's view-projection, fenced, waiting for the frame before
 * (bench/tessellation's bt_draw, pipelined). GLU needs no GL context in tessellator mode; its few
 * fixed-function calls (glPushAttrib, ...) only raise errors in the 4.5 core context, which are
 * drained and counted. Mesa's GLU has no order limit that the samples reach (degree 12 surfaces,
 * degree 11 trims pass), but it crashes on a few faces it accepts: every face is screened once in
 * child processes (peer_glu.c says how) before the timed frames. A face GLU reports an error for
 * ("knot multiplicity greater than order of spline", ...) or that crashed it is counted as refused,
 * with its first error or signal, and not drawn.
 */
#ifndef BP_PEER_GLU_H
#define BP_PEER_GLU_H

#include "bench_peer.h"

int bp_peer_glu(const bp_job *job, bp_result *out);

#endif

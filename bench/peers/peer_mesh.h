/* SPDX-License-Identifier: MIT */
/* bench/peers: the OCCT peer's frames. The BREP of the scene is meshed once at the deflection
 * equal to ε_img at the path's nearest viewing distance — the object-space size of ε_img pixels
 * at the smallest eye-to-scene-box distance d along the path: ε_img · 2 d tan(fovy / 2) / height
 * — uploaded once into one VBO, and drawn every frame through splinewalk's view-projection
 * (translated to world space), fenced, waiting for the frame before (bench/tessellation's bt_draw,
 * pipelined). Its triangles per
 * frame are all of them: nothing is culled.
 */
#ifndef BP_PEER_MESH_H
#define BP_PEER_MESH_H

#include "bench_peer.h"

/* The deflection described above for the job's path (clamped below at 1e-6 of the box diagonal
 * for an eye inside the box). */
double bp_occt_deflection(const bp_job *job);
int bp_peer_occt(const bp_job *job, bp_result *out);

#endif

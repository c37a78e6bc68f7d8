/* SPDX-License-Identifier: MIT */
/* OpenSubdiv limit-surface evaluation behind a C interface (lod/osd/uniform_bicubic_osd.cpp).
 *
 * The independent reference for the project's uniform bicubic B-spline evaluator (the patch type
 * of Guthe et al. 2005 §6's bi-cubic hierarchy and of OpenSubdiv's regular Catmull-Clark faces):
 * a regular grid of control vertices is handed to Far::TopologyRefiner (Catmark, boundary
 * VTX_BOUNDARY_EDGE_AND_CORNER), refined adaptively, turned into a double-precision PatchTable and
 * evaluated with PatchMap::FindPatch + PatchTable::EvaluateBasis. No C++ exception crosses it.
 */
#ifndef SW_LOD_OSD_H
#define SW_LOD_OSD_H

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One evaluation request: face (face_i, face_j) of the grid is the quad of vertices (i, j),
 * (i+1, j), (i+1, j+1), (i, j+1); (s, t) in [0,1]^2 runs along +i and +j. */
typedef struct sw_lod_osd_sample {
    int32_t face_i, face_j;
    double s, t;
} sw_lod_osd_sample;

/* Evaluates the Catmull-Clark limit surface of an nx x ny grid of vertices (verts[(j*nx+i)*3],
 * i fastest; nx, ny >= 2) at `count` samples. Writes positions to pos[count*3] and, when not
 * NULL, the partial derivatives along s and t to ds[count*3] and dt[count*3]. On the faces whose
 * 4x4 neighbourhood lies inside the grid (1 <= face_i <= nx-3, same in j) the limit surface is the
 * uniform bicubic B-spline of that neighbourhood.
 * Returns SW_OK, SW_ERR_INVALID_ARGUMENT (bad sizes, NULL arrays, a face outside the grid, a
 * parameter outside [0,1] or not finite), SW_ERR_OUT_OF_MEMORY, or SW_ERR_INTERNAL when
 * OpenSubdiv fails or throws; the message says which. */
sw_result sw_lod_osd_eval_grid(const double *verts, int32_t nx, int32_t ny,
                               const sw_lod_osd_sample *samples, size_t count, double *pos,
                               double *ds, double *dt, sw_status *status);

/* OpenSubdiv's version as linked, e.g. "3.5.0" (static string). */
const char *sw_lod_osd_version(void);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* Simplification of a static LOD's level-0 mesh into coarser levels, behind a C interface
 * (modules/lodbuild/static_lod_openmesh.cpp: OpenMesh's Decimater, Kumar et al. 1997 §4.2).
 *
 * Borders first (§4.2): every boundary loop of the mesh is cut at its corner vertices into
 * polylines, and each polyline is simplified on its own (Douglas-Peucker in 3D against the level-0
 * polyline, choosing only among the vertices still present, so the levels are nested); the
 * vertices it keeps are locked, the ones it drops may only collapse along the border, and then
 * the interior is decimated by halfedge collapses with the quadric priority, the Hausdorff bound
 * (level-0 vertices within the level's tolerance of the mesh) and a normal-flip limit. Collapses
 * move no vertex, so every level's vertices are level-0 vertices. No exception escapes.
 */
#ifndef SW_LOD_STATIC_DECIMATE_H
#define SW_LOD_STATIC_DECIMATE_H

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_decimate_input {
    const double *pos; /* 3 per vertex */
    uint32_t n_vertices;
    const uint32_t *tri; /* 3 per triangle, consistently oriented per connected piece */
    uint32_t n_triangles;
    const uint8_t *corner;   /* per vertex: a border vertex every level keeps */
    const double *tolerance; /* per level, ascending: one-sided distance to level 0 allowed */
    int32_t n_levels;
} sw_lod_decimate_input;

/* Receives level k's triangles (indices of level-0 vertices), k = 0..n_levels-1 in order;
 * returning non-zero stops the decimation (sw_lod_static_decimate then returns SW_OK). */
typedef int (*sw_lod_decimate_level_fn)(void *ctx, int32_t level, const uint32_t *tri,
                                        uint32_t n_triangles);

/* Errors: SW_ERR_INVALID_GEOMETRY (a triangle OpenMesh cannot add: non-manifold input),
 * SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL. */
sw_result sw_lod_static_decimate(const sw_lod_decimate_input *in, sw_lod_decimate_level_fn fn,
                                 void *ctx, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

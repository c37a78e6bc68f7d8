/* SPDX-License-Identifier: MIT */
/* Exact point-to-triangle-mesh distance queries behind a C interface (lod/mesh_distance_cgal.cpp,
 * CGAL's AABB tree over the triangles in double precision). The static LOD builder
 * (lod/static_lod.c) measures the surface-to-mesh side of the two-sided distance with it.
 *
 * A built tree is immutable: queries may run from several threads at once.
 */
#ifndef SW_LOD_MESH_DISTANCE_H
#define SW_LOD_MESH_DISTANCE_H

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_mesh_distance sw_lod_mesh_distance;

/* Builds the tree over n_triangles >= 1 triangles tri[3k..3k+2] indexing pos[3 * vertex]; the
 * arrays are copied. Errors: SW_ERR_INVALID_ARGUMENT (no triangle), SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INTERNAL. */
sw_result sw_lod_mesh_distance_create(const double *pos, const uint32_t *tri, uint32_t n_triangles,
                                      sw_lod_mesh_distance **out, sw_status *status);
void sw_lod_mesh_distance_free(sw_lod_mesh_distance *d); /* NULL allowed */

/* Euclidean distance from p to the nearest point of the mesh. */
double sw_lod_mesh_distance_query(const sw_lod_mesh_distance *d, const double p[3]);

#ifdef __cplusplus
}
#endif
#endif

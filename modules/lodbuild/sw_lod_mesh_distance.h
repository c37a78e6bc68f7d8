/* SPDX-License-Identifier: MIT */
/* Exact point-to-triangle-mesh distance queries behind a C interface
 * (modules/lodbuild/mesh_distance_cgal.cpp, CGAL's AABB tree over the triangles in double
 * precision). The static LOD builder (modules/lodbuild/static_lod.c) measures the surface-to-mesh
 * side of the two-sided distance with it.
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

/* The one-sided Hausdorff distance h(A, M) = max over the points p of A's triangles of the
 * distance from p to the tree's mesh M, bounded from both sides:
 *  - lower: the largest distance at a point evaluated (vertices, edge midpoints, centroids and
 *    the subdivision's points): h >= lower;
 *  - upper: certified, h <= upper. A triangle T (or a piece of it) is certified by
 *    u(T) = min over candidate triangles C of M of max over T's corners v of dist(v, C), the
 *    candidates being the triangles of M nearest to T's corners: p -> dist(p, C) is convex for
 *    one convex C, so its maximum over T is at a corner, and dist(p, M) <= dist(p, C). Where no
 *    single candidate is close to all corners (T spans several triangles of M), T is split in
 *    four at its edge midpoints and its pieces certified, down to a depth cap; a capped piece is
 *    certified by the Lipschitz bound min_v dist(v, M) + its longest edge (every point of the
 *    piece lies within that edge of every corner).
 * A piece is accepted once its bound is at most max(upper so far, (1 + rel) x lower so far +
 * abs_floor), so upper ends at most (1 + rel) h + abs_floor unless pieces were capped. The closest
 * points are computed in double, so each distance is raised by 1e-14 of the coordinates' magnitude.
 */
typedef struct sw_lod_mesh_bound {
    double lower, upper;
    uint64_t pieces; /* pieces certified */
    uint64_t capped; /* of them at the depth cap (the Lipschitz fallback) */
} sw_lod_mesh_bound;

/* tri[3k..3k+2] index pos[3 * vertex], n_triangles >= 0 (none: lower = upper = 0). rel >= 0,
 * abs_floor >= 0; max_depth caps the splitting (each level splits a piece in four). Errors:
 * SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL. */
sw_result sw_lod_mesh_distance_bound(const sw_lod_mesh_distance *d, const double *pos,
                                     const uint32_t *tri, uint32_t n_triangles, double rel,
                                     double abs_floor, int32_t max_depth, sw_lod_mesh_bound *out,
                                     sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

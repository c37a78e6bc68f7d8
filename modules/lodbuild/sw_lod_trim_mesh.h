/* SPDX-License-Identifier: MIT */
/* 2D constrained Delaunay triangulation in a face's parameter domain, behind a C interface
 * (modules/lodbuild/trim_mesh_cgal.cpp, CGAL's Constrained_Delaunay_triangulation_2 with exact
 * predicates).
 *
 * Kumar et al. 1997 §4.3 meshes a trimmed patch with its trimming curves as borders: the static
 * LOD builder (modules/lodbuild/static_lod.c) inserts the flattened trim loops, the knot lines of
 * the selected Bézier patches and interior sample points, reads the triangles back, and inserts
 * refinement points until every triangle meets its deviation bound (§4.1). Constraints that cross
 * (a trim loop over a knot line) are split at their intersection, which CGAL inserts as a new
 * vertex (tag SW_LOD_CDT_NO_TAG). No C++ exception crosses this interface.
 *
 * One triangulation is used by one thread at a time.
 */
#ifndef SW_LOD_TRIM_MESH_H
#define SW_LOD_TRIM_MESH_H

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_LOD_CDT_NO_TAG 0xffffffffu /* a vertex CGAL created at a constraint intersection */

typedef struct sw_lod_cdt sw_lod_cdt;

/* Errors: SW_ERR_OUT_OF_MEMORY. On success *out is freed with sw_lod_cdt_free. */
sw_result sw_lod_cdt_create(sw_lod_cdt **out, sw_status *status);
void sw_lod_cdt_free(sw_lod_cdt *cdt); /* NULL allowed */

/* Inserts n points uv[2n] with caller tags (not SW_LOD_CDT_NO_TAG); ids[k] receives an id for
 * point k to name it in constraints (a point equal to an earlier one gets that one's id and keeps
 * its tag). Non-finite coordinates: SW_ERR_INVALID_ARGUMENT. Also SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INTERNAL (CGAL failed). */
sw_result sw_lod_cdt_insert_points(sw_lod_cdt *cdt, const double *uv, const uint32_t *tags,
                                   uint32_t n, uint32_t *ids, sw_status *status);

/* Inserts constrained segments between ids pairs[2k], pairs[2k+1] (ids from insert_points; a pair
 * of equal ids is skipped). Errors: SW_ERR_INVALID_ARGUMENT (unknown id), SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INTERNAL. */
sw_result sw_lod_cdt_insert_constraints(sw_lod_cdt *cdt, const uint32_t *pairs, uint32_t n_pairs,
                                        sw_status *status);

/* The current triangulation: every vertex (uv, tag) and every finite triangle, counter-clockwise
 * in (u, v). Arrays are malloc'ed; free with sw_lod_cdt_mesh_free. */
typedef struct sw_lod_cdt_mesh {
    double *uv;    /* 2 per vertex */
    uint32_t *tag; /* per vertex */
    uint32_t *tri; /* 3 per triangle */
    uint32_t n_vertices, n_triangles;
} sw_lod_cdt_mesh;

sw_result sw_lod_cdt_snapshot(sw_lod_cdt *cdt, sw_lod_cdt_mesh *out, sw_status *status);
void sw_lod_cdt_mesh_free(sw_lod_cdt_mesh *m); /* NULL allowed */

#ifdef __cplusplus
}
#endif
#endif

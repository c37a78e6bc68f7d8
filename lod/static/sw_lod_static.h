/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: static levels of detail of a super-surface, Kumar et al. 1997 §4.1-§4.3.
 *
 * Input: a set of trimmed rational Bézier patches (a super-surface, §3), each named by its face and
 * its (iu, iv) in the face's Bézier grid extracted over the face's uv_box, every net cut to its
 * knot rectangle intersected with uv_box — the patches lod/hierarchy/hierarchy.c builds its trees
 * from.
 *
 * Level 0, the adaptive tessellation within δ (§4.1, §4.3): per face, a constrained Delaunay
 * triangulation (CGAL, modules/lodbuild/trim_mesh_cgal.cpp) of the part of the face's (u, v) domain
 * covered by the selected patches and inside its trim loops. The loops and the selected patches'
 * knot lines are constraints, so the mesh follows the trim curves and no triangle straddles two
 * patches; triangles are refined until a rigorous bound of their deviation meets δ (see
 * static_lod.c).
 *
 * Levels 1..n, simplification (§4.2): OpenMesh's Decimater
 * (modules/lodbuild/static_lod_openmesh.cpp) with the borders simplified first and then locked.
 * Each level's ε_k is certified, not sampled: H(level, S) <= H(level, level 0) + H(level 0, S) <=
 * bound + δ, the distance between the two meshes bounded both ways by sw_lod_mesh_distance_bound
 * (modules/lodbuild/sw_lod_mesh_distance.h). sw_lod_static_measure is the independent check:
 * sampled distances to the exact surface.
 *
 * Memory of a chain (sw_lod_static_memory): per level 56 bytes per vertex (position 24, normal
 * 12, (u, v) 16, face 4) and 12 bytes per triangle; the levels after level 0 are small (their
 * triangle counts are in the test output). Building needs about 3x level 0 besides (the CDT, the
 * OpenMesh copy).
 */
#ifndef SW_LOD_STATIC_H
#define SW_LOD_STATIC_H

#include "sw_module_abi.h"

#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One Bézier patch of a super-surface. Same layout as sw_lod_ss_patch of the super-surface
 * clustering (lod/static/sw_lod_supersurface.h), so a cluster's patch range can be passed as it is.
 */
typedef struct sw_lod_static_patch {
    uint32_t face;
    uint16_t iu, iv;
} sw_lod_static_patch;

/* Zero fields take the defaults. */
typedef struct sw_lod_static_desc {
    double delta;      /* δ of level 0, object space; 0 = SW_LOD_STATIC_DELTA_REL x the diagonal
                          of the patches' control-point box */
    int32_t n_levels;  /* simplified levels after level 0 (1..8); 0 = 4; -1 = none */
    double eps_first;  /* target ε of level 1 in units of δ (> 1); 0 = 2 */
    double eps_growth; /* ratio of consecutive target ε (> 1); 0 = 4 */
    uint32_t max_vertices;           /* level 0 limit (SW_ERR_LIMIT beyond it); 0 = 4,000,000 */
    uint32_t max_vertices_per_patch; /* level 0 limit per patch, the same way; 0 = 4,096 (the
                          sample models need 30-1,500; where a patch's rational derivative bounds
                          are far too loose, tens of thousands: such a super-surface is refused in
                          a moment rather than decimated for many minutes, and drawn per frame) */
} sw_lod_static_desc;

/* One level. Vertices are points of the exact surface (decimation only removes vertices), each
 * with the face and (u, v) it was evaluated at. */
typedef struct sw_lod_static_level {
    double *positions;   /* 3 per vertex */
    float *normals;      /* 3 per vertex, unit, outward (the B-rep face orientation) */
    double *uv;          /* 2 per vertex: parameters of the vertex's face */
    uint32_t *face;      /* per vertex: scene face index */
    uint32_t *triangles; /* 3 per triangle, counter-clockwise seen from outside */
    uint32_t n_vertices, n_triangles;
    double eps;        /* declared ε_k, a certified bound: every point of the level is within eps
                          of the exact trimmed surface and vice versa (level 0: δ; level k:
                          δ + max(bound[0], bound[1])) */
    double eps_target; /* the ε the simplification aimed at (level 0: δ) */
    double bound[2];   /* certified upper bounds of the one-sided distances level -> level 0 and
                          level 0 -> level (sw_lod_mesh_distance_bound; 0 for level 0). The first
                          is certified only down to the second, which is all ε_k needs. */
    uint32_t n_triangles_dropped; /* triangles the level had when its arrays were dropped
                          (sw_lod_static_drop_undrawn: it is then empty, its ε kept); 0 else */
} sw_lod_static_level;

typedef struct sw_lod_static_chain {
    sw_lod_static_level *levels; /* n_levels + 1, fine -> coarse; [0] is the exact tessellation */
    int32_t n_levels;            /* entries of levels[] */
    uint32_t n_patches;
    double delta;
    double seconds[3];      /* build time: tessellation, decimation, certification of the ε_k */
    uint64_t capped_pieces; /* pieces of the certification at its depth cap (their bound is the
                               coarser Lipschitz one) */
} sw_lod_static_chain;

/* Builds the chain of the n >= 1 patches (repeats allowed, order irrelevant). desc may be NULL.
 * Precondition: SW_SG_SEC_FACES, LOOPS, CURVES and POOL required and validated.
 * Errors: SW_ERR_INVALID_ARGUMENT (a face or (iu, iv) out of range, bad desc values, no patch),
 * SW_ERR_INVALID_GEOMETRY (a trim loop that cannot be flattened, a mesh OpenMesh rejects),
 * SW_ERR_LIMIT (more than max_vertices), SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL (CGAL/OpenMesh).
 * On success *out is owned by the caller (sw_lod_static_free). */
sw_result sw_lod_static_build(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                              uint32_t n, const sw_lod_static_desc *desc, sw_lod_static_chain **out,
                              sw_status *status);
SW_MODULE_ABI void sw_lod_static_free(sw_lod_static_chain *chain); /* NULL allowed */

/* The builder the static set's pool tasks call: sw_lod_static_build, which needs CGAL and
 * OpenMesh, lives in the LOD-building module (sw_lod_build, libsplinewalk_lodbuild) above the
 * core; the module installs it. Without one, a unit's build fails at once with
 * SW_ERR_UNSUPPORTED (it is drawn by the per-frame path) and only levels read from a LOD cache
 * are drawn. Installing is idempotent and may race with readers (an atomic pointer); NULL
 * uninstalls. */
typedef sw_result (*sw_lod_static_build_fn)(const sw_sg_scene *scene,
                                            const sw_lod_static_patch *patches, uint32_t n,
                                            const sw_lod_static_desc *desc,
                                            sw_lod_static_chain **out, sw_status *status);
SW_MODULE_ABI void sw_lod_static_builder_install(sw_lod_static_build_fn build);
/* The installed builder, NULL when none. */
sw_lod_static_build_fn sw_lod_static_builder(void);

/* The default δ of level 0 relative to the super-surface's diagonal. Level 0 is never drawn
 * (the frame draws a level only at <= 24 triangles per patch; a rigorous tessellation has
 * hundreds): it is what the levels are decimated from, and the decimation's cost grows with its
 * size times its reduction to level 1 (each collapse re-projects the points its faces carry).
 * 2e-3 with level 1 at 2 δ keeps level 1's target (4e-3 x the diagonal) of the earlier 1e-3 / 4 δ
 * at half the level-0 triangles. */
#define SW_LOD_STATIC_DELTA_REL 2e-3

/* How the levels' ε_k are declared, hashed into the cache key so that caches declared by another
 * rule are stale: 2 = certified (sw_lod_mesh_distance_bound); 1.5 was the sampled distance x 1.5.
 */
#define SW_LOD_STATIC_EPS_RULE 2.0

/* The δ of level 0 when the desc leaves it 0: SW_LOD_STATIC_DELTA_REL x the diagonal of `box`
 * (the patches' control-point box), 1e-12 for an empty one. */
SW_MODULE_ABI double sw_lod_static_default_delta(const double box[6]);

/* *out = *in (NULL: all zero) with every zero field but delta replaced by its default, and the
 * values checked: SW_ERR_INVALID_ARGUMENT for a negative or non-finite δ, n_levels outside
 * -1..8, eps_first or eps_growth <= 1. delta stays 0 when left 0 (per patch set). */
SW_MODULE_ABI sw_result sw_lod_static_desc_resolve(const sw_lod_static_desc *in,
                                                   sw_lod_static_desc *out, sw_status *status);

/* A level's bytes per vertex (position 3 f64, normal 3 f32, (u, v) 2 f64, face u32) and per
 * triangle (3 u32), in memory and in the LODS cache alike. */
enum { SW_LOD_STATIC_VERTEX_BYTES = 56, SW_LOD_STATIC_TRIANGLE_BYTES = 12 };

/* Bytes the chain owns. */
size_t sw_lod_static_memory(const sw_lod_static_chain *chain);

/* A frame draws a static level only when it has at most this many triangles per Bézier patch:
 * its vertices are sent every frame, while the per-frame path evaluates each patch's grid in the
 * vertex shader from 16 control points, so a fine static level (a rigorous level 0 has 100-500
 * per patch on the sample models) costs more than the patches it replaces; the per-frame path
 * drew ~40 per patch on the 64-CrankArm grid's orbit. Kumar §4 meant static LODs for the far
 * field, where few triangles do. */
#define SW_LOD_STATIC_MAX_DRAWN_TRIANGLES_PER_PATCH 24.0

/* Whether a frame may draw level k of the chain: it is kept and within the limit above. */
int sw_lod_static_level_drawable(const sw_lod_static_chain *chain, int32_t k);

/* Frees the arrays of every level no frame draws, keeping each one's ε, bounds and former
 * triangle count (n_triangles_dropped); such a level is then empty (0 vertices, 0 triangles), in
 * memory and in a LOD cache written from it. Two kinds: a level finer than the limit above (level
 * 0 of most chains, which exists to decimate and certify the others from; levels only get
 * coarser with k, so the coarsest level within a tolerance was finer than a frame draws or is
 * still there) but the chain's coarsest mesh, which cluster proxies are made from (sw_lod_proxy.h),
 * and a level whose mesh is the next finer level's, bit for bit (a decimation with
 * nothing to collapse: a plane's two triangles), whose ε the finer one takes when smaller, so
 * that a frame draws the same mesh. The two take the 10^6-surface building's LOD cache from 1,107
 * to 420 MiB. Returns the bytes freed. */
size_t sw_lod_static_drop_undrawn(sw_lod_static_chain *chain);

/* How the two-sided distance is sampled. Zero fields take the defaults. */
typedef struct sw_lod_static_measure_desc {
    uint32_t seed;            /* offsets of the lattices; 0 = 1 */
    int32_t patch_samples;    /* surface lattice per patch side; 0 = 10 */
    int32_t triangle_samples; /* barycentric points per triangle at the level-0 edge length
                                 (more on larger triangles); 0 = 6 */
    int random;               /* 1: random points instead of lattices (same counts) */
} sw_lod_static_measure_desc;

typedef struct sw_lod_static_distance {
    double surface_to_mesh; /* max over samples of the exact trimmed surface: distance to mesh */
    double mesh_to_surface; /* max over mesh samples: an upper bound of the distance to the
                               surface at that sample (a surface point found by Newton) */
    uint64_t n_surface, n_mesh; /* samples taken */
} sw_lod_static_distance;

/* Measures `level` of the patches both ways. Surface samples: a lattice (or random points) of the
 * selected patches' domains inside the trim loops, the loops themselves (flattened within 1 % of
 * eps_hint > 0, the level's ε, in object space) and the super-surface's patch-rectangle borders.
 * Mesh samples: points of each triangle, more on larger ones (not its vertices, which lie on the
 * surface), each projected by Newton's iteration from its interpolated (u, v); a foot outside the
 * trimmed domain is moved to the nearest loop point, so each value bounds the distance from above.
 * level0 (may be NULL or equal to level) with its rigorous bound delta gives a second upper bound
 * at each mesh sample, the exact distance to level 0 plus delta, which Newton's local foot can
 * exceed where the surface folds back (a thread's next turn).
 * The surface side is a sampled maximum, so it can miss a peak between samples: it checks a
 * declared ε_k from below (the tests), it does not declare one. Errors as
 * sw_lod_static_build. */
sw_result sw_lod_static_measure(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                                uint32_t n, const sw_lod_static_level *level,
                                const sw_lod_static_level *level0, double delta, double eps_hint,
                                const sw_lod_static_measure_desc *desc, sw_lod_static_distance *out,
                                sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: a scene's static LODs, built lazily in the worker pool and chosen per frame
 * (Kumar et al. 1997 §4, merged with the per-frame path as ARCHITECTURE.md says).
 *
 * Units. The super-surfaces of §3 (sw_lod_supersurfaces_build) partition the scene's Bézier
 * patches, and a face's patches may fall into several of them. The frame draws whole faces
 * (a face's hierarchy, its trim texture, its fat borders), so the static path works on whole faces
 * too: every face goes to its home cluster, the one that holds most of its patches (ties: the
 * lowest index), and a unit is the set of faces of one home cluster. A unit is a super-surface
 * whose border follows face borders; its static LOD chain is built from all its faces' patches.
 * Units of faces shared by several instances are built once (object space of the faces).
 *
 * Slots. One per unit: its state word moves EMPTY -> QUEUED -> READY | FAILED by compare-and-swap
 * (only the winner of EMPTY -> QUEUED submits), the finished chain is immutable and published by
 * one atomic pointer store (release); sw_lod_static_set_get reads it with no lock. A chain is
 * never replaced, so readers need no epochs: chains live until the set is destroyed.
 * Builds are not cancelled when the camera moves on: a static LOD does not depend on the view, so
 * a build once asked for is used by every later frame that looks that way.
 *
 * Instances (Kumar §4.4: "the leaves of the hierarchy are super-surfaces"). A frame culls, picks
 * levels and back-culls per unit and instance transform, so the set groups the scene's face
 * occurrences by (unit, transform) once, when it is created, and builds a BVH whose leaves are
 * these unit instances (sw_lod_static_set_instances); frames never regroup.
 *
 * Threads: every function but create and destroy may be called from any thread at any time.
 */
#ifndef SW_LOD_STATIC_SET_H
#define SW_LOD_STATIC_SET_H

#include "sw_lod_static.h"
#include "sw_lod_supersurface.h"
#include "sw_sg_bvh.h"
#include "sw_th_pool.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_LOD_STATIC_NO_UNIT UINT32_MAX

typedef struct sw_lod_static_set sw_lod_static_set;

typedef enum sw_lod_static_state {
    SW_LOD_STATIC_EMPTY = 0,  /* not built, not asked for */
    SW_LOD_STATIC_QUEUED = 1, /* a build task is in the pool (or running) */
    SW_LOD_STATIC_READY = 2,  /* sw_lod_static_set_get returns the chain */
    SW_LOD_STATIC_FAILED = 3  /* the build failed; never retried (the unit is drawn dynamically) */
} sw_lod_static_state;

typedef struct sw_lod_static_unit {
    uint32_t first_face, n_faces;    /* into sw_lod_static_set_faces() */
    uint32_t first_patch, n_patches; /* into sw_lod_static_set_patches() */
    double box[6];                   /* object-space box of its cut Bézier nets: lo xyz, hi xyz */
    double delta;                    /* δ its level 0 is built with (known before the build) */
    sw_lod_cone cone; /* outward normals of its patches (their pseudo-Gauss cones enclosed, Kumar
                         §4.4), object space; the full cone unless every face of the unit is in a
                         closed shell of consistent orientation (SW_SG_FACE_CLOSED_SHELL), as
                         sw_lod_face_cones bounds faces: an open sheet is seen from both sides */
} sw_lod_static_unit;

/* One face occurrence of a unit instance: the face and its resolved colour as the scene's
 * traversal gives it ({-1, -1, -1, -1} when it gives none). */
typedef struct sw_lod_static_occ {
    uint32_t face;
    float color[4];
} sw_lod_static_occ;

/* One unit under one instance transform (or, with unit SW_LOD_STATIC_NO_UNIT, one occurrence of a
 * face that has no unit: every face occurrence of the scene is in exactly one instance). */
typedef struct sw_lod_static_instance {
    uint32_t unit;
    uint32_t first_occ, n_occ; /* its face occurrences, in traversal order, in occs[] */
} sw_lod_static_instance;

/* The unit instances and their BVH (sw_sg_bvh.h). bvh->items[k] is instance
 * instances[bvh->items[k].face]; sw_sg_bvh_item_at gives its transform (world) and box: the
 * unit's box, or the lone face's control-net box (sw_sg_bvh_face_box), through the transform
 * (sw_sg_box_transform), as the BVH stores it (rounded outward); colour unset. face_boxes:
 * sw_sg_bvh_face_box of every face (6 doubles each), so that a frame boxes an occurrence exactly
 * as the face-occurrence BVH (sw_sg_bvh_build) does. scene_box: the world box of every face
 * occurrence so boxed, the exact box (bvh->box) of that BVH. */
typedef struct sw_lod_static_instances {
    const sw_sg_bvh *bvh;
    const sw_lod_static_instance *instances;
    uint32_t n_instances;
    const sw_lod_static_occ *occs;
    uint32_t n_occs;
    const double *face_boxes;
    double scene_box[6];
} sw_lod_static_instances;

/* Zero fields take the defaults of each part. */
typedef struct sw_lod_static_set_desc {
    sw_lod_ss_desc clustering; /* §3 */
    sw_lod_static_desc levels; /* §4.1-§4.2; delta 0 = per unit, SW_LOD_STATIC_DELTA_REL x its
                                  diagonal */
    int keep_undrawn; /* 1: chains keep the levels no frame draws (sw_lod_static_drop_undrawn),
                         for tests that force them into a frame to check their joins */
    int ignore_cached_proxies; /* 1: sw_lod_static_set_load adopts a cache's chains only, so that
                                  the proxies are built (tests of the build against the cache) */
} sw_lod_static_set_desc;

typedef struct sw_lod_static_set_stats {
    uint32_t n_units, ready, failed, queued;
    uint64_t builds;      /* chains built by the pool */
    uint64_t adopted;     /* chains handed in (sw_lod_static_set_adopt: read from a cache) */
    double build_seconds; /* summed over builds (pool threads in parallel) */
    size_t memory_bytes;  /* the chains' memory */
    /* cluster proxies (sw_lod_static_set_build_proxies) */
    uint64_t proxies, proxies_failed; /* nodes given a proxy; candidates that could not be */
    uint64_t proxies_pruned;          /* built, then dropped: over the proxies' memory budget */
    uint64_t proxy_triangles;
    size_t proxy_bytes;
    double proxy_seconds; /* summed over builds */
    int proxies_building; /* 1 while builds are queued or running */
    int proxies_adopted;  /* 1: the proxies were read from a cache (sw_lod_static_set_load) */
} sw_lod_static_set_stats;

/* Clusters the scene (§3), forms the units and their instances with the instances' BVH; builds no
 * LOD. scene: FACES, LOOPS, CURVES, ADJACENCY, NODES and POOL required and validated; it and pool
 * outlive the set. desc may be NULL. Errors: those of sw_lod_supersurfaces_build,
 * SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (2^31 face occurrences or more). */
sw_result sw_lod_static_set_create(const sw_sg_scene *scene, sw_th_pool *pool,
                                   const sw_lod_static_set_desc *desc, sw_lod_static_set **out,
                                   sw_status *status);
/* Builds queued from now on return without building (those running finish): called before a
 * set that is going away is destroyed, so that its destroy waits for the running builds only.
 * Any thread; NULL ok. */
void sw_lod_static_set_cancel(sw_lod_static_set *set);
/* Waits for the builds in flight, frees every chain. No other thread may use the set. NULL ok.
 * May run as a pool task (it runs pool tasks while it waits). */
void sw_lod_static_set_destroy(sw_lod_static_set *set);

uint32_t sw_lod_static_set_unit_count(const sw_lod_static_set *set);
/* A number no other set of this process has had (1, 2, ...): what keys a set's chains where the
 * set's address could be a freed set's (GPU copies of its levels). */
uint64_t sw_lod_static_set_serial(const sw_lod_static_set *set);
const sw_sg_scene *sw_lod_static_set_scene(const sw_lod_static_set *set);
/* The level settings the set builds with (its desc's, zero fields as given). */
const sw_lod_static_desc *sw__lod_static_set_levels(const sw_lod_static_set *set);
/* A chain about to be published: its undrawn levels dropped unless the set keeps them. */
void sw__lod_static_set_trim(const sw_lod_static_set *set, sw_lod_static_chain *chain);
/* The unit of `face`, SW_LOD_STATIC_NO_UNIT for a face out of range. */
uint32_t sw_lod_static_set_unit_of(const sw_lod_static_set *set, uint32_t face);
const sw_lod_static_unit *sw_lod_static_set_unit(const sw_lod_static_set *set, uint32_t unit);
const uint32_t *sw_lod_static_set_faces(const sw_lod_static_set *set);
const sw_lod_static_patch *sw_lod_static_set_patches(const sw_lod_static_set *set);
const sw_lod_supersurfaces *sw_lod_static_set_supersurfaces(const sw_lod_static_set *set);
/* The unit instances and their BVH (borrowed, immutable, valid as long as the set). */
const sw_lod_static_instances *sw_lod_static_set_instances(const sw_lod_static_set *set);

sw_lod_static_state sw_lod_static_set_state(const sw_lod_static_set *set, uint32_t unit);
/* The unit's chain once READY, else NULL. No lock (acquire load). */
const sw_lod_static_chain *sw_lod_static_set_get(const sw_lod_static_set *set, uint32_t unit);
/* Submits the unit's build unless it is QUEUED, READY or FAILED. SW_OK, SW_ERR_INVALID_ARGUMENT
 * (unit out of range), SW_ERR_OUT_OF_MEMORY (not submitted; the slot stays EMPTY). */
sw_result sw_lod_static_set_request(sw_lod_static_set *set, uint32_t unit, sw_th_priority priority);
/* Converged frames: requests the unit and returns once it is READY or FAILED, running pool tasks
 * meanwhile. Returns its state then (EMPTY only when the request could not be submitted). */
sw_lod_static_state sw_lod_static_set_wait(sw_lod_static_set *set, uint32_t unit);
/* Hands in a chain made elsewhere (a cache read from a file) for an EMPTY unit; the set owns it
 * from then on, whatever the result. SW_ERR_INVALID_ARGUMENT: unit out of range or not EMPTY. */
sw_result sw_lod_static_set_adopt(sw_lod_static_set *set, uint32_t unit,
                                  sw_lod_static_chain *chain);
/* The failure of a FAILED unit (SW_OK otherwise), and its message (NULL otherwise). */
sw_result sw_lod_static_set_failure(const sw_lod_static_set *set, uint32_t unit,
                                    const char **message);
void sw_lod_static_set_get_stats(const sw_lod_static_set *set, sw_lod_static_set_stats *out);

/* ---- cluster proxies (static_proxy.c; sw_lod_proxy.h: how a proxy is made, why its bound holds)
 * Across objects (Erikson et al. 2001's HLODs): a node of the unit-instance BVH with enough
 * instances under it gets one mesh standing for all of them, with a bound `err` certified both
 * ways against their exact surfaces. A frame's cut stops at a node whose proxy is within the
 * view's tolerance at the node box's nearest depth and draws it instead of its subtree. Parts keep
 * the instances' colours apart (a draw each).
 *
 * Cracks. Within its bound a proxy may have gaps the clustering did not weld: between units whose
 * levels approximate a shared border independently (ε_a + ε_b apart), and where a strip thinner
 * than a cell collapsed. Each is bounded by open edges (used by one triangle of the part), at most
 * 2 err wide, so at most 2 ε_img = 1 px on screen where the proxy is drawn. The frame draws every
 * open edge as a one-pixel line too (the rasterizer's diamond rule covers each pixel whose centre
 * lies within half a pixel of the line along its minor axis, and a pixel inside a gap under 1 px
 * wide is that close to one of its two sides): the proxies' analogue of fat borders. */
typedef struct sw_lod_proxy {
    double centre[3];           /* world: the point the parts' positions are relative to */
    sw_lod_static_level *parts; /* one per colour: positions and normals only (uv, face NULL) */
    float (*colors)[4];         /* per part: the instances' colour as the set gives it */
    uint32_t **lines;           /* per part: its open edges (2 vertex indices each) */
    uint32_t *n_lines;          /* per part: how many */
    uint32_t n_parts;
    uint32_t key;     /* parts are numbered key .. key + n_parts - 1, unique in the set */
    double err;       /* world units, both ways, to the exact surfaces of the instances */
    double input_err; /* of it, the inputs' own (their levels' ε, child proxies' err) */
    double cell;      /* the clustering's cell */
    double range[3];  /* positions lie within +-range of the centre (quantized so: the LOD cache) */
    uint32_t n_triangles, instances;
    uint64_t faces; /* face occurrences of those instances */
    uint64_t input_triangles, vanished;
} sw_lod_proxy;

/* Starts building the proxies of every node whose instances' chains are READY (a cache adopted),
 * in the pool at background priority; once per set (later calls do nothing). Proxies are
 * published as they are built, within a memory budget (static_proxy.c). Errors:
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw_lod_static_set_build_proxies(sw_lod_static_set *set, sw_status *status);
/* 1 once sw_lod_static_set_build_proxies was called (some proxies may be built yet), and once
 * every proxy build has finished. No lock. */
int sw_lod_static_set_proxies_started(const sw_lod_static_set *set);
int sw_lod_static_set_proxies_done(const sw_lod_static_set *set);
/* Returns once the proxy builds started are done, running pool tasks meanwhile. */
void sw_lod_static_set_wait_proxies(sw_lod_static_set *set);
/* The proxy of a node of sw_lod_static_set_instances()->bvh once built, else NULL. No lock. */
const sw_lod_proxy *sw_lod_static_set_proxy(const sw_lod_static_set *set, uint32_t node);

/* static_proxy.c, static_lod_set.c and static_lod_io.c */
typedef struct sw__lod_proxies sw__lod_proxies;
void sw__lod_proxy_free(sw_lod_proxy *x); /* NULL ok; parts up to n_parts, lines if any */
/* A coordinate within +-range as the LOD cache stores a proxy's (65536 steps), and back. */
uint16_t sw__lod_proxy_coord_pack(double x, double range);
double sw__lod_proxy_coord_unpack(uint16_t q, double range);
/* A unit normal as the LOD cache stores a proxy's (octahedral, two snorm16), and back. */
void sw__lod_proxy_normal_pack(const float n[3], int16_t q[2]);
void sw__lod_proxy_normal_unpack(const int16_t q[2], float n[3]);
/* Finds the open edges of every part that has none yet (lines, n_lines); 0: out of memory. */
int sw__lod_proxy_find_lines(sw_lod_proxy *x);
/* The point a proxy's positions are relative to: the centre of its node's box (the builder's and
 * the cache reader's, computed alike so that a proxy read back is the one built). */
void sw__lod_proxy_centre(const double box[6], double centre[3]);
/* 1 when the node is one the set's proxy builds consider (enough instances under it). */
int sw__lod_proxy_candidate(const sw_lod_static_set *set, uint32_t node);
/* Hashes what proxies are made from besides the chains (instances, transforms, colours, BVH) and
 * the build's rules: a cache's proxies are stale when it differs. */
uint32_t sw__lod_proxies_key(const sw_lod_static_set *set);
/* Publishes by_node[n] (one per BVH node, NULL: none), taking them (entries set NULL), with the
 * counts of their build (nodes that could not have one, proxies dropped over the budget), and
 * marks the proxies started and done; SW_ERR_INVALID_ARGUMENT (nothing taken) when the set's
 * proxies were already started. */
sw_result sw__lod_proxies_adopt(sw__lod_proxies *p, sw_lod_proxy **by_node, uint64_t failed,
                                uint64_t pruned);
sw_result sw__lod_static_set_adopt_proxies(sw_lod_static_set *set, sw_lod_proxy **by_node,
                                           uint64_t failed, uint64_t pruned);
int sw__lod_static_set_ignores_cached_proxies(const sw_lod_static_set *set);
sw_result sw__lod_proxies_create(uint32_t n_nodes, sw__lod_proxies **out, sw_status *status);
void sw__lod_proxies_destroy(sw_th_pool *pool, sw__lod_proxies *p); /* waits for its builds */
sw_result sw__lod_proxies_start(const sw_lod_static_set *set, sw__lod_proxies *p, sw_th_pool *pool,
                                sw_status *status);
const sw_lod_proxy *sw__lod_proxies_get(const sw__lod_proxies *p, uint32_t node);
void sw__lod_proxies_stats(const sw__lod_proxies *p, sw_lod_static_set_stats *out);
void sw__lod_proxies_wait(sw_th_pool *pool, sw__lod_proxies *p);
int sw__lod_proxies_started(const sw__lod_proxies *p);
int sw__lod_proxies_done(const sw__lod_proxies *p);
int sw__lod_static_set_cancelled(const sw_lod_static_set *set);

/* ---- the LOD cache (static_lod_io.c) ---------------------------------------------------------
 * The READY chains and the proxies as one byte string (the .sws file's LODS section, `splinewalk
 * build-lod`):
 *   "SWLODS\0\0", u32 version 3, u32 unit count, u64 key, the level settings (f64 δ (0: relative),
 *   f64 δ relative to the diagonal (0 when δ is given), f64 eps_first, eps_growth, the ε rule,
 *   i32 n_levels, u32 max_vertices, u32 max_vertices_per_patch), then per unit a u32 (0: no chain,
 *   1: a chain follows): i32 levels, u32 patches, f64 δ, and per level u32 vertices, u32
 *   triangles, f64 ε, ε_target, bound[2] (the certified distances to and from level 0), then
 * positions (f64 x 3), normals (f32 x 3), (u, v) (f64 x 2), faces (u32) per vertex and the
 * triangles (u32 x 3); little-endian. A level no frame draws is stored empty, its ε kept
 * (sw_lod_static_drop_undrawn); a reader drops such levels of an older cache as it reads them.
 * The key hashes the units (their faces and patches) and the
 * level settings, so a cache made for another clustering, scene or setting is refused rather than
 * misread.
 *   Then the cluster proxies: u32 0 (none stored) or 1, and after a 1: u32 key
 *   (sw__lod_proxies_key), u32 BVH nodes, u32 proxies, u64 candidates that failed, u64 pruned,
 *   and per proxy in increasing node order: u32 node, f64 err, input_err, cell, range[3],
 *   u32 instances, u64 faces, input_triangles, vanished, u32 parts, and per part f32 colour[4],
 *   u32 vertices, u32 triangles, positions relative to the centre of the node's box, each
 *   coordinate one of 65536 steps across +-range (u16 x 3: sw__lod_proxy_coord_pack; the builder
 *   rounds them so and counts the rounding in err), normals (octahedral, i16 x 2:
 *   sw__lod_proxy_normal_pack; the builder rounds them so too), triangles (u16 x 3 when the part
 *   has at most 65536 vertices, else u32 x 3). Open edges are found again on reading. Version 2 is
 * version 3 without the proxies (read as such). Proxies of a stale key (other instances,
 * transforms, colours or build rules) are skipped, the chains still adopted; the renderer then
 * builds the proxies in the pool. */

/* *out (malloc, the caller frees) and *size. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw_lod_static_set_serialize(const sw_lod_static_set *set, void **out, size_t *size,
                                      sw_status *status);
/* Adopts every chain of a cache made by sw_lod_static_set_serialize for the same units and
 * settings; `what` names the source in messages. All or nothing: the whole string is checked
 * (bounds, counts, finite values, triangle and face indices inside the unit) before one chain is
 * adopted. *adopted (may be NULL) = chains adopted. Errors: SW_ERR_FORMAT (with the offset),
 * SW_ERR_VERSION, SW_ERR_INVALID_ARGUMENT (a cache of other units or settings: stale),
 * SW_ERR_OUT_OF_MEMORY. Units already READY or QUEUED keep what they have. */
sw_result sw_lod_static_set_load(sw_lod_static_set *set, const void *data, size_t size,
                                 const char *what, uint32_t *adopted, sw_status *status);

/* What a cache holds, read without the scene's clustering (`splinewalk info`): its structure is
 * checked (header, bounds, counts, finite ε), not whether it fits the scene's super-surfaces,
 * which the first renderer to use it checks. Per level index k: the chains with a level k and
 * their vertices, triangles and ε range. */
enum { SW_LOD_CACHE_MAX_LEVELS = 9 };
/* The level settings a cache was built with: the resolved desc (delta 0: delta_rel x each
 * super-surface's diagonal) and the rule that declared its ε (SW_LOD_STATIC_EPS_RULE). */
typedef struct sw_lod_static_cache_settings {
    sw_lod_static_desc levels;
    double delta_rel, eps_rule;
} sw_lod_static_cache_settings;
typedef struct sw_lod_static_cache_summary {
    uint32_t version, units, chains, max_levels;
    uint64_t key;
    sw_lod_static_cache_settings settings;
    double delta_min, delta_max; /* level 0's rigorous bound δ over the chains (object units) */
    uint32_t level_chains[SW_LOD_CACHE_MAX_LEVELS];
    uint32_t level_dropped[SW_LOD_CACHE_MAX_LEVELS]; /* of those, stored empty: no frame draws
                                                        them (sw_lod_static_drop_undrawn) */
    uint64_t level_vertices[SW_LOD_CACHE_MAX_LEVELS], level_triangles[SW_LOD_CACHE_MAX_LEVELS];
    double level_eps_min[SW_LOD_CACHE_MAX_LEVELS], level_eps_max[SW_LOD_CACHE_MAX_LEVELS];
    uint32_t proxies;                         /* stored cluster proxies (0: none stored) */
    uint64_t proxy_triangles, proxy_vertices; /* over them */
    uint64_t proxy_instances;                 /* under the largest proxy (its node's) */
    double proxy_err_min, proxy_err_max;      /* world units */
    size_t proxy_bytes;                       /* of the section's bytes */
} sw_lod_static_cache_summary;
/* Errors: SW_ERR_FORMAT (with the offset), SW_ERR_VERSION. */
sw_result sw_lod_static_cache_summarize(const void *data, size_t size, const char *what,
                                        sw_lod_static_cache_summary *out, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

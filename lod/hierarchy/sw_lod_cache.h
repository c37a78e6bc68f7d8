/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: the per-scene cache of face hierarchies (ARCHITECTURE.md: "once per surface,
 * on first sight, in the worker pool"; Guthe et al. 2005 §6 hierarchies, extended below their
 * leaves for close-ups as §7's traversal demands finer nodes).
 *
 * One slot per face (instances share their face's slot). A request submits one build task to
 * the pool when the face has no hierarchy and none is in flight; the slot's state word moves
 * EMPTY -> QUEUED -> RUNNING -> READY | FAILED by compare-and-swap, and only the task that wins
 * QUEUED -> RUNNING builds, so a face is built at most once however many threads request it.
 * The finished hierarchy is immutable and published by one atomic pointer store (release);
 * sw_lod_cache_get reads it with no lock (acquire) and returns NULL while there is none, and the
 * walkthrough renderer draws something coarser meanwhile.
 *
 * Cancellation: a request names a token and generation (sw_th_token). The pool skips a build
 * task whose generation went stale before it started (sw_th_pool.h); its slot is then logically
 * EMPTY again (sw_lod_cache_state says so) and the next fresh request for the face reclaims it
 * and submits anew. A queued build is also superseded by a request of higher priority (a
 * background prefetch the frame now needs), so priorities keep meaning what they say.
 *
 * Converged mode: sw_lod_cache_request_group adds to the caller's group one small task that
 * returns when the face is READY or FAILED (it waits on the slot's own build group and so runs
 * pool tasks meanwhile); sw_th_group_wait on the caller's group then returns with every face of
 * the frame built.
 *
 * Refinement below the leaves: sw_lod_cache_refine builds, in the pool, a finer hierarchy of one
 * leaf's rectangle (sw_lod_hierarchy_build restricted to it) and publishes a NEW version of the
 * face's hierarchy = the old nodes (same indices) + the new subtree hung under the leaf, by one
 * atomic pointer exchange. At most one refinement per face is in flight.
 *
 * Reclamation of replaced versions (epoch-based, Fraser 2004 / RCU style). The rule:
 *   - a reader brackets every use of pointers from sw_lod_cache_get with
 *     sw_lod_cache_reader_enter / sw_lod_cache_reader_leave on its own reader slot
 *     (sw_lod_cache_reader_add; one per thread; the single-renderer case uses one slot and
 *     enters/leaves once per frame);
 *   - enter records the global epoch in the reader's slot, leave clears it;
 *   - a version replaced at global epoch e (the publisher then advances the epoch to e + 1) is
 *     freed only once every reader slot is clear or holds an epoch > e: every reader that could
 *     have loaded the old pointer entered at an epoch <= e and has left since.
 * Retired versions are collected after each publication and by sw_lod_cache_collect. A pointer
 * obtained outside a read section stays valid only as long as nobody refines that face.
 * Plain memory only: GL objects made from a hierarchy are the renderer's to retire after a fence.
 *
 * Locks: readers (get, enter, leave, state, memory) never take one. The list of retired versions
 * is protected by a mutex taken only by publishers and collectors (see hierarchy_cache.c).
 */
#ifndef SW_LOD_CACHE_H
#define SW_LOD_CACHE_H

#include "sw_lod_hierarchy.h"
#include "sw_sg_scene.h"
#include "sw_th_pool.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_cache sw_lod_cache;

typedef enum sw_lod_cache_state {
    SW_LOD_CACHE_EMPTY = 0,   /* no hierarchy, no build in flight (or its request went stale) */
    SW_LOD_CACHE_QUEUED = 1,  /* a build task is waiting in the pool */
    SW_LOD_CACHE_RUNNING = 2, /* a build task is building */
    SW_LOD_CACHE_READY = 3,   /* sw_lod_cache_get returns the hierarchy */
    SW_LOD_CACHE_FAILED = 4   /* the build failed; never retried (sw_lod_cache_failure) */
} sw_lod_cache_state;

/* Zero-initialise for the defaults. */
typedef struct sw_lod_cache_desc {
    sw_lod_hierarchy_desc hierarchy; /* per-face build settings; use_box and uv_box are replaced
                                        by each face's trim box */
    uint32_t max_readers;            /* reader slots; 0 = 64 */
} sw_lod_cache_desc;

/* Who asks, and how urgently. NULL in the calls below means FRAME priority, never stale. */
typedef struct sw_lod_cache_req {
    sw_th_priority priority; /* 0 = FRAME */
    sw_th_token *token;      /* NULL: never stale; else must outlive the request's tasks */
    uint64_t generation;     /* the token generation the request belongs to */
} sw_lod_cache_req;

typedef enum sw_lod_refine_outcome {
    SW_LOD_REFINE_SUBMITTED = 0, /* a refinement task is in the pool */
    SW_LOD_REFINE_BUSY = 1,      /* another refinement of this face is in flight: ask again */
    SW_LOD_REFINE_DONE = 2,      /* nothing to do: the node is no longer a leaf, or already meets
                                    the tolerance */
    SW_LOD_REFINE_STALE = 3      /* the request's generation is already stale */
} sw_lod_refine_outcome;

typedef struct sw_lod_cache_stats {
    uint64_t submitted;   /* build tasks handed to the pool */
    uint64_t builds;      /* hierarchy builds run (each face at most once) */
    uint64_t failed;      /* of which failed */
    uint64_t cancelled;   /* queued builds found stale (skipped by the pool) and reclaimed */
    uint64_t superseded;  /* queued builds replaced by a more urgent request */
    uint64_t refinements; /* versions published by refinement */
    uint64_t refine_cancelled;
    uint64_t versions_retired, versions_freed;
    size_t memory_bytes;    /* sw_lod_cache_memory */
    uint64_t refine_capped; /* refinements of leaves above their tolerance refused: at
                               the depth cap, a parameter rectangle at the rounding floor, or a
                               hierarchy at its node cap (hierarchy_cache.c, refine_leaf) */
} sw_lod_cache_stats;

/* scene: its FACES and POOL sections required and validated (sw_sg_scene_require), and it must
 * outlive the cache. pool: outlives the cache. desc may be NULL. Errors: SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INVALID_ARGUMENT (max_readers > 65536). *out is NULL on failure. */
sw_result sw_lod_cache_create(const sw_sg_scene *scene, sw_th_pool *pool,
                              const sw_lod_cache_desc *desc, sw_lod_cache **out, sw_status *status);
/* Precondition: every group passed to the cache has been waited for, and no other thread uses
 * the cache. Waits for the cache's own build and refinement tasks, then frees every version.
 * NULL is a no-op. */
void sw_lod_cache_destroy(sw_lod_cache *cache);

uint32_t sw_lod_cache_face_count(const sw_lod_cache *cache);
/* The pool and scene the cache was created with (borrowed): a converged frame waits for its
 * requests with sw_th_group_wait on this pool. */
sw_th_pool *sw_lod_cache_pool(const sw_lod_cache *cache);
const sw_sg_scene *sw_lod_cache_scene(const sw_lod_cache *cache);

/* Any thread. Submits the face's build unless it is READY, FAILED, RUNNING, or QUEUED by a
 * request that covers this one (same token and generation, or no token, and at least this
 * priority). A stale request (its generation no longer current) submits nothing. req may be NULL.
 * Returns SW_OK, the stored failure of a FAILED face (never rebuilt), SW_ERR_INVALID_ARGUMENT
 * (face out of range) or SW_ERR_OUT_OF_MEMORY (the task could not be submitted; the slot is left
 * EMPTY). */
sw_result sw_lod_cache_request(sw_lod_cache *cache, uint32_t face, const sw_lod_cache_req *req);

/* Converged mode: as sw_lod_cache_request, and unless the face is READY or FAILED, adds one task
 * to `group` that completes when it is (or when the request goes stale). After
 * sw_th_group_wait(pool, group) every face so requested with a current generation is READY or
 * FAILED. Results as sw_lod_cache_request (a FAILED face returns its failure and adds nothing). */
sw_result sw_lod_cache_request_group(sw_lod_cache *cache, uint32_t face,
                                     const sw_lod_cache_req *req, sw_th_group *group);

/* Lock-free. The face's current hierarchy, or NULL when it is not READY. Borrowed: valid until
 * the calling reader leaves its read section (until the cache is destroyed for a face that is
 * never refined). Node indices of a version remain valid in every later version. */
const sw_lod_hierarchy *sw_lod_cache_get(const sw_lod_cache *cache, uint32_t face);

/* Lock-free. The face's state; a QUEUED slot whose request went stale reads EMPTY. */
sw_lod_cache_state sw_lod_cache_state_get(const sw_lod_cache *cache, uint32_t face);

/* The sw_result (and message, when status is not NULL) of a FAILED face; SW_OK otherwise. */
sw_result sw_lod_cache_failure(const sw_lod_cache *cache, uint32_t face, sw_status *status);

/* ---- refinement below the leaves ------------------------------------------------------------- */
/* Builds in the pool a hierarchy of leaf `node`'s rectangle whose leaves meet `tolerance`
 * (object space, > 0) and publishes a new version of the face's hierarchy with it hung under the
 * leaf (the leaf keeps its own bicubic and becomes an inner node). group may be NULL; when given
 * the refinement task is counted in it. *outcome says what happened (may be NULL).
 * Returns SW_OK, SW_ERR_INVALID_ARGUMENT (face not READY, node out of range, tolerance <= 0) or
 * SW_ERR_OUT_OF_MEMORY. A failed sub-build publishes nothing and is counted in no stat but
 * leaves the face refinable again. */
sw_result sw_lod_cache_refine(sw_lod_cache *cache, uint32_t face, int32_t node, double tolerance,
                              const sw_lod_cache_req *req, sw_th_group *group,
                              sw_lod_refine_outcome *outcome);

/* As sw_lod_cache_refine for n leaves of one face at once (one task, one new version holding every
 * refined subtree): SUBMITTED when at least one of them is a leaf above its tolerance. Errors as
 * sw_lod_cache_refine (any node out of range or tolerance <= 0: SW_ERR_INVALID_ARGUMENT). */
sw_result sw_lod_cache_refine_leaves(sw_lod_cache *cache, uint32_t face, const int32_t *nodes,
                                     const double *tolerances, uint32_t n,
                                     const sw_lod_cache_req *req, sw_th_group *group,
                                     sw_lod_refine_outcome *outcome);

/* ---- readers (epoch-based reclamation; the rule is at the top of this file) ------------------ */
/* Claims a reader slot for the calling thread; returns its index, or -1 when all are taken. */
int32_t sw_lod_cache_reader_add(sw_lod_cache *cache);
/* Releases a slot (not inside a read section). */
void sw_lod_cache_reader_remove(sw_lod_cache *cache, int32_t reader);
/* Lock-free, wait-free. Sections do not nest; one thread per slot. */
void sw_lod_cache_reader_enter(sw_lod_cache *cache, int32_t reader);
void sw_lod_cache_reader_leave(sw_lod_cache *cache, int32_t reader);
/* Frees the retired versions no reader can still hold; returns how many remain retired. */
size_t sw_lod_cache_collect(sw_lod_cache *cache);

/* ---- accounting ------------------------------------------------------------------------------ */
/* Bytes held: the cache's own arrays plus every hierarchy version, current or retired. */
size_t sw_lod_cache_memory(const sw_lod_cache *cache);
/* Counters (approximate while tasks run, exact once they are done). */
void sw_lod_cache_stats_get(const sw_lod_cache *cache, sw_lod_cache_stats *out);

#ifdef __cplusplus
}
#endif
#endif

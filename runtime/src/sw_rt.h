/* SPDX-License-Identifier: MIT */
/* runtime/ internals shared by the API implementation and the CLI (never installed). */
#ifndef SW_RT_H
#define SW_RT_H

#include <splinewalk/splinewalk.h>

#include "sw_gpu.h"
#include "sw_rt_misuse.h"
#include "sw_sg_scene.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

/* ---- handle pools (handle_pool.c) -------------------------------------------------------------
 * A handle id is (generation << 16) | (slot + 1); 0 is never valid. The pool's mutex protects its
 * slots only; it is taken on create, destroy and lookup, never on a per-frame path. */
typedef struct sw_rt_pool {
    pthread_mutex_t lock;
    void **items;
    uint16_t *generations;
    uint32_t capacity;
} sw_rt_pool;

#define SW_RT_POOL_INIT                                                                            \
    {                                                                                              \
        PTHREAD_MUTEX_INITIALIZER, NULL, NULL, 0                                                   \
    }
#define SW_RT_POOL_MAX_SLOTS 65535u

uint32_t sw_rt_pool_add(sw_rt_pool *pool, void *item);  /* 0 when full or out of memory */
void *sw_rt_pool_remove(sw_rt_pool *pool, uint32_t id); /* NULL for stale or invalid ids */

/* A check (or a reference count increment) made while the pool's lock is held, so that the item
 * cannot be removed and freed by another thread between its lookup and the check. It must be
 * short and must not call into the pool. SW_OK accepts the item. */
typedef sw_result (*sw_rt_pool_check_fn)(void *item, void *ctx);
/* Looks `id` up and runs `check` on its item under the lock. Returns SW_ERR_STALE_HANDLE for a
 * stale or invalid id, else check's result; *out = the item when that is SW_OK, else NULL. */
sw_result sw_rt_pool_get_checked(sw_rt_pool *pool, uint32_t id, sw_rt_pool_check_fn check,
                                 void *ctx, void **out);
/* The same, and removes the item (the handle goes stale) when check accepts it. */
sw_result sw_rt_pool_remove_checked(sw_rt_pool *pool, uint32_t id, sw_rt_pool_check_fn check,
                                    void *ctx, void **out);

/* ---- scenes (api_scene.c) -------------------------------------------------------------------- */
typedef struct sw_rt_scene {
    sw_sg_scene *sg;
    /* The pool's reference plus one per call using the scene: a scene destroyed while another
     * thread saves or draws it is freed by the last of them, never under their feet. */
    atomic_uint refs;
    pthread_mutex_t once_lock; /* guards `ready`, `ready_result` and `stats` (first use only),
                                  and `pick_bvh` (built by the first pick) */
    int ready;
    sw_result ready_result;
    sw_sg_scene_stats stats;
    uint32_t faces_skipped, faces_repaired; /* of the CAD import that made it; set before the
                                               handle is published, then immutable */
    int32_t partial;
    struct sw_sg_bvh *pick_bvh; /* immutable once built; freed with the scene */
    /* Node scenes (api_nodes*.c). The handle's scene is a container: sg NULL, `model` the node
     * tree, and acquiring it yields the model's published version instead. A version is an
     * ordinary scene made by the model's compile task with everything below set before it is
     * published (then immutable): ready, stats, pick_bvh (also what renderers cull with),
     * cones, and the node handle id of each face. */
    struct sw_rt_model *model;
    uint64_t lineage; /* a version: its model's serial number (never reused); 0 otherwise */
    uint64_t revision;
    const struct sw_sg_bvh *prebuilt_bvh;     /* = pick_bvh of a version; NULL otherwise */
    struct sw_lod_face_cones *prebuilt_cones; /* owned */
    uint32_t *face_nodes;                     /* owned; n_faces entries */
    uint32_t *mesh_nodes;                     /* owned; n_meshes entries (NULL: none) */
} sw_rt_scene;

/* A new scene holding sg (one reference, the caller's; NULL on failure, sg then freed). */
sw_rt_scene *sw_rt_scene_alloc(sw_sg_scene *sg);
/* Gives the scene a handle (the pool takes the caller's reference). On failure frees the scene
 * and returns SW_ERR_LIMIT. */
sw_result sw_rt_scene_add_handle(sw_rt_scene *scene, sw_scene *out, sw_status *status);
struct sw_sg_import_report;
/* Reads a scene file as sw_scene_load does (.sws mapped, .tsm, or CAD through OCCT); `report`
 * (may be NULL) gets a CAD import's counts, zero otherwise. */
sw_result sw_rt_scene_read(const sw_scene_load_desc *desc, sw_sg_scene **out,
                           struct sw_sg_import_report *report, sw_status *status);
/* Node scenes: frees the model of a container and what a version owns (api_nodes.c); called by
 * the last release. */
void sw_rt_nodes_scene_free(sw_rt_scene *scene);
/* Node scenes: the version to use for a container — the published one (latest = 0: never waits)
 * or the one holding every edit made before the call (latest = 1: waits for the compile task);
 * a reference the caller releases. Errors: those of compiling (sw_scene_flush). */
sw_result sw_rt_model_acquire_version(struct sw_rt_model *model, int latest, sw_rt_scene **out,
                                      sw_status *status);

/* The scene behind a handle, with every section verified and its stats computed (first call does
 * the work), holding a reference that the caller gives back with sw_rt_scene_release. Errors:
 * SW_ERR_STALE_HANDLE, or whatever the first verification found (then *out = NULL and no
 * reference is held). */
sw_result sw_rt_scene_acquire(sw_scene handle, sw_rt_scene **out, sw_status *status);
/* The same for a frame: a walkthrough frame (walkthrough = 1) takes a node scene's published
 * version without waiting; sw_rt_scene_acquire waits for every edit made before the call. */
sw_result sw_rt_scene_acquire_frame(sw_scene handle, int walkthrough, sw_rt_scene **out,
                                    sw_status *status);
/* The scene behind a handle as the pool holds it (a node scene's container, not a version), with
 * a reference; no verification. SW_ERR_STALE_HANDLE. */
sw_result sw_rt_scene_lookup(sw_scene handle, sw_rt_scene **out, sw_status *status);
void sw_rt_scene_release(sw_rt_scene *scene); /* frees it when it was the last reference */
/* One more reference, for a caller that already holds one (acquire) and keeps the scene beyond
 * its call (a renderer's hierarchy cache). */
void sw_rt_scene_retain(sw_rt_scene *scene);

/* ---- cameras (camera.c) ---------------------------------------------------------------------- */
/* Fits a preset to a world box (min xyz, max xyz) as sw_camera_fit documents. */
void sw_rt_camera_fit_box(const double bbox[6], sw_view_preset view, sw_camera *out);
/* What is wrong with a camera whose every field is given (fovy too: 0 is not a default here), as
 * a phrase for a message ("the eye coincides with the target"), or NULL when it spans a view:
 * the one check behind sw_camera_check, every frame's camera and camera paths. */
const char *sw_rt_camera_problem(const sw_camera *c);
/* Parses "iso|front|top|right"; returns 0 on success. */
int sw_rt_view_parse(const char *text, sw_view_preset *out);

/* ---- immediate draws (api_immediate.c, sw_immediate.h) --------------------------------------- */
struct sw_rt_immediate;          /* a renderer's immediate state: its object scene and shading */
struct sw__gpu_surface_programs; /* gpu/sw_gpu_internal.h */
/* Frees a renderer's immediate state (NULL allowed): its owner thread, its context current. */
void sw__rt_immediate_free(struct sw_rt_immediate *im, sw_gpu_context *gpu);
/* What an immediate frame changes in a scene's frame: the occurrences drawn (instead of the
 * scene's traversal) and the surface programs (NULL: the library's). */
typedef struct sw_rt_frame_extra {
    const sw_gpu_occurrence *occurrences;
    size_t n_occurrences;
    const struct sw__gpu_surface_programs *shading;
} sw_rt_frame_extra;
/* The renderer's immediate-state slot and GL context, for its owner thread (`drawing`: also
 * refused while prepared frames wait, before the draw changes any state). Errors:
 * SW_ERR_STALE_HANDLE, SW_ERR_INVALID_ARGUMENT (another thread; frames waiting), naming fn. */
sw_result sw__rt_renderer_immediate(sw_renderer handle, const char *fn, int drawing,
                                    struct sw_rt_immediate ***slot, sw_gpu_context **gpu,
                                    sw_status *status);
/* A frame in one call, prepared on the visibility thread and submitted (sw_renderer_draw's, named
 * fn in errors): of `scene` (a reference the caller holds; not behind a handle) with `extra`, or
 * with scene NULL of desc->scene's handle (extra NULL). Errors: those of sw_renderer_draw. */
sw_result sw__rt_renderer_draw_scene(sw_renderer handle, const char *fn, sw_rt_scene *scene,
                                     const sw_frame_desc *desc, const sw_rt_frame_extra *extra,
                                     sw_frame_stats *stats, sw_status *status);

/* The renderer's trim atlas (sw_gpu_trim_atlas_info), for the viewer's overlay. Owner thread;
 * 0 with the outputs set, -1 for a stale handle or another thread. */
int sw_rt_renderer_trim_atlas(sw_renderer renderer, uint32_t *texture, int32_t *pages,
                              int32_t *side);
/* The renderer's worker pool, borrowed until the renderer is destroyed, for the profile's
 * per-frame pool statistics (sw_th_pool_stats_get, sw_th_pool_queued: any thread). NULL before
 * the first frame made it, for a stale handle or another thread than the owner. */
struct sw_th_pool *sw_rt_renderer_pool_ptr(sw_renderer renderer);
/* Times the pool's tasks by kind (sw_th_pool_desc.time_tasks) from now on: the pool's, or the
 * one the first frame makes. Owner thread; 0, or -1 for a stale handle or another thread. */
int sw_rt_renderer_time_pool_tasks(sw_renderer renderer, int on);

#endif

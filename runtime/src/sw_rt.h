/* runtime/ internals shared by the API implementation and the CLI (never installed). */
#ifndef SW_RT_H
#define SW_RT_H

#include <splinewalk/splinewalk.h>

#include "sw_gpu.h"
#include "sw_sg_scene.h"

#include <pthread.h>
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

#define SW_RT_POOL_INIT {PTHREAD_MUTEX_INITIALIZER, NULL, NULL, 0}
#define SW_RT_POOL_MAX_SLOTS 65535u

uint32_t sw_rt_pool_add(sw_rt_pool *pool, void *item);    /* 0 when full or out of memory */
void *sw_rt_pool_get(sw_rt_pool *pool, uint32_t id);      /* NULL for stale or invalid ids */
void *sw_rt_pool_remove(sw_rt_pool *pool, uint32_t id);   /* NULL for stale or invalid ids */

/* ---- scenes (api_scene.c) -------------------------------------------------------------------- */
typedef struct sw_rt_scene {
    sw_sg_scene *sg;
    pthread_mutex_t once_lock; /* guards `ready`, `ready_result` and `stats` (first use only) */
    int ready;
    sw_result ready_result;
    sw_sg_scene_stats stats;
} sw_rt_scene;

/* The scene behind a handle, with every section verified and its stats computed (first call does
 * the work). Errors: SW_ERR_STALE_HANDLE, or whatever the first verification found. */
sw_result sw_rt_scene_acquire(sw_scene handle, sw_rt_scene **out, sw_status *status);

/* ---- cameras (camera.c) ---------------------------------------------------------------------- */
/* Fits a preset to a world box (min xyz, max xyz) as sw_camera_fit documents. */
void sw_rt_camera_fit_box(const double bbox[6], sw_view_preset view, sw_camera *out);
/* Parses "iso|front|top|right"; returns 0 on success. */
int sw_rt_view_parse(const char *text, sw_view_preset *out);

#endif

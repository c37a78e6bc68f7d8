/* SPDX-License-Identifier: MIT */
/* Public rendering API: a headless renderer owns a GL context on its creating thread and draws
 * converged frames (ARCHITECTURE.md: only the GL owner touches GL). */
#include "sw_clock.h"
#include "sw_rt.h"
#include "sw_hooks.h"
#include "sw_rt_pipeline.h"

#include "sw_gpu_internal.h"

#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"
#include "sw_status_util.h"
#include "sw_th_pool.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

/* The pool's task kinds of the renderer's static LODs. */
static sw_th_task_kind_slot k_cluster = SW_TH_TASK_KIND_SLOT("static_cluster");
static sw_th_task_kind_slot k_retire = SW_TH_TASK_KIND_SLOT("static_retire");

/* The hierarchies live with the renderer, for the scene it last drew: a walkthrough keeps drawing
 * one scene, and the pool's workers then stay busy with that scene only. The renderer holds a
 * reference to that scene: its workers may still build hierarchies from it after a walkthrough
 * frame returned, and after the caller destroyed its handle. */
typedef struct sw_rt_renderer {
    sw_gpu_context *gpu;
    pthread_t owner;
    sw_th_pool *pool;            /* created on the first frame that needs it */
    sw_lod_cache *cache;         /* of cache_scene */
    sw_sg_bvh *bvh;              /* of cache_scene */
    sw_lod_face_cones *cones;    /* of cache_scene: back-patch culling of closed shells */
    sw_gpu_occluders *occluders; /* of cache_scene: built on the first occlusion-culled frame */
    /* Occlusion culling's rest where it hides nothing (a car park of curved panels, a view from
     * outside): after a culled frame that hid nothing the next occlusion_rest frames go without
     * it, the rest growing 1, 3, 7, 15 while it keeps hiding nothing and ending at the first
     * frame that hides something. A frame without it draws a superset of the same image's faces,
     * so resting never changes an image, only what the map costs (4-10 % of the visibility
     * stage where nothing is hidden). */
    uint32_t occlusion_rest, occlusion_rest_left;
    /* of cache_scene: static LODs (Kumar §3-§4), the set made by a pool task on the first frame
     * that asks for them and published by one pointer store; statics_state: 0 none, 1 being
     * made, 2 ready, 3 failed (statics_failure says why) */
    _Atomic(sw_lod_static_set *) statics;
    _Atomic int statics_state;
    sw_th_group statics_group;
    sw_status statics_failure;
    _Atomic int statics_from_cache; /* the set's chains came from the scene's LOD cache */
    int statics_skip_proxies; /* the frame that asked for the set wanted no proxies: the cache's
                                 are not read (built in the pool if a later frame wants them) */
    sw_rt_scene *cache_scene; /* retained while the cache lives; NULL = none */
    uint32_t worker_threads;  /* the pool's size; 0 = one per online processor */
    int time_pool_tasks;      /* sw_rt_renderer_time_pool_tasks: the pool times its tasks */
    sw_rt_pipeline *pipeline; /* the visibility thread, started by the first prepare */
    uint32_t in_flight;       /* prepared frames not submitted yet */
    /* the last submitted frame's spent plan, handed to V with the next prepare (V frees it) */
    sw_gpu_frame_plan *spent;
    uint64_t frames_prepared;
    struct sw_rt_immediate *immediate; /* api_immediate.c; NULL until the first immediate call */
} sw_rt_renderer;

/* A prepared frame: the job V works on, and what its submission needs. */
typedef struct rt_job {
    sw_rt_frame_job job; /* first: pipeline pointers are rt_job pointers */
    sw_rt_scene *scene;  /* a reference held until the frame is submitted */
    char *output_path;   /* copy of the desc's, or NULL */
    /* an immediate frame's surface programs, for its submission only (Guthe §8's special
     * program); NULL: the library's */
    const struct sw__gpu_surface_programs *shading;
    double t_pushed; /* when it was handed to the visibility thread (ms) */
} rt_job;

static void job_free(rt_job *j);

static sw_rt_pool g_renderers = SW_RT_POOL_INIT;

sw_result sw_renderer_create(const sw_renderer_desc *desc, sw_renderer *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_create: NULL out");
    out->id = 0;
    const uint32_t workers = desc ? desc->worker_threads : 0;
    if (workers > 1024)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "worker_threads %u above 1024", workers);
    sw_rt_renderer *r = sw__calloc(1, sizeof *r);
    if (!r)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    r->worker_threads = workers;
    sw_result res = desc && desc->use_current_context
                        ? sw_gpu_context_adopt_current(&r->gpu, status)
                        : sw_gpu_context_create_headless(&r->gpu, status);
    if (res != SW_OK) {
        sw__free(r);
        return res;
    }
    sw_gpu_set_memory_budget(r->gpu, desc ? desc->memory_budget_host : 0,
                             desc ? desc->memory_budget_gpu : 0);
    r->owner = pthread_self();
    out->id = sw_rt_pool_add(&g_renderers, r);
    if (!out->id) {
        sw_gpu_context_free(r->gpu);
        sw__free(r);
        return sw__fail(status, SW_ERR_LIMIT, "too many renderers");
    }
    sw__log(SW_LOG_INFO, "renderer %#x: %s%s", out->id, sw_gpu_context_description_ptr(r->gpu),
            desc && desc->use_current_context ? " (the host's context)" : "");
    uint64_t host, gpu, reported;
    sw_gpu_memory_budget(r->gpu, &host, &gpu, &reported);
    sw__log(SW_LOG_INFO,
            "renderer %#x: memory budget host %.0f MiB, GPU %.0f MiB (driver reports %.0f MiB)",
            out->id, host / 1048576.0, gpu / 1048576.0, reported / 1048576.0);
    return SW_OK;
}

/* Runs under the renderer pool's lock: a renderer is only ever used and destroyed by its owner
 * thread, so a caller that passes this check cannot see it freed under its feet, and a caller on
 * another thread never reads past the lock. */
static sw_result check_owner(void *item, void *ctx)
{
    (void)ctx;
    return pthread_equal(((sw_rt_renderer *)item)->owner, pthread_self()) ? SW_OK
                                                                          : SW_ERR_INVALID_ARGUMENT;
}

/* The renderer behind a handle, if the calling thread owns it. */
static sw_result owned_renderer(sw_renderer handle, const char *fn, sw_rt_renderer **out,
                                sw_status *status)
{
    void *item;
    sw_result r = sw_rt_pool_get_checked(&g_renderers, handle.id, check_owner, NULL, &item);
    *out = item;
    if (r == SW_ERR_STALE_HANDLE)
        return SW__MISUSE(status, r, "%s: renderer handle %#x is stale or invalid", fn, handle.id);
    if (r != SW_OK)
        return SW__MISUSE(status, r, "%s: called from a thread that does not own the renderer", fn);
    return SW_OK;
}

typedef struct retired_statics {
    sw_lod_static_set *set;
    sw_rt_scene *scene; /* a reference the set's builds need until they are done */
} retired_statics;

static void retire_statics_task(void *ctx)
{
    retired_statics *rs = ctx;
    sw_lod_static_set_destroy(rs->set); /* waits for its running builds, runs pool tasks */
    sw_rt_scene_release(rs->scene);
    sw__free(rs);
}

/* The scene's static LODs, given up (another scene, a new version of a node scene, the renderer
 * going away): queued builds are cancelled, and the set is freed by a pool task once its running
 * builds end, so the frame thread never waits for them (a level build takes seconds). Only the
 * clustering task, if it is still running, is waited for here: it writes r->statics. */
static void retire_statics(sw_rt_renderer *r)
{
    if (r->pool)
        sw_th_group_wait(r->pool, &r->statics_group);
    sw_lod_static_set *set = atomic_exchange(&r->statics, NULL);
    atomic_store(&r->statics_state, 0);
    if (!set)
        return;
    sw_lod_static_set_cancel(set);
    retired_statics *rs = sw__malloc(sizeof *rs);
    if (rs) {
        *rs = (retired_statics){set, r->cache_scene};
        sw_rt_scene_retain(r->cache_scene);
        const sw_th_task task = {
            retire_statics_task,          rs, SW_TH_PRIORITY_BACKGROUND, NULL, 0, NULL,
            sw_th_task_kind_of(&k_retire)};
        if (sw_th_pool_submit(r->pool, &task) == SW_OK)
            return;
        sw_rt_scene_release(r->cache_scene);
        sw__free(rs);
    }
    sw_lod_static_set_destroy(set); /* out of memory: here, waiting */
}

typedef struct retired_cache {
    sw_lod_cache *cache;
    sw_rt_scene *scene; /* a reference the cache's tasks need until they are done */
} retired_cache;

static void retire_cache_task(void *ctx)
{
    retired_cache *rc = ctx;
    sw_lod_cache_destroy(rc->cache); /* waits for its builds, runs pool tasks */
    sw_rt_scene_release(rc->scene);
    sw__free(rc);
}

/* The hierarchy cache, given up: destroyed by a pool task once its builds and refinements end,
 * so the frame thread never waits for them (a walkthrough frame drawing a node scene's new
 * version would otherwise wait here for the old version's builds). */
static void retire_cache(sw_rt_renderer *r)
{
    if (!r->cache)
        return;
    /* no scene yet: a cache that failed to set up, no build asked for */
    retired_cache *rc = r->cache_scene && r->pool ? sw__malloc(sizeof *rc) : NULL;
    if (rc) {
        *rc = (retired_cache){r->cache, r->cache_scene};
        sw_rt_scene_retain(r->cache_scene);
        const sw_th_task task = {retire_cache_task, rc, SW_TH_PRIORITY_BACKGROUND, NULL, 0, NULL,
                                 SW_TH_TASK_OTHER};
        if (sw_th_pool_submit(r->pool, &task) == SW_OK) {
            r->cache = NULL;
            return;
        }
        sw_rt_scene_release(r->cache_scene);
        sw__free(rc);
    }
    sw_lod_cache_destroy(r->cache); /* out of memory: here, waiting */
    r->cache = NULL;
}

/* Drops the hierarchy cache and the static LODs (both freed in the pool) and the BVH, then the
 * scene reference they needed. */
static void drop_cache(sw_rt_renderer *r)
{
    retire_statics(r);
    retire_cache(r);
    r->cache = NULL;
    sw_sg_bvh_free(r->bvh);
    r->bvh = NULL;
    sw_lod_face_cones_free(r->cones);
    r->cones = NULL;
    sw_gpu_occluders_free(r->occluders);
    r->occluders = NULL;
    r->occlusion_rest = r->occlusion_rest_left = 0;
    if (r->cache_scene)
        sw_rt_scene_release(r->cache_scene);
    r->cache_scene = NULL;
}

/* The renderer's hierarchy cache and BVH for `scene` (those of another scene are dropped first).
 * The scene pointer identifies them: a retained scene cannot be freed, so its address is not
 * reused. */
static sw_result renderer_cache(sw_rt_renderer *r, sw_rt_scene *scene, sw_status *status)
{
    if (r->cache && r->cache_scene == scene)
        return SW_OK;
    drop_cache(r);
    if (!r->pool) {
        sw_th_pool_desc pd = {0};
        pd.worker_count = r->worker_threads;
        pd.time_tasks = r->time_pool_tasks != 0;
        if (sw_th_pool_create(&pd, &r->pool) != SW_OK)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "worker pool: could not start");
    }
    sw_result res = sw_lod_cache_create(scene->sg, r->pool, NULL, &r->cache, status);
    /* A node scene's version comes with them, built by its compile task (gpu_frame). */
    if (res == SW_OK && !scene->prebuilt_bvh)
        res = sw_sg_bvh_build(scene->sg, &r->bvh, status);
    if (res == SW_OK && !scene->prebuilt_cones)
        res = sw_lod_face_cones_build(scene->sg, &r->cones, status);
    if (res != SW_OK) {
        drop_cache(r);
        return res;
    }
    sw_rt_scene_retain(scene);
    r->cache_scene = scene;
    return SW_OK;
}

sw_result sw_renderer_destroy(sw_renderer renderer)
{
    void *item;
    sw_result r = sw_rt_pool_remove_checked(&g_renderers, renderer.id, check_owner, NULL, &item);
    if (r == SW_ERR_STALE_HANDLE) /* left untouched */
        return SW__MISUSE(NULL, r, "sw_renderer_destroy: renderer handle %#x is stale or invalid",
                          renderer.id);
    if (r != SW_OK) /* another thread's context: left untouched */
        return SW__MISUSE(NULL, r,
                          "sw_renderer_destroy: called from a thread that does not own "
                          "the renderer");
    sw_rt_renderer *rr = item;
    while (rr->in_flight) { /* prepared, never submitted: V finishes them, nobody draws them */
        job_free((rt_job *)sw_rt_pipeline_pop(rr->pipeline));
        rr->in_flight--;
    }
    sw_rt_pipeline_stop(rr->pipeline);
    sw_gpu_frame_plan_free(rr->spent);
    sw__rt_immediate_free(rr->immediate, rr->gpu);
    drop_cache(rr);
    sw_th_pool_destroy(rr->pool);
    sw_gpu_context_free(rr->gpu);
    sw__free(rr);
    return SW_OK;
}

int sw_rt_renderer_trim_atlas(sw_renderer renderer, uint32_t *texture, int32_t *pages,
                              int32_t *side)
{
    sw_rt_renderer *r;
    *texture = 0;
    *pages = *side = 0;
    if (owned_renderer(renderer, "sw_rt_renderer_trim_atlas", &r, NULL) != SW_OK)
        return -1;
    sw_gpu_trim_atlas_info(r->gpu, texture, pages, side);
    return 0;
}

sw_th_pool *sw_rt_renderer_pool_ptr(sw_renderer renderer)
{
    sw_rt_renderer *r;
    if (owned_renderer(renderer, "sw_rt_renderer_pool_ptr", &r, NULL) != SW_OK)
        return NULL;
    return r->pool;
}

int sw_rt_renderer_time_pool_tasks(sw_renderer renderer, int on)
{
    sw_rt_renderer *r;
    if (owned_renderer(renderer, "sw_rt_renderer_time_pool_tasks", &r, NULL) != SW_OK)
        return -1;
    r->time_pool_tasks = on != 0;
    if (r->pool)
        sw_th_pool_set_task_timing(r->pool, on);
    return 0;
}

const char *sw_renderer_description_ptr(sw_renderer renderer)
{
    sw_rt_renderer *r;
    if (owned_renderer(renderer, "sw_renderer_description_ptr", &r, NULL) != SW_OK)
        return "";
    return sw_gpu_context_description_ptr(r->gpu);
}

sw_result sw_renderer_memory_budget(sw_renderer renderer, sw_memory_budget *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_memory_budget: NULL out");
    memset(out, 0, sizeof *out);
    sw_rt_renderer *r;
    sw_result res = owned_renderer(renderer, "sw_renderer_memory_budget", &r, status);
    if (res != SW_OK)
        return res;
    sw_gpu_memory_budget(r->gpu, &out->host_bytes, &out->gpu_bytes, &out->gpu_reported_bytes);
    sw__status_ok(status);
    return SW_OK;
}

static sw_result check_frame_desc(const sw_frame_desc *desc, sw_status *status)
{
    if (desc->width < 0 || desc->height < 0 || desc->width > 16384 || desc->height > 16384)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "frame size %dx%d out of 1..16384",
                        desc->width, desc->height);
    if (desc->error_px != 0.0 && !(desc->error_px >= SW_ERROR_MIN_PX && isfinite(desc->error_px)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "screen-space error %g px must be finite and at least %g px (the floor "
                        "below which refinement outgrows the arithmetic)",
                        desc->error_px, SW_ERROR_MIN_PX);
    sw_result res = sw_camera_check(&desc->camera, status);
    if (res != SW_OK)
        return res;
    if (desc->near_plane != 0.0 && !(desc->near_plane > 0.0 && isfinite(desc->near_plane)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "near plane %g must be positive and finite (0: from the scene's box)",
                        desc->near_plane);
    return SW_OK;
}

static void copy_stats(const sw_gpu_frame_stats *g, sw_frame_stats *out)
{
    out->faces_drawn = g->faces_drawn;
    out->faces_culled = g->faces_culled;
    out->patches_trimmed = g->patches_trimmed;
    out->patches_untrimmed = g->patches_untrimmed;
    out->patches_culled = g->patches_culled;
    out->triangles = g->triangles;
    out->trim_textures = g->trim_textures;
    out->trim_texels = g->trim_texels;
    out->trim_exact = g->trim_exact;
    out->trim_exact_fallbacks = g->trim_exact_fallbacks;
    out->shapes_drawn = g->shapes_drawn;
    out->shapes_culled = g->shapes_culled;
    out->shapes_skipped = g->shapes_skipped;
    out->shape_fallbacks = g->shape_fallbacks;
    out->patches_gpu_evaluated = g->patches_gpu_evaluated;
    out->patches_exact = g->patches_exact;
    out->atlas_pages = g->atlas_pages;
    out->trim_reused = g->trim_reused;
    out->hierarchy_nodes = g->hlod_nodes;
    out->refine_rounds = g->hlod_refine_rounds;
    out->fallback_draws = g->hlod_fallback_faces + g->hlod_refine_requests;
    out->ms_hierarchy = g->ms_hierarchy;
    out->ms_tessellate = g->ms_tessellate;
    out->ms_trim = g->ms_trim;
    out->ms_draw = g->ms_draw;
    out->ms_readback = g->ms_readback;
    out->faces_backculled = g->faces_backculled;
    out->ms_gpu = g->ms_gpu;
    out->static_drawn = g->static_units_drawn;
    out->static_faces = g->static_faces;
    out->static_triangles = g->static_triangles;
    out->meshes_drawn = g->meshes_drawn;
    out->meshes_culled = g->meshes_culled;
    out->mesh_triangles = g->mesh_triangles;
    out->static_requests = g->static_requests;
    out->proxies_drawn = g->proxies_drawn;
    out->proxy_instances = g->proxy_instances;
    out->proxy_triangles = g->proxy_triangles;
    out->bound_exceeded = g->bound_exceeded;
    out->budget_coarsened = g->budget_coarsened;
    out->bound_excess_px = g->bound_excess_px;
    out->tess_chunks = g->tess_chunks;
    out->tess_chunks_by_pool = g->tess_chunks_by_pool;
    out->ms_join = g->ms_join;
    out->border_triangles = g->border_triangles;
    out->border_loops_kept = g->border_loops_kept;
    out->border_loops_made = g->border_loops_made;
    out->border_quads_away = g->border_quads_away;
    out->occlusion_tests = g->occlusion_tests;
    out->nodes_occluded = g->nodes_occluded;
    out->faces_occluded = g->faces_occluded;
    out->occluders_drawn = g->occluders_drawn;
    out->resident_triangles = g->resident_triangles;
    out->upload_bytes = g->upload_bytes;
    out->grid_hits = g->grid_hits;
    out->grid_misses = g->grid_misses;
}

static int camera_is_zero(const sw_camera *c)
{
    for (int k = 0; k < 3; k++) {
        if (c->eye[k] != 0.0 || c->target[k] != 0.0 || c->up[k] != 0.0)
            return 0;
    }
    return c->fovy_deg == 0.0;
}

sw_result sw_camera_check(const sw_camera *camera, sw_status *status)
{
    if (!camera)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_camera_check: NULL camera");
    if (camera_is_zero(camera))
        return SW_OK;
    sw_camera c = *camera;
    if (c.fovy_deg == 0.0)
        c.fovy_deg = SW_DEFAULT_FOVY_DEG;
    const char *problem = sw_rt_camera_problem(&c);
    if (problem)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "camera: %s", problem);
    return SW_OK;
}

/* The frame's camera: a zero camera means the iso preset fitted to the scene (zero = default);
 * otherwise eye, target and up must span a view (a degenerate one would yield NaN matrices and an
 * empty image instead of an error), checked again after the fit (a degenerate scene box). */
static sw_result resolve_camera(const sw_camera *in, const sw_rt_scene *scene, sw_gpu_camera *out,
                                sw_status *status)
{
    sw_camera c = *in;
    if (camera_is_zero(&c))
        sw_rt_camera_fit_box(scene->stats.bbox, SW_VIEW_ISO, &c);
    sw_result res = sw_camera_check(&c, status);
    if (res != SW_OK)
        return res;
    for (int k = 0; k < 3; k++) {
        out->eye[k] = c.eye[k];
        out->target[k] = c.target[k];
        out->up[k] = c.up[k];
    }
    out->fovy_deg = c.fovy_deg > 0.0 ? c.fovy_deg : SW_DEFAULT_FOVY_DEG;
    return SW_OK;
}

static void frame_from_desc(const sw_frame_desc *desc, sw_gpu_frame_desc *frame)
{
    frame->width = desc->width ? desc->width : SW_DEFAULT_WIDTH;
    frame->height = desc->height ? desc->height : SW_DEFAULT_HEIGHT;
    frame->error_px = desc->error_px > 0.0 ? desc->error_px : SW_DEFAULT_ERROR_PX;
    frame->background[0] = frame->background[1] = frame->background[2] = 1.0f;
    frame->background[3] = 1.0f;
    frame->eval_exact = desc->eval_exact != 0;
    frame->walkthrough = desc->walkthrough != 0;
    frame->present = desc->present != 0;
    frame->present_depth = desc->present && desc->present_depth;
    frame->near_plane = desc->near_plane;
    frame->wireframe = desc->wireframe != 0;
    frame->trim_edges = desc->trim_edges != 0;
    frame->no_kept_grids = desc->no_kept_grids != 0;
    /* pixels leave the renderer only through output_path (the library returns no image): a
     * frame without one reads nothing back (at 1280x720 on llvmpipe the readback was a third of
     * a profile's frame, 14 of 42 ms); its raster work ends before the next submit returns */
    frame->no_readback = !desc->output_path;
    frame->want_depth = 0;
    if (desc->output_path) {
        size_t n = strlen(desc->output_path);
        frame->want_depth = n > 4 && strcasecmp(desc->output_path + n - 4, ".exr") == 0;
    }
}

static void statics_task(void *ctx)
{
    sw_rt_renderer *r = ctx;
    sw_status st = {0}, cst = {0}; /* the set's, the cache's (both reported) */
    /* the scene file's LOD cache (build-lod), when it has one made for these super-surfaces; a
     * stale or damaged cache is refused as a whole (nothing adopted) and the units are built as
     * they are needed instead, when a LOD builder is installed (the LOD-building module) */
    const void *cache = NULL;
    size_t cache_bytes = 0;
    const char *path = sw_sg_scene_path_ptr(r->cache_scene->sg);
    const char *name = path && *path ? path : "the scene";
    const int can_build = sw_lod_static_builder() != NULL;
    sw_result found = sw_sg_scene_lods(r->cache_scene->sg, &cache, &cache_bytes, &cst);
    if (found != SW_OK && !can_build) {
        /* nothing to draw from: no set, so no clustering either */
        sw__log(SW_LOG_WARN,
                "static LODs: %s%s and no LOD builder is installed (the LOD-building module: "
                "sw_lod_build_install): every face is drawn per frame",
                found == SW_ERR_NOT_FOUND ? name : cst.message,
                found == SW_ERR_NOT_FOUND ? " has no LOD cache" : "");
        atomic_store(&r->statics, NULL);
        atomic_store(&r->statics_state, 2);
        return;
    }
    sw_lod_static_set *set = NULL;
    const sw_lod_static_set_desc desc = {.ignore_cached_proxies = r->statics_skip_proxies};
    sw_result res = sw_lod_static_set_create(r->cache_scene->sg, r->pool, &desc, &set, &st);
    if (res != SW_OK) {
        r->statics_failure = st;
        r->statics_failure.result = res;
        atomic_store(&r->statics_state, 3);
        return;
    }
    if (found == SW_OK) {
        found = sw_lod_static_set_load(set, cache, cache_bytes, path, NULL, &cst);
        sw_sg_scene_lods_release(r->cache_scene->sg); /* decoded (or refused): its pages go */
    }
    atomic_store(&r->statics_from_cache, found == SW_OK);
    if (found == SW_ERR_NOT_FOUND)
        sw__log(SW_LOG_WARN,
                "static LODs: %s has no LOD cache: the levels are built in the worker pool as "
                "frames need them (`splinewalk build-lod` stores them in a .sws)",
                name);
    else if (found != SW_OK)
        sw__log(SW_LOG_WARN, "static LODs: %s; %s", cst.message,
                can_build ? "the levels are built again as frames need them"
                          : "no LOD builder is installed: every face is drawn per frame");
    atomic_store(&r->statics, set);
    atomic_store(&r->statics_state, 2);
}

/* Cluster proxies: read with the LOD cache when it holds them (build-lod stores them), else made in
 * the pool from its chains (every chain is there) once a frame wants them — minutes of a pool
 * thread at 10^6 surfaces, so a renderer that never draws them never pays. A converged frame is the
 * same frame for the same view, so it draws the proxies once all are built and none before (it does
 * not wait for them: `render` would wait for every proxy of the scene for a frame a few of them
 * serve). */
static void frame_proxies(sw_rt_renderer *r, sw_gpu_frame_desc *frame)
{
    sw_lod_static_set *set = frame->static_lods;
    if (!set || frame->no_proxies)
        return;
    sw_status st = {0};
    if (atomic_load(&r->statics_from_cache) && !sw_lod_static_set_proxies_started(set)) {
        const char *path = sw_sg_scene_path_ptr(r->cache_scene->sg);
        sw__log(SW_LOG_INFO, "cluster proxies: %s: building them in the background (%s)",
                path && *path ? path : "the scene",
                r->statics_skip_proxies
                    ? "the first frame wanted none, so the LOD cache's were not read"
                    : "its LOD cache holds none made for this scene: `splinewalk build-lod` "
                      "stores them");
        if (sw_lod_static_set_build_proxies(set, &st) != SW_OK)
            sw__log(SW_LOG_WARN, "static LODs: %s: no cluster proxies", st.message);
    }
    if (!frame->walkthrough && !sw_lod_static_set_proxies_done(set))
        frame->no_proxies = 1;
}

/* The static LODs of the cache's scene for this frame: their clustering is started in the pool
 * on first need; a walkthrough frame goes on without it (drawn per frame), a converged one
 * waits. */
static sw_result frame_statics(sw_rt_renderer *r, sw_gpu_frame_desc *frame, sw_status *status)
{
    int expect = 0;
    if (atomic_compare_exchange_strong(&r->statics_state, &expect, 1)) {
        r->statics_skip_proxies = frame->no_proxies; /* read by the task it submits */
        const sw_th_task task = {statics_task,
                                 r,
                                 SW_TH_PRIORITY_BACKGROUND,
                                 NULL,
                                 0,
                                 &r->statics_group,
                                 sw_th_task_kind_of(&k_cluster)};
        if (sw_th_pool_submit(r->pool, &task) != SW_OK) {
            atomic_store(&r->statics_state, 0);
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: could not submit");
        }
    }
    if (!frame->walkthrough)
        sw_th_group_wait(r->pool, &r->statics_group);
    const int state = atomic_load(&r->statics_state);
    if (state == 3 && !frame->walkthrough)
        return sw__fail(status, r->statics_failure.result, "static LODs: %s",
                        r->statics_failure.message);
    frame->static_lods = state == 2 ? atomic_load(&r->statics) : NULL;
    frame_proxies(r, frame);
    return SW_OK;
}

/* 1 when this frame rests from occlusion culling (sw_rt_renderer.occlusion_rest). */
static int occlusion_resting(sw_rt_renderer *r)
{
    if (r->occlusion_rest_left == 0)
        return 0;
    r->occlusion_rest_left--;
    return 1;
}

/* What an occlusion-culled frame hid sets the rest of the frames prepared after it. */
static void occlusion_feedback(sw_rt_renderer *r, const sw_gpu_frame_desc *frame,
                               const sw_gpu_frame_stats *g)
{
    enum { MAX_REST = 15 };
    if (!frame->occluders || g->occlusion_tests == 0)
        return;
    if (g->nodes_occluded > 0 || g->faces_occluded > 0) {
        r->occlusion_rest = r->occlusion_rest_left = 0;
        return;
    }
    r->occlusion_rest = r->occlusion_rest < MAX_REST ? 2 * r->occlusion_rest + 1 : MAX_REST;
    r->occlusion_rest_left = r->occlusion_rest;
}

/* The GPU frame of a checked desc: its camera resolved, drawn through the renderer's hierarchy
 * cache and BVH for the scene (made for it if needed). */
static sw_result gpu_frame(sw_rt_renderer *r, sw_rt_scene *scene, const sw_frame_desc *desc,
                           sw_gpu_frame_desc *frame, sw_status *status)
{
    frame_from_desc(desc, frame);
    sw_result res = resolve_camera(&desc->camera, scene, &frame->camera, status);
    if (res == SW_OK)
        res = renderer_cache(r, scene, status);
    if (res != SW_OK)
        return res;
    frame->bvh = r->bvh ? r->bvh : scene->prebuilt_bvh;
    frame->face_cones = r->cones ? r->cones : scene->prebuilt_cones;
    if (!frame->eval_exact && !desc->no_hierarchy)
        frame->hierarchies = r->cache;
    frame->pool = r->pool;
    frame->lod_colors = desc->lod_colors != 0;
    frame->static_force = desc->static_force > 0 ? desc->static_force : 0;
    frame->no_proxies = desc->no_proxies != 0;
    if (desc->occlusion_culling && !r->occluders)
        res = sw_gpu_occluders_build(scene->sg, &r->occluders, status);
    frame->occluders = desc->occlusion_culling && !occlusion_resting(r) ? r->occluders : NULL;
    if (res == SW_OK && desc->static_lods && !frame->eval_exact)
        res = frame_statics(r, frame, status);
    return res;
}

/* The matrices of a resolved camera (gpu_frame's), the one place they are made: sw__gpu_view_init
 * builds the basis the frame draws with. */
static sw_result frame_matrices(const sw_gpu_camera *camera, int32_t width, int32_t height,
                                double near_plane, double view[16], double proj[16],
                                sw_status *status)
{
    sw__gpu_view v;
    sw_result res = sw__gpu_view_init(&v, camera, width, height, near_plane, status);
    if (res == SW_OK)
        sw__gpu_view_matrices(&v, view, proj);
    return res;
}

sw_result sw_camera_matrices(const sw_camera *camera, int32_t width, int32_t height,
                             double near_plane, double view[16], double proj[16], sw_status *status)
{
    if (!camera || !view || !proj)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_camera_matrices: NULL pointer");
    sw_frame_desc d = {0};
    d.camera = *camera;
    d.width = width;
    d.height = height;
    sw_result res = check_frame_desc(&d, status);
    if (res != SW_OK)
        return res;
    if (camera_is_zero(camera))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "sw_camera_matrices: zero camera (fit one to a scene with sw_camera_fit)");
    if (!(near_plane > 0.0 && isfinite(near_plane)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "sw_camera_matrices: near plane %g must be positive and finite",
                        near_plane);
    sw_gpu_camera c;
    res = resolve_camera(camera, NULL, &c, status); /* not zero: no scene to fit to */
    if (res == SW_OK)
        res = frame_matrices(&c, width ? width : SW_DEFAULT_WIDTH,
                             height ? height : SW_DEFAULT_HEIGHT, near_plane, view, proj, status);
    if (res == SW_OK)
        sw__status_ok(status);
    return res;
}

/* Writes a drawn frame's image when asked and fills the caller's stats (times from t0; the
 * matrices of the frame's desc). pool_waits: the calling thread's waits for the pool since w0
 * (the whole call: scene, caches, prepare, submit) plus other_waits (other threads' and earlier
 * calls' for this frame: the visibility thread's prepare, sw_renderer_prepare's), so every place
 * where the frame can block on the pool is counted, in both modes. */
static sw_result finish_frame(sw_gpu_image *image, const char *output_path,
                              const sw_gpu_frame_desc *frame, const sw_gpu_frame_stats *gstats,
                              double t0, const sw_th_wait_count *w0, uint64_t other_waits,
                              sw_frame_stats *stats, sw_status *status)
{
    double t1 = sw__clock_ms();
    sw_result res = output_path ? sw_gpu_image_write(image, output_path, status) : SW_OK;
    double t2 = sw__clock_ms();
    sw_gpu_image_free(image);
    if (res == SW_OK && stats) {
        memset(stats, 0, sizeof *stats);
        copy_stats(gstats, stats);
        stats->pool_waits = sw_th_thread_waits().waits - w0->waits + other_waits;
        stats->ms_write = t2 - t1;
        stats->ms_total = t2 - t0;
        stats->near_plane = gstats->near_plane;
        /* the camera drew this frame: it cannot fail here */
        (void)frame_matrices(&frame->camera, frame->width, frame->height, gstats->near_plane,
                             stats->view, stats->proj, NULL);
    }
    return res;
}

static void job_free(rt_job *j)
{
    sw_gpu_frame_plan_free(j->job.plan);
    if (j->scene)
        sw_rt_scene_release(j->scene);
    sw__free(j->output_path);
    sw__free(j);
}

/* A new job for a checked desc: its scene acquired from the desc's handle, or `scene` (a
 * reference the caller holds) retained. */
static sw_result job_create(sw_rt_renderer *r, const sw_frame_desc *desc, sw_rt_scene *scene,
                            rt_job **out, sw_status *status)
{
    rt_job *j = *out = sw__calloc(1, sizeof *j);
    if (!j)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_renderer_prepare: out of memory");
    sw_result res = SW_OK;
    if (scene) {
        sw_rt_scene_retain(scene);
        j->scene = scene;
    } else {
        res = sw_rt_scene_acquire_frame(desc->scene, desc->walkthrough, &j->scene, status);
    }
    if (res == SW_OK && r->in_flight && j->scene != r->cache_scene && j->scene->lineage &&
        j->scene->lineage == r->cache_scene->lineage) {
        /* A node scene published a version since the waiting frames were prepared: this frame
         * draws theirs too (the pipeline draws one version at a time); the next prepare with no
         * frame waiting moves on to the newest. */
        sw_rt_scene_release(j->scene);
        j->scene = r->cache_scene;
        sw_rt_scene_retain(j->scene);
    }
    if (res == SW_OK && r->in_flight && j->scene != r->cache_scene)
        res = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                       "sw_renderer_prepare: frames of another scene are prepared; submit them "
                       "before preparing one of this scene");
    if (res == SW_OK && desc->output_path && !(j->output_path = sw__strdup(desc->output_path)))
        res = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_renderer_prepare: out of memory");
    if (res == SW_OK)
        res = gpu_frame(r, j->scene, desc, &j->job.desc, status);
    if (res != SW_OK) {
        job_free(j);
        *out = NULL;
        return res;
    }
    j->job.sg = j->scene->sg;
    return SW_OK;
}

/* Hands the frame of a checked desc to the visibility thread (started on first use): on the
 * desc's scene, or on `scene` with `extra` (an immediate frame, whose occurrences V reads: the
 * caller keeps them until the frame is submitted). Every frame, sw_renderer_draw's too, is
 * prepared there: one pipeline, whichever call drew it. */
static sw_result prepare_frame(sw_rt_renderer *r, const sw_frame_desc *desc, sw_rt_scene *scene,
                               const sw_rt_frame_extra *extra, sw_status *status)
{
    sw_result res = r->pipeline ? SW_OK : sw_rt_pipeline_start(r->gpu, &r->pipeline, status);
    if (res != SW_OK)
        return res;
    const uint64_t w0 = sw_th_thread_waits().waits;
    rt_job *j;
    res = job_create(r, desc, scene, &j, status);
    if (res != SW_OK)
        return res;
    if (extra) {
        j->job.desc.occurrences = extra->occurrences;
        j->job.desc.n_occurrences = extra->n_occurrences;
        j->shading = extra->shading;
        /* a host's shading has no program for kept grids: its frame evaluates every grid */
        j->job.desc.no_kept_grids |= extra->shading != NULL;
    }
    j->job.pool_waits_before = sw_th_thread_waits().waits - w0;
    j->job.frame = ++r->frames_prepared;
    j->job.spent = r->spent;
    r->spent = NULL;
    r->in_flight++;
    j->t_pushed = sw__clock_ms();
    sw_rt_pipeline_push(r->pipeline, &j->job);
    return SW_OK;
}

/* Waits for the oldest prepared frame and draws it on this thread; ms_total counts from t0, the
 * wait for the visibility thread from this call (since_push: from the frame's hand-over, for a
 * caller that did nothing in between, so that the wait covers the visibility thread's time
 * however the threads were scheduled). */
static sw_result submit_frame(sw_rt_renderer *r, double t0, int since_push, sw_frame_stats *stats,
                              sw_status *status)
{
    const double t_call = sw__clock_ms();
    const sw_th_wait_count w0 = sw_th_thread_waits();
    rt_job *j = (rt_job *)sw_rt_pipeline_pop(r->pipeline);
    r->in_flight--;
    const double t1 = sw__clock_ms();
    sw_result res = j->job.result;
    if (res != SW_OK) {
        if (status)
            *status = j->job.status;
        job_free(j);
        return res;
    }
    sw_gpu_image image = {0};
    sw_gpu_frame_stats gstats = {0};
    const sw__gpu_surface_programs library = r->gpu->surf;
    if (j->shading)
        r->gpu->surf = *j->shading; /* this frame only */
    res = sw_gpu_frame_submit_keep(r->gpu, j->job.plan, &image, &gstats, status);
    r->gpu->surf = library;
    if (res == SW_OK)
        occlusion_feedback(r, &j->job.desc, &gstats);
    /* freed by V with the next prepare; a spent plan older than that (no prepare in between) is
     * freed here */
    sw_gpu_frame_plan_recycle(r->gpu, r->spent);
    r->spent = j->job.plan;
    j->job.plan = NULL;
    if (res == SW_OK)
        res = finish_frame(&image, j->output_path, &j->job.desc, &gstats, t0, &w0,
                           j->job.pool_waits + j->job.pool_waits_before, stats, status);
    if (res == SW_OK && stats) {
        stats->ms_visibility = j->job.ms_visibility;
        stats->ms_wait_visibility = t1 - (since_push ? j->t_pushed : t_call);
    }
    job_free(j);
    return res;
}

sw_result sw_renderer_prepare(sw_renderer renderer, const sw_frame_desc *desc, sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_prepare: NULL desc");
    sw_rt_renderer *r;
    sw_result res = owned_renderer(renderer, "sw_renderer_prepare", &r, status);
    if (res == SW_OK)
        res = check_frame_desc(desc, status);
    if (res == SW_OK && r->in_flight >= SW_RENDERER_MAX_PREPARED)
        res = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                       "sw_renderer_prepare: %d frames are prepared already; submit one first",
                       SW_RENDERER_MAX_PREPARED);
    if (res == SW_OK)
        res = prepare_frame(r, desc, NULL, NULL, status);
    if (res == SW_OK)
        sw__status_ok(status);
    return res;
}

sw_result sw_renderer_submit(sw_renderer renderer, sw_frame_stats *stats, sw_status *status)
{
    sw_rt_renderer *r;
    sw_result res = owned_renderer(renderer, "sw_renderer_submit", &r, status);
    if (res != SW_OK)
        return res;
    if (!r->in_flight)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "sw_renderer_submit: no prepared frame (call sw_renderer_prepare first)");
    return submit_frame(r, sw__clock_ms(), 0, stats, status);
}

sw_result sw_renderer_draw(sw_renderer renderer, const sw_frame_desc *desc, sw_frame_stats *stats,
                           sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_draw: NULL desc");
    return sw__rt_renderer_draw_scene(renderer, "sw_renderer_draw", NULL, desc, NULL, stats,
                                      status);
}

sw_result sw__rt_renderer_immediate(sw_renderer handle, const char *fn, int drawing,
                                    struct sw_rt_immediate ***slot, sw_gpu_context **gpu,
                                    sw_status *status)
{
    sw_rt_renderer *r;
    sw_result res = owned_renderer(handle, fn, &r, status);
    if (res != SW_OK)
        return res;
    if (drawing && r->in_flight)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "%s: %u prepared frames wait; submit them first", fn, r->in_flight);
    *slot = &r->immediate;
    *gpu = r->gpu;
    return SW_OK;
}

sw_result sw__rt_renderer_draw_scene(sw_renderer handle, const char *fn, sw_rt_scene *scene,
                                     const sw_frame_desc *desc, const sw_rt_frame_extra *extra,
                                     sw_frame_stats *stats, sw_status *status)
{
    sw_rt_renderer *r;
    sw_result res = owned_renderer(handle, fn, &r, status);
    if (res != SW_OK)
        return res;
    if (r->in_flight)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "%s: %u prepared frames wait; submit them first", fn, r->in_flight);
    const double t0 = sw__clock_ms();
    res = check_frame_desc(desc, status);
    if (res == SW_OK)
        res = prepare_frame(r, desc, scene, extra, status);
    return res == SW_OK ? submit_frame(r, t0, 1, stats, status) : res;
}

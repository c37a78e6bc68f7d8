/* Public rendering API: a headless renderer owns a GL context on its creating thread and draws
 * converged frames (ARCHITECTURE.md: only the GL owner touches GL). */
#include "sw_rt.h"

#include "sw_lod_cache.h"
#include "sw_status_util.h"
#include "sw_th_pool.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

/* The hierarchies live with the renderer, for the scene it last drew: a walkthrough keeps drawing
 * one scene, and the pool's workers then stay busy with that scene only. */
typedef struct sw_rt_renderer {
    sw_gpu_context *gpu;
    pthread_t owner;
    sw_th_pool *pool;        /* created on the first frame that needs it */
    sw_lod_cache *cache;     /* of cache_scene */
    uint32_t cache_scene;    /* scene handle id; 0 = none */
    uint32_t worker_threads; /* the pool's size; 0 = one per online processor */
} sw_rt_renderer;

static sw_rt_pool g_renderers = SW_RT_POOL_INIT;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

sw_result sw_renderer_create(const sw_renderer_desc *desc, sw_renderer *out, sw_status *status)
{
    if (!out)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_create: NULL out");
    out->id = 0;
    const uint32_t workers = desc ? desc->worker_threads : 0;
    if (workers > 1024)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "worker_threads %u above 1024", workers);
    sw_rt_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    r->worker_threads = workers;
    sw_result res = sw_gpu_context_create_headless(&r->gpu, status);
    if (res != SW_OK) {
        free(r);
        return res;
    }
    r->owner = pthread_self();
    out->id = sw_rt_pool_add(&g_renderers, r);
    if (!out->id) {
        sw_gpu_context_free(r->gpu);
        free(r);
        return sw__fail(status, SW_ERR_LIMIT, "too many renderers");
    }
    return SW_OK;
}

sw_result sw_renderer_destroy(sw_renderer renderer)
{
    sw_rt_renderer *r = sw_rt_pool_get(&g_renderers, renderer.id);
    if (!r)
        return SW_ERR_STALE_HANDLE;
    if (!pthread_equal(r->owner, pthread_self()))
        return SW_ERR_INVALID_ARGUMENT; /* its GL context is current on another thread */
    sw_rt_pool_remove(&g_renderers, renderer.id);
    sw_lod_cache_destroy(r->cache);
    sw_th_pool_destroy(r->pool);
    sw_gpu_context_free(r->gpu);
    free(r);
    return SW_OK;
}

const char *sw_renderer_description_ptr(sw_renderer renderer)
{
    sw_rt_renderer *r = sw_rt_pool_get(&g_renderers, renderer.id);
    return r ? sw_gpu_context_description_ptr(r->gpu) : "";
}

static sw_result check_frame_desc(const sw_frame_desc *desc, sw_status *status)
{
    if (desc->width < 0 || desc->height < 0 || desc->width > 16384 || desc->height > 16384)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "frame size %dx%d out of 1..16384",
                        desc->width, desc->height);
    if (desc->error_px != 0.0 && !(desc->error_px > 0.0 && isfinite(desc->error_px)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "screen-space error %g px must be positive and finite", desc->error_px);
    if (desc->camera.fovy_deg != 0.0 && !(desc->camera.fovy_deg > 0.0 && desc->camera.fovy_deg < 180.0))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "field of view %g° out of (0, 180)",
                        desc->camera.fovy_deg);
    for (int k = 0; k < 3; k++) {
        if (!isfinite(desc->camera.eye[k]) || !isfinite(desc->camera.target[k]) ||
            !isfinite(desc->camera.up[k]))
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "camera has a non-finite coordinate");
    }
    return SW_OK;
}

/* The renderer's hierarchy cache for `scene` (a cache of another scene is dropped first). */
static sw_result renderer_cache(sw_rt_renderer *r, sw_scene handle, sw_rt_scene *scene,
                                sw_lod_cache **out, sw_status *status)
{
    if (r->cache && r->cache_scene == handle.id) {
        *out = r->cache;
        return SW_OK;
    }
    sw_lod_cache_destroy(r->cache);
    r->cache = NULL;
    r->cache_scene = 0;
    if (!r->pool) {
        sw_th_pool_desc pd = {0};
        pd.worker_count = r->worker_threads;
        if (sw_th_pool_create(&pd, &r->pool) != SW_OK)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "worker pool: could not start");
    }
    sw_result res = sw_lod_cache_create(scene->sg, r->pool, NULL, &r->cache, status);
    if (res == SW_OK)
        r->cache_scene = handle.id;
    *out = r->cache;
    return res;
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
    out->patches_gpu_evaluated = g->patches_gpu_evaluated;
    out->patches_exact = g->patches_exact;
    out->atlas_pages = g->atlas_pages;
    out->trim_reused = g->trim_reused;
    out->hierarchy_nodes = g->hlod_nodes;
    out->refine_rounds = g->hlod_refine_rounds;
    out->fallback_draws = g->hlod_fallback_faces + g->hlod_refine_requests;
    out->pool_waits = g->hlod_waits;
    out->ms_hierarchy = g->ms_hierarchy;
    out->ms_tessellate = g->ms_tessellate;
    out->ms_trim = g->ms_trim;
    out->ms_draw = g->ms_draw;
    out->ms_readback = g->ms_readback;
}

sw_result sw_renderer_draw(sw_renderer renderer, const sw_frame_desc *desc, sw_frame_stats *stats,
                           sw_status *status)
{
    if (!desc)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_renderer_draw: NULL desc");
    sw_rt_renderer *r = sw_rt_pool_get(&g_renderers, renderer.id);
    if (!r)
        return sw__fail(status, SW_ERR_STALE_HANDLE, "renderer handle %#x is stale or invalid",
                        renderer.id);
    if (!pthread_equal(r->owner, pthread_self()))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "sw_renderer_draw called from a thread that does not own the GL context");
    sw_result res = check_frame_desc(desc, status);
    if (res != SW_OK)
        return res;
    sw_rt_scene *scene;
    res = sw_rt_scene_acquire(desc->scene, &scene, status);
    if (res != SW_OK)
        return res;

    double t0 = now_ms();
    sw_gpu_frame_desc frame = {0};
    frame.width = desc->width ? desc->width : 1280;
    frame.height = desc->height ? desc->height : 720;
    frame.error_px = desc->error_px > 0.0 ? desc->error_px : 0.5;
    for (int k = 0; k < 3; k++) {
        frame.camera.eye[k] = desc->camera.eye[k];
        frame.camera.target[k] = desc->camera.target[k];
        frame.camera.up[k] = desc->camera.up[k];
    }
    frame.camera.fovy_deg = desc->camera.fovy_deg > 0.0 ? desc->camera.fovy_deg : 40.0;
    frame.background[0] = frame.background[1] = frame.background[2] = 1.0f;
    frame.background[3] = 1.0f;
    frame.eval_exact = desc->eval_exact != 0;
    frame.walkthrough = desc->walkthrough != 0;
    frame.want_depth = 0;
    if (desc->output_path) {
        size_t n = strlen(desc->output_path);
        frame.want_depth = n > 4 && strcasecmp(desc->output_path + n - 4, ".exr") == 0;
    }

    if (!frame.eval_exact && !desc->no_hierarchy) {
        res = renderer_cache(r, desc->scene, scene, &frame.hierarchies, status);
        if (res != SW_OK)
            return res;
    }

    sw_gpu_image image = {0};
    sw_gpu_frame_stats gstats = {0};
    res = sw_gpu_render_scene(r->gpu, scene->sg, &frame, &image, &gstats, status);
    double t1 = now_ms();
    if (res == SW_OK && desc->output_path)
        res = sw_gpu_image_write(&image, desc->output_path, status);
    double t2 = now_ms();
    sw_gpu_image_free(&image);
    if (res == SW_OK && stats) {
        copy_stats(&gstats, stats);
        stats->ms_write = t2 - t1;
        stats->ms_total = t2 - t0;
    }
    return res;
}

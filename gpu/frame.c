/* SPDX-License-Identifier: MIT */
/* One frame of a scene (Guthe et al. 2005 §7 merged with Kumar et al. 1997 §4), as the stages of
 * frame_stages.h: the desc resolved once into the frame's constants (sw__fr_env: the view, the
 * density bound's view, the grid classes' segment counts, ε_img), then cull -> select ->
 * tessellate -> trim plan in sw_gpu_frame_prepare (plain memory: the visibility thread may run it
 * for frame i+1 while the GL thread submits frame i, Kumar §5.2), and trim atlas -> submit ->
 * present / read back in sw_gpu_frame_submit.
 *
 * Times: ms_hierarchy is the converged wait for hierarchy builds and refinements; ms_tessellate the
 * rest of prepare (culling, selection, bounds, grids, trim resolutions, loops and borders);
 * ms_trim the atlas; ms_draw upload and draw calls, then the wait for the frame before to complete
 * (one frame in flight: no glFinish); ms_readback presenting and reading back. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sw__gpu_set_patch_hook(sw_gpu_context *ctx, sw__gpu_patch_hook fn, void *user)
{
    ctx->patch_hook = fn;
    ctx->patch_hook_user = user;
}

void sw__gpu_set_crack_fill(sw_gpu_context *ctx, int on)
{
    ctx->crack_fill_off = !on;
}

void sw__gpu_set_resident(sw_gpu_context *ctx, int on)
{
    ctx->resident_off = !on;
}

void sw__gpu_set_grids_resident(sw_gpu_context *ctx, int on)
{
    ctx->grids_resident_off = !on;
}

void sw__gpu_set_border_affine(sw_gpu_context *ctx, int on)
{
    ctx->border_affine_off = !on;
}

void sw__gpu_set_back_ribbons(sw_gpu_context *ctx, int keep)
{
    ctx->back_ribbons_kept = keep != 0;
}

void sw__gpu_set_eval_mode(sw_gpu_context *ctx, sw__gpu_eval_mode mode)
{
    ctx->eval_mode = (int32_t)mode;
}

/* The density bound's view and the segment counts grids may take (every count up to
 * MAX_SEGMENTS on the CPU; what the predefined grid classes draw on the GPU). */
static void screen_view_init(sw__fr_env *env)
{
    const sw__gpu_view *v = &env->view;
    sw_lod_screen_view *s = &env->screen;
    memcpy(s->right, v->right, sizeof s->right);
    memcpy(s->up, v->up, sizeof s->up);
    memcpy(s->fwd, v->fwd, sizeof s->fwd);
    s->focal_px = v->focal_px;
    s->tan_corner = hypot(v->tan_x, v->tan_y);
    s->near_plane = v->near_plane;
    s->eps_px = env->eps_px;
    env->cpu_segments.count = env->gpu_segments.count = 0;
    for (int32_t n = 1; n <= MAX_SEGMENTS; ++n) {
        env->cpu_segments.n[env->cpu_segments.count++] = n;
        int32_t c = sw__fr_class_segments(n);
        segment_set *g = &env->gpu_segments;
        if (c <= MAX_SEGMENTS && (g->count == 0 || g->n[g->count - 1] < c))
            g->n[g->count++] = c;
    }
}

/* Visibility, selection and tessellation of a frame are GL-free (the plan is plain memory). */
struct sw_gpu_frame_plan {
    sw_gpu_frame_desc desc; /* defaults resolved */
    sw__fr_env env;
    sw__fr_hierarchy hy;
    sw__fr_visible vis;
    sw__fr_selection sel;
    sw__fr_geometry geo;
    sw_gpu_frame_stats st;
    double ms_prepare;
};

static void plan_release_reader(sw_gpu_frame_plan *p)
{
    sw__fr_hierarchy *hy = &p->hy;
    if (!hy->cache || hy->reader < 0)
        return;
    sw_lod_cache_reader_leave(hy->cache, hy->reader);
    sw_lod_cache_reader_remove(hy->cache, hy->reader);
    hy->reader = -1;
}

void sw_gpu_frame_plan_free(sw_gpu_frame_plan *plan)
{
    if (!plan)
        return;
    plan_release_reader(plan);
    sw__fr_visible_free(&plan->vis);
    sw__fr_selection_free(&plan->sel);
    sw__fr_geometry_free(&plan->geo);
    sw__free(plan);
}

/* Every field zeroed but the stages' arrays, which are kept empty (frame_stash.c). */
static void plan_empty(sw_gpu_frame_plan *p)
{
    plan_release_reader(p);
    sw__fr_visible vis = p->vis;
    sw__fr_selection sel = p->sel;
    sw__fr_geometry geo = p->geo;
    sw__fr_visible_empty(&vis);
    sw__fr_selection_empty(&sel);
    sw__fr_geometry_empty(&geo);
    memset(p, 0, sizeof *p);
    p->vis = vis;
    p->sel = sel;
    p->geo = geo;
}

void sw_gpu_frame_plan_recycle(sw_gpu_context *ctx, sw_gpu_frame_plan *plan)
{
    if (!plan)
        return;
    plan_empty(plan);
    if (!sw__gpu_stash_put(ctx, SW__GPU_STASH_PLAN, plan))
        sw_gpu_frame_plan_free(plan);
}

double sw_gpu_frame_plan_ms(const sw_gpu_frame_plan *plan)
{
    return plan->ms_prepare;
}

const sw_gpu_frame_stats *sw_gpu_frame_plan_stats(const sw_gpu_frame_plan *plan)
{
    return &plan->st;
}

sw_result sw__fr_env_init(sw__fr_env *env, sw_gpu_context *ctx, const sw_sg_scene *scene,
                          const sw_gpu_frame_desc *d, sw_status *status)
{
    memset(env, 0, sizeof *env);
    env->ctx = ctx;
    env->scene = scene;
    env->sv = sw_sg_scene_view_ptr(scene);
    env->eps_px = d->error_px;
    env->exact = d->eval_exact != 0;
    env->walkthrough = d->walkthrough != 0;
    env->lod_colors = d->lod_colors != 0;
    env->trim_edges = d->trim_edges != 0;
    /* the debug capture reads the per-frame evaluation's vertices */
    env->grids_resident =
        !env->exact && !d->no_kept_grids && !ctx->grids_resident_off && ctx->capture_max == 0;
    env->static_force = d->static_force;
    if (d->static_lods && sw_lod_static_set_scene(d->static_lods) != scene)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: the static LODs belong to another scene");
    /* static LODs cull and draw only the scene's own occurrences, and not on the exact path */
    env->statics = env->exact || d->occurrences ? NULL : d->static_lods;
    /* a set whose proxies were never started keeps the plain cull of its instances */
    env->proxies = env->statics && !d->no_proxies && env->static_force == 0 &&
                   sw_lod_static_set_proxies_started(env->statics);
    env->pool = d->pool;
    memcpy(env->view.eye, d->camera.eye, sizeof env->view.eye);
    return SW_OK;
}

static sw_result hierarchy_init(sw_gpu_frame_plan *p, const sw_sg_scene *scene, sw_status *status)
{
    sw__fr_hierarchy *hy = &p->hy;
    hy->reader = -1;
    if (!p->desc.hierarchies)
        return SW_OK;
    if (sw_lod_cache_scene(p->desc.hierarchies) != scene)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: the hierarchy cache belongs to another scene");
    hy->cache = p->desc.hierarchies;
    /* A slot per plan: the plans of two overlapping frames are read at the same time. */
    hy->reader = sw_lod_cache_reader_add(hy->cache);
    if (hy->reader < 0)
        return sw__fail(status, SW_ERR_LIMIT, "frame: no free reader slot in the cache");
    sw_lod_cache_reader_enter(hy->cache, hy->reader);
    return SW_OK;
}

sw_result sw__fr_env_view(sw__fr_env *env, const sw_gpu_frame_desc *d, const double scene_box[6],
                          sw_status *status)
{
    static const double k_origin[3] = {0.0, 0.0, 0.0};
    const double near_plane = d->near_plane > 0.0 ? d->near_plane
                              : scene_box[0] <= scene_box[3]
                                  ? sw__gpu_near_plane(k_origin, scene_box)
                                  : 1.0;
    sw_result r =
        sw__gpu_view_init(&env->view, &d->camera, d->width, d->height, near_plane, status);
    screen_view_init(env);
    env->eye_shells = r == SW_OK ? sw__fr_eye_shells(env, d) : SW__FR_EYE_UNKNOWN;
    return r;
}

static sw_result run_stages(sw_gpu_frame_plan *p, sw_status *status)
{
    double scene_box[6];
    sw__fr_env *env = &p->env;
    sw_result r = sw__fr_cull_scene_box(env, &p->desc, &p->vis, scene_box, status);
    if (r == SW_OK)
        r = sw__fr_env_view(env, &p->desc, scene_box, status);
    if (r == SW_OK)
        r = sw__fr_cull(env, &p->desc, &p->vis, &p->st, status);
    if (r == SW_OK)
        r = sw__fr_select(env, &p->hy, &p->vis, &p->sel, &p->st, status);
    if (r == SW_OK)
        r = sw__fr_tessellate(env, &p->vis, &p->sel, &p->geo, &p->st, status);
    if (r == SW_OK)
        r = sw__fr_trim_plan(env, &p->geo, &p->st, status);
    if (r == SW_OK)
        r = sw__fr_shapes_plan(env, &p->vis, &p->geo, &p->st, status);
    return r;
}

sw_result sw_gpu_frame_prepare(sw_gpu_context *ctx, const sw_sg_scene *scene,
                               const sw_gpu_frame_desc *desc, sw_gpu_frame_plan **out,
                               sw_status *status)
{
    *out = NULL;
    double t0 = sw__clock_ms();
    const sw_th_wait_count w0 = sw_th_thread_waits(); /* every wait of the frame */
    sw_gpu_frame_plan *p = sw__gpu_stash_take(ctx, SW__GPU_STASH_PLAN);
    if (!p)
        p = sw__calloc(1, sizeof *p);
    if (!p)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame: out of memory");
    p->hy.reader = -1;
    sw__gpu_desc_defaults(desc, &p->desc);
    sw_result r = sw__fr_env_init(&p->env, ctx, scene, &p->desc, status);
    if (r == SW_OK)
        r = hierarchy_init(p, scene, status);
    if (r == SW_OK) {
        p->env.borders = sw__fr_border_cache_begin(ctx->borders, scene);
        r = run_stages(p, status);
        sw__fr_border_cache_end(p->env.borders);
        p->env.borders = NULL; /* the plan outlives the frame's hold */
    }
    if (r != SW_OK) {
        sw_gpu_frame_plan_recycle(ctx, p);
        return r;
    }
    /* the selection is consumed by the tessellation: only the geometry travels to submit (its
     * arrays stay, for the frame this plan is recycled into) */
    sw__fr_selection_empty(&p->sel);
    p->ms_prepare = sw__clock_ms() - t0;
    p->st.ms_tessellate = p->ms_prepare - p->st.ms_hierarchy; /* the waits are counted apart */
    sw__gpu_waits_since(&w0, &p->st);
    *out = p;
    return SW_OK;
}

sw_result sw_gpu_frame_submit_keep(sw_gpu_context *ctx, sw_gpu_frame_plan *plan, sw_gpu_image *out,
                                   sw_gpu_frame_stats *stats, sw_status *status)
{
    memset(out, 0, sizeof *out);
    const sw_th_wait_count w0 = sw_th_thread_waits();
    sw__gpu_make_current(ctx);
    const sw_gpu_frame_desc *desc = &plan->desc;
    sw__fr_geometry *geo = &plan->geo;
    sw_gpu_frame_stats *st = &plan->st;
    sw_result r = plan->env.ctx == ctx
                      ? SW_OK
                      : sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                                 "frame: the plan was prepared for another context");
    sw__gpu_host_state host;
    const int host_state = desc->present || sw__gpu_context_adopted(ctx);
    if (host_state)
        sw__gpu_host_state_save(&host);
    double t1 = sw__clock_ms();
    /* GPU time of the trim textures and the draw, by two GL_TIMESTAMP queries read once the frame
     * is complete (a GL_TIME_ELAPSED query gave 7.5e6 ms for the first frame of a context on
     * llvmpipe) */
    GLuint query[2] = {0, 0};
    glGenQueries(2, query);
    glQueryCounter(query[0], GL_TIMESTAMP);
    if (r == SW_OK)
        r = sw__fr_trim_atlas(ctx, plan->env.scene, geo, st, status);
    double t2 = sw__clock_ms();
    if (r == SW_OK)
        r = sw__fr_submit(ctx, &plan->env.view, desc, geo, status);
    glQueryCounter(query[1], GL_TIMESTAMP);
    /* No glFinish: the frame is fenced and flushed, and this thread waits only for the frame
     * before it, so the rasterizer works on this one while the next is prepared and uploaded. */
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    st->ms_gpu = sw__gpu_frame_complete(ctx); /* the frame before's */
    ctx->frame_fence = fence;
    memcpy(ctx->frame_query, query, sizeof query);
    double t3 = sw__clock_ms();
    if (r == SW_OK && desc->present)
        r = sw__gpu_present(ctx, &plan->env.view, desc->present_depth, &host, status);
    if (r == SW_OK && !desc->no_readback) {
        r = sw__gpu_readback(ctx, &plan->env.view, desc->want_depth, out, status);
        st->ms_gpu = sw__gpu_frame_complete(ctx); /* read back: this frame is complete */
    }
    if (host_state)
        sw__gpu_host_state_restore(&host);
    double t4 = sw__clock_ms();

    st->triangles += geo->mesh.n_idx / 3 - geo->border_triangles + geo->resident_triangles;
    st->triangles += (uint64_t)ctx->grid_extra_triangles; /* >= 0: never a coarser grid kept */
    st->resident_triangles = geo->resident_triangles + ctx->grid_triangles;
    st->grid_hits = ctx->grid_hits;
    st->grid_misses = ctx->grid_misses;
    st->upload_bytes = ctx->upload_bytes;
    st->border_triangles = geo->border_triangles;
    st->ms_trim = t2 - t1;
    st->ms_draw = t3 - t2;
    st->ms_readback = t4 - t3;
    st->near_plane = plan->env.view.near_plane;
    sw__gpu_waits_since(&w0, st);
    if (stats)
        *stats = *st;
    sw_lod_cache *cache = plan->hy.cache;
    plan_release_reader(plan);
    if (cache)
        sw_lod_cache_collect(cache);
    plan->env.scene = NULL; /* spent: what is left is plain memory */
    plan->env.ctx = NULL;
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

double sw__gpu_frame_complete(sw_gpu_context *ctx)
{
    if (!ctx->frame_fence)
        return 0.0;
    GLenum w;
    do /* a second at a time: a fence that never signals is a lost context, reported by GL */
        w = glClientWaitSync(ctx->frame_fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000u);
    while (w == GL_TIMEOUT_EXPIRED);
    glDeleteSync(ctx->frame_fence);
    ctx->frame_fence = 0;
    GLuint64 ns[2] = {0, 0};
    if (w != GL_WAIT_FAILED) {
        glGetQueryObjectui64v(ctx->frame_query[0], GL_QUERY_RESULT, &ns[0]);
        glGetQueryObjectui64v(ctx->frame_query[1], GL_QUERY_RESULT, &ns[1]);
    }
    glDeleteQueries(2, ctx->frame_query);
    memset(ctx->frame_query, 0, sizeof ctx->frame_query);
    return ns[1] > ns[0] ? 1e-6 * (double)(ns[1] - ns[0]) : 0.0;
}

sw_result sw_gpu_frame_submit(sw_gpu_context *ctx, sw_gpu_frame_plan *plan, sw_gpu_image *out,
                              sw_gpu_frame_stats *stats, sw_status *status)
{
    sw_result r = sw_gpu_frame_submit_keep(ctx, plan, out, stats, status);
    sw_gpu_frame_plan_recycle(ctx, plan);
    return r;
}

sw_result sw_gpu_render_scene(sw_gpu_context *ctx, const sw_sg_scene *scene,
                              const sw_gpu_frame_desc *desc, sw_gpu_image *out,
                              sw_gpu_frame_stats *stats, sw_status *status)
{
    memset(out, 0, sizeof *out);
    sw_gpu_frame_plan *plan;
    sw_result r = sw_gpu_frame_prepare(ctx, scene, desc, &plan, status);
    return r == SW_OK ? sw_gpu_frame_submit(ctx, plan, out, stats, status) : r;
}

/* SPDX-License-Identifier: MIT */
/* The outline stage (sw_nodes.h SHAPE nodes; sw_sg_scene.h, SW_SG_NODE_SHAPE). On the
 * visibility thread, GL-free: each shape occurrence inside the frustum is mapped into the target's
 * pixels exactly (gpu/curves_place.c: its loops cut at the near plane and mapped through the
 * perspective). On the GL thread, after the opaque frame: each is drawn anti-aliased and
 * composited with its plane's depth (gpu/curves.c, Santana §3-§5), in scene order.
 * An outline the 2D path refuses after the cut (a loop left without area) is skipped and counted;
 * nothing else of the frame depends on it. */
#include "frame_stages.h"
#include "sw_curves.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <string.h>

/* The loops of shape `s` as the 2D path takes them (curves borrowed from the scene). */
static sw_result shape_loops(const sw__fr_env *env, const sw_sg_shape_rec *s,
                             sw__curves_loop **loops, size_t *cap_loops, sw_sg_curve **curves,
                             size_t *cap_curves, sw_status *status)
{
    const sw_sg_scene_view *v = env->sv;
    size_t n_curves = 0;
    for (uint32_t L = 0; L < s->n_loops; ++L)
        n_curves += v->loops[s->first_loop + L].n_curves;
    if (!sw__grow((void **)loops, cap_loops, s->n_loops, sizeof **loops) ||
        !sw__grow((void **)curves, cap_curves, n_curves, sizeof **curves))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "outlines: out of memory");
    size_t at = 0;
    for (uint32_t L = 0; L < s->n_loops; ++L) {
        const sw_sg_loop_rec *l = &v->loops[s->first_loop + L];
        (*loops)[L] = (sw__curves_loop){*curves + at, l->n_curves};
        for (uint32_t k = 0; k < l->n_curves; ++k)
            sw_sg_scene_curve(env->scene, l->first_curve + k, &(*curves)[at++]);
    }
    return SW_OK;
}

/* The occurrence's plane in eye-relative world coordinates: (x, y, 0) under its transform; for
 * a label on screen (SW_SG_SHAPE_SCREEN) the plane through its node's origin facing the camera,
 * scaled so that one unit is px_size pixels at that depth (the plane is parallel to the screen:
 * every point of it is at the origin's depth). 0: the origin is not in front of the near plane. */
static int shape_plane(const sw__fr_env *env, const sw_sg_shape_rec *s, const double world[12],
                       sw__curves_plane *pl)
{
    const sw__gpu_view *v = &env->view;
    for (int k = 0; k < 3; ++k) {
        pl->origin[k] = world[4 * k + 3] - v->eye[k];
        pl->ax[k] = world[4 * k];
        pl->ay[k] = world[4 * k + 1];
    }
    if (!(s->flags & SW_SG_SHAPE_SCREEN))
        return 1;
    const double d =
        v->fwd[0] * pl->origin[0] + v->fwd[1] * pl->origin[1] + v->fwd[2] * pl->origin[2];
    if (!(d > v->near_plane))
        return 0;
    const double unit = s->px_size * d / v->focal_px;
    for (int k = 0; k < 3; ++k) {
        pl->ax[k] = unit * v->right[k];
        pl->ay[k] = unit * v->up[k];
    }
    return 1;
}

sw_result sw__fr_shapes_plan(const sw__fr_env *env, const sw__fr_visible *vis, sw__fr_geometry *geo,
                             sw_gpu_frame_stats *st, sw_status *status)
{
    sw__curves_loop *loops = NULL;
    sw_sg_curve *curves = NULL;
    size_t cap_loops = 0, cap_curves = 0;
    sw_result r = SW_OK;
    for (size_t i = 0; i < vis->n_shapes && r == SW_OK; ++i) {
        const sw__fr_mesh_occ *o = &vis->shapes[i];
        const sw_sg_shape_rec *s = &env->sv->shapes[o->mesh];
        r = shape_loops(env, s, &loops, &cap_loops, &curves, &cap_curves, status);
        if (r != SW_OK)
            break;
        sw__curves_plane plane;
        if (!shape_plane(env, s, o->world, &plane)) {
            st->shapes_culled++; /* a label whose anchor is behind the near plane */
            continue;
        }
        sw__curves_projected pr;
        sw_status why = {0};
        sw_result pr_r = sw__curves_project(loops, s->n_loops, &plane, &env->view, &pr, &why);
        if (pr_r == SW_ERR_OUT_OF_MEMORY) {
            r = sw__fail(status, pr_r, "outlines: %s", why.message);
            break;
        }
        if (pr_r != SW_OK) {
            st->shapes_skipped++;
            continue;
        }
        st->shape_fallbacks += pr.fallbacks;
        if (!pr.shape) {
            st->shapes_culled++; /* nothing of it in front of the near plane, near the target */
            continue;
        }
        if (!sw__grow((void **)&geo->shapes, &geo->cap_shapes, geo->n_shapes + 1,
                      sizeof *geo->shapes)) {
            sw__curves_shape_free(pr.shape);
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "outlines: out of memory");
            break;
        }
        sw__fr_shape_draw *d = &geo->shapes[geo->n_shapes++];
        d->shape = pr.shape;
        d->depth = pr.depth;
        memcpy(d->color, o->color, sizeof d->color);
        st->shapes_drawn++;
    }
    sw__free(loops);
    sw__free(curves);
    return r;
}

sw_result sw__fr_draw_shapes(sw_gpu_context *ctx, const sw__gpu_view *view,
                             const sw__fr_geometry *geo, sw_status *status)
{
    if (geo->n_shapes == 0)
        return SW_OK;
    if (!ctx->curves) {
        sw_result r = sw__curves_renderer_create(&ctx->curves, status);
        if (r != SW_OK)
            return r;
    }
    const sw__curves_view px = {{1, 0, 0, 0, 1, 0}, view->width, view->height};
    for (size_t i = 0; i < geo->n_shapes; ++i) {
        const sw__fr_shape_draw *d = &geo->shapes[i];
        sw_result r = sw__curves_draw_placed(ctx->curves, d->shape, &px, d->color, ctx->fbo,
                                             &d->depth, status);
        if (r != SW_OK)
            return r;
    }
    return SW_OK;
}

void sw__fr_shapes_empty(sw__fr_geometry *geo)
{
    for (size_t i = 0; i < geo->n_shapes; ++i)
        sw__curves_shape_free(geo->shapes[i].shape);
    geo->n_shapes = 0;
}

/* SPDX-License-Identifier: MIT */
/* The select stage: the representation of everything the cull stage kept — the LOD cut.
 *
 * Per visible unit instance (a super-surface of whole faces, lod/static/sw_lod_static_set.h) the
 * static LOD level whose declared ε_k meets the object-space tolerance its nearest point needs
 * (Kumar et al. 1997 §4), else its shown faces go to the per-frame path. Per per-frame face
 * occurrence its hierarchy cut (Guthe et al. 2005 §7, stage_hierarchy.c), or its own Bézier patches
 * when it has no hierarchy (yet).
 *
 * The tolerance. A displacement d of a point at depth z (along the view axis) and off-axis
 * tangents (t_x, t_y) moves its image by at most focal_px |d| sqrt(1 + t_x^2 + t_y^2) / z pixels
 * (the projection's Jacobian [[1, 0, -t_x], [0, 1, -t_y]] f / z has that spectral norm). Every
 * visible point of the unit has z >= the nearest depth of its world box (clamped by the near
 * plane) and tangents within the frustum's corner, so a level within
 *     ε_world = ε_img z_min / (focal_px sqrt(1 + tan_corner^2))
 * of the exact surface is within ε_img pixels wherever it shows (sw_lod_object_tolerance); in the
 * faces' object space that is ε_world / s, s the bound of the instance transform's stretch the
 * hierarchy path uses too (sw_sg_stretch_bound: at least 1 for a rigid one). Kumar §4.4 measures
 * the distance to the box's centre ("the distance of the super-surface from the viewer"): it is no
 * bound for a large unit seen from close by, so we take the box's nearest depth. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Colours of LOD colouring: static levels fine -> coarse, then the per-frame path. */
static const float k_level_colors[6][4] = {
    {0.20f, 0.45f, 0.90f, 1.0f}, {0.15f, 0.70f, 0.70f, 1.0f}, {0.30f, 0.75f, 0.30f, 1.0f},
    {0.80f, 0.75f, 0.20f, 1.0f}, {0.90f, 0.50f, 0.15f, 1.0f}, {0.85f, 0.25f, 0.55f, 1.0f},
};
static const float k_dynamic_color[4] = {0.75f, 0.75f, 0.78f, 1.0f};
static const float k_exact_edges_color[4] = {0.68f, 0.55f, 0.90f, 1.0f};
static const float k_proxy_color[4] = {0.95f, 0.35f, 0.25f, 1.0f};

void sw__fr_lod_color(int32_t level, float out[4])
{
    const float *c = level == SW__FR_PROXY_COLOR ? k_proxy_color
                     : level == -2               ? k_exact_edges_color
                     : level < 0                 ? k_dynamic_color
                                                 : k_level_colors[level > 5 ? 5 : level];
    memcpy(out, c, 4 * sizeof *out);
}

void sw__fr_selection_free(sw__fr_selection *sel)
{
    sw__free(sel->statics);
    sw__free(sel->faces);
    sw__free(sel->items);
    memset(sel, 0, sizeof *sel);
}

double sw__fr_unit_tolerance(const sw__fr_env *env, const double obj_box[6], const double m[12],
                             double *extent_px)
{
    const sw__gpu_view *v = &env->view;
    double eb[6];
    sw__fr_eye_box_of(v->eye, obj_box, m, eb);
    const double z = sw__gpu_view_box_depth(v, eb);
    const double diag = sqrt((eb[3] - eb[0]) * (eb[3] - eb[0]) + (eb[4] - eb[1]) * (eb[4] - eb[1]) +
                             (eb[5] - eb[2]) * (eb[5] - eb[2]));
    const double eps_world =
        sw_lod_object_tolerance(env->eps_px, z, v->focal_px, v->tan_x, v->tan_y);
    *extent_px = diag * env->eps_px / eps_world;
    return eps_world / sw_sg_stretch_bound(m);
}

/* Coarsest level within tol that is kept, -1 when none. */
static int32_t level_within(const sw_lod_static_chain *c, double tol)
{
    for (int32_t k = c->n_levels - 1; k >= 0; --k)
        if (c->levels[k].eps <= tol && c->levels[k].n_triangles > 0)
            return k;
    return -1;
}

/* The level to draw for tol: the coarsest within it, if cheap enough (sw_lod_static.h says why
 * finer ones are not drawn). */
static int32_t level_to_draw(const sw_lod_static_chain *c, double tol)
{
    const int32_t k = level_within(c, tol);
    return k >= 0 && sw_lod_static_level_drawable(c, k) ? k : -1;
}

/* Tests: the choice-th kept level of those within tol, -1 (the per-frame path) for
 * choice == their count; choice taken modulo count + 1. */
static int32_t forced_level(const sw_lod_static_chain *c, double tol, uint32_t choice)
{
    int32_t kept[SW_LOD_CACHE_MAX_LEVELS];
    uint32_t n = 0;
    const int32_t w = level_within(c, tol);
    for (int32_t k = 0; k <= w && n < SW_LOD_CACHE_MAX_LEVELS; ++k)
        if (c->levels[k].n_triangles > 0)
            kept[n++] = k;
    choice %= n + 1;
    return choice == n ? -1 : kept[choice];
}

/* The chain to use, asked for when missing: walkthrough frames only queue the build (drawn by
 * the per-frame path meanwhile), converged frames wait for it. */
static const sw_lod_static_chain *unit_chain(const sw__fr_env *env, uint32_t unit,
                                             sw_gpu_frame_stats *st)
{
    sw_lod_static_set *set = env->statics;
    const sw_lod_static_chain *c = sw_lod_static_set_get(set, unit);
    if (c)
        return c;
    if (sw_lod_static_set_state(set, unit) != SW_LOD_STATIC_EMPTY &&
        sw_lod_static_set_state(set, unit) != SW_LOD_STATIC_QUEUED)
        return NULL;
    if (env->walkthrough) {
        if (sw_lod_static_set_state(set, unit) == SW_LOD_STATIC_EMPTY)
            st->static_requests++;
        sw_lod_static_set_request(set, unit, SW_TH_PRIORITY_BACKGROUND);
        return NULL;
    }
    st->static_waits++;
    sw_lod_static_set_wait(set, unit);
    return sw_lod_static_set_get(set, unit);
}

/* The level a unit is drawn at under transform m, -1 for the per-frame path. */
static int32_t choose_level(const sw__fr_env *env, uint32_t unit, const double m[12],
                            const sw_lod_static_chain **chain, double *extent_px,
                            sw_gpu_frame_stats *st)
{
    const sw_lod_static_unit *un = sw_lod_static_set_unit(env->statics, unit);
    *chain = NULL;
    const double tol = sw__fr_unit_tolerance(env, un->box, m, extent_px);
    if (env->static_force > 0) {
        /* tests: neighbours at different levels, each within the view's tolerance, and beside
         * the per-frame path: unit i takes choice i + k among the kept levels within it */
        const sw_lod_static_chain *c = unit_chain(env, unit, st);
        if (!c)
            return -1;
        *chain = c;
        return forced_level(c, tol, unit + (uint32_t)env->static_force);
    }
    if (un->delta > tol)
        return -1; /* not even level 0 would do: do not build it for this view */
    const sw_lod_static_chain *c = unit_chain(env, unit, st);
    if (!c)
        return -1;
    *chain = c;
    return level_to_draw(c, tol);
}

/* Per visible instance: a static pick, or its shown faces into `perframe`. */
static sw_result select_instances(const sw__fr_env *env, const sw__fr_visible *vis,
                                  sw__fr_selection *sel, sw__fr_faces *perframe,
                                  sw_gpu_frame_stats *st, sw_status *status)
{
    const sw_lod_static_instances *ins = sw_lod_static_set_instances(env->statics);
    for (size_t i = 0; i < vis->n_instances; ++i) {
        const sw__fr_instance *vi = &vis->instances[i];
        sw_sg_bvh_item_view view;
        sw_sg_bvh_item_at(ins->bvh, vi->item, &view);
        const sw_sg_bvh_item_view *it = &view;
        const sw_lod_static_instance *in = &ins->instances[it->face];
        sw__fr_static_pick pick = {(uint32_t)i, NULL, -1, 0.0};
        if (in->unit != SW_LOD_STATIC_NO_UNIT)
            pick.level = choose_level(env, in->unit, it->world, &pick.chain, &pick.extent_px, st);
        if (pick.level >= 0) {
            if (!sw__grow((void **)&sel->statics, &sel->cap_statics, sel->n_statics + 1,
                          sizeof *sel->statics))
                return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static picks: out of memory");
            sel->statics[sel->n_statics++] = pick;
            continue;
        }
        for (size_t k = vi->first_face; k < vi->first_face + vi->n_faces; ++k)
            if (!sw__fr_faces_push(perframe, &vis->unit_faces.occ[k],
                                   vis->unit_faces.boxes + 6 * k))
                return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    }
    return SW_OK;
}

/* The per-frame faces whose boxes meet the view (the others are counted culled). */
static sw_result visible_faces(const sw__fr_env *env, const sw__fr_faces *in, sw__fr_faces *out,
                               sw_gpu_frame_stats *st, sw_status *status)
{
    for (size_t i = 0; i < in->n; ++i) {
        if (!sw__gpu_view_box_visible(&env->view, in->boxes + 6 * i)) {
            st->faces_culled++;
            continue;
        }
        occurrence o = in->occ[i];
        if (env->lod_colors)
            sw__fr_lod_color(-1, o.color);
        if (!sw__fr_faces_push(out, &o, in->boxes + 6 * i))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    }
    return SW_OK;
}

static sw_result pick_face(const sw__fr_env *env, sw__fr_hierarchy *hy, const occurrence *o,
                           sw__fr_selection *sel, sw_gpu_frame_stats *st, sw_status *status)
{
    if (!sw__grow((void **)&sel->faces, &sel->cap_faces, sel->n_faces + 1, sizeof *sel->faces))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face picks: out of memory");
    sw__fr_face_pick *p = &sel->faces[sel->n_faces];
    memset(p, 0, sizeof *p);
    p->occ = *o;
    p->first_item = sel->n_items;
    const sw_lod_hierarchy *h =
        hy->cache && !env->exact ? sw_lod_cache_get(hy->cache, o->face) : NULL;
    sw_result r = SW_OK;
    if (h) {
        p->hierarchy = 1;
        r = sw__fr_hierarchy_cut(env, hy, o, h, sel, st, status);
        p->n_items = sel->n_items - p->first_item;
    } else if (hy->cache && !env->exact) {
        st->hlod_fallback_faces++;
    }
    sel->n_faces++;
    return r;
}

void sw__fr_selection_empty(sw__fr_selection *sel)
{
    sel->n_statics = sel->n_faces = sel->n_items = 0;
}

sw_result sw__fr_select(const sw__fr_env *env, sw__fr_hierarchy *hy, const sw__fr_visible *vis,
                        sw__fr_selection *sel, sw_gpu_frame_stats *st, sw_status *status)
{
    sw__fr_selection_empty(sel);
    sw__fr_faces perframe, shown;
    memset(&perframe, 0, sizeof perframe);
    memset(&shown, 0, sizeof shown);
    sw_result r = SW_OK;
    const sw__fr_faces *candidates = &vis->faces;
    if (env->statics) {
        r = select_instances(env, vis, sel, &perframe, st, status);
        candidates = &perframe;
    }
    if (r == SW_OK)
        r = visible_faces(env, candidates, &shown, st, status);
    if (r == SW_OK && hy->cache && !env->exact)
        r = sw__fr_hierarchy_prepare(env, hy, &shown, st, status);
    for (size_t i = 0; i < shown.n && r == SW_OK; ++i)
        r = pick_face(env, hy, &shown.occ[i], sel, st, status);
    sw__fr_faces_free(&perframe);
    sw__fr_faces_free(&shown);
    return r;
}

/* SPDX-License-Identifier: MIT */
/* The trim stage: trim textures for every trimmed draw (Guthe et al. 2005 §4, §5.3) through the
 * context's atlas (§4.4).
 *
 * The plan (plain memory, on the visibility thread): each pending trim's resolution class — its
 * wanted texels (§5.3, from the tessellate stage) rounded up to a power-of-two footprint, all
 * scaled down together when the frame's footprints exceed the atlas budget — and, for a texture
 * over a face's whole trim box, the face's loops flattened at half its texel, with the face's
 * fat borders (§7.1) along those loops. The atlas (the GL thread): each texture found in the
 * atlas (kept across frames) or added and rendered by fan parity; a tile's or a node part's
 * texture from the face's loops clipped to its rectangle grown by one texel (the clipped border
 * then falls in the entry's gutter), keyed by the rectangle. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Footprints (texture plus gutters) are powers of two, so that a class changes only when the
 * wanted resolution doubles or halves, and pages pack them tightly. */
int32_t sw__fr_class_texels(double want, int32_t max_entry)
{
    int32_t foot = 16;
    while (foot - 2 * SW__GPU_ATLAS_GUTTER < want && foot - 2 * SW__GPU_ATLAS_GUTTER < max_entry)
        foot *= 2;
    int32_t n = foot - 2 * SW__GPU_ATLAS_GUTTER;
    return n < max_entry ? n : max_entry;
}

/* Whether the face lies left of loop k (the side its fat border covers), by parity: the left of a
 * counter-clockwise loop is its interior, and a point there is inside the face when the loops
 * around it, k included, are odd in number (the even-odd rule of sw_sg_trim_classify and of the
 * trim textures). The loops around k are counted at the middle of its longest edge (loops are
 * simple and do not cross, so one point decides). A probe point a fixed fraction of the longest
 * edge off the loop is no test: a band 2π long in u and 0.002 wide in v (a cone's face around its
 * seam, screw.step scaled to a diagonal of 0.03) was probed beyond its far side, and its ribbons
 * were drawn on the outer side, over the silhouette. */
int sw__fr_left_is_inside(const sw_sg_polyline *loops, uint32_t n_loops, uint32_t k)
{
    const sw_sg_polyline *l = &loops[k];
    if (l->count < 3)
        return 1;
    uint32_t best = 0;
    double best_len = -1.0, area2 = 0.0;
    const double *o = l->uv; /* the shoelace sum about a vertex: no cancellation far from 0 */
    for (uint32_t i = 0; i < l->count; ++i) {
        const double *a = l->uv + 2 * i, *b = l->uv + 2 * ((i + 1) % l->count);
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        if (len > best_len) {
            best_len = len;
            best = i;
        }
        area2 += (a[0] - o[0]) * (b[1] - o[1]) - (b[0] - o[0]) * (a[1] - o[1]);
    }
    if (!(area2 != 0.0))
        return 1;
    const double *a = l->uv + 2 * best, *b = l->uv + 2 * ((best + 1) % l->count);
    const double u = 0.5 * (a[0] + b[0]), v = 0.5 * (a[1] + b[1]);
    int around = area2 > 0.0; /* k itself, when its left is its interior */
    for (uint32_t j = 0; j < n_loops; ++j)
        if (j != k)
            around ^= sw_sg_trim_classify(&loops[j], 1, u, v);
    return around;
}

/* ---- the plan ---------------------------------------------------------------------------------
 */
int sw__fr_exact_edges(const sw__fr_env *env, double need_u, double need_v, int32_t max_entry)
{
    if (!env->trim_edges)
        return 0;
    const double texel_u = env->eps_px * need_u / sw__fr_class_texels(need_u, max_entry);
    const double texel_v = env->eps_px * need_v / sw__fr_class_texels(need_v, max_entry);
    return fmax(texel_u, texel_v) > k_exact_texel_px;
}

double sw__fr_trim_flat_tol(const sw__fr_env *env, double extent, double need, int exact,
                            int32_t max_entry)
{
    double tol = 0.5 * extent / sw__fr_class_texels(need, max_entry);
    /* need texels of extent / need each keep the surface within ε_img px (§5.3); rounded down to
     * a power of two of the extent, so that a face seen again at a similar size asks for the same
     * loops (the border cache's key) rather than new ones every frame */
    if (exact && need > 0.0 && extent > 0.0)
        tol = fmin(tol, extent * exp2(floor(log2(k_exact_flat_px / env->eps_px / need))));
    return tol;
}

/* Atlas texels the frame's trim textures take at `scale`: their classes' footprints, gutters
 * included (exact edges take none). */
static double trim_footprint(const sw__fr_geometry *g, int32_t max_entry, double scale)
{
    const int32_t g2 = 2 * SW__GPU_ATLAS_GUTTER;
    double sum = 0.0;
    for (size_t i = 0; i < g->n_trims; ++i)
        if (g->trims[i].grid < 0)
            sum += (double)(sw__fr_class_texels(g->trims[i].width * scale, max_entry) + g2) *
                   (double)(sw__fr_class_texels(g->trims[i].height * scale, max_entry) + g2);
    return sum;
}

/* The common scale of the wanted trim resolutions that keeps the frame's atlas footprints within
 * `budget` texels (the trim textures' share of the memory budget, memory_budget.c). The wanted
 * texels alone are no bound: rounding up to classes and the gutters make the footprints up to ~4x
 * larger (a 10^6-surface building wanted 3.4e8 texels, scaled to the budget, and still
 * needed 5.7e8, more than the atlas holds). Each step shrinks the scale by at least 10 %; when
 * every trim is at the smallest class the footprints cannot shrink further and the atlas reports
 * the overflow. */
static double trim_scale(const sw__fr_geometry *g, int32_t max_entry, double budget)
{
    double total = 0.0;
    for (size_t i = 0; i < g->n_trims; ++i)
        if (g->trims[i].grid < 0)
            total += g->trims[i].width * g->trims[i].height;
    double scale = total > budget ? sqrt(budget / total) : 1.0;
    for (int step = 0; step < 64; ++step) {
        const double foot = trim_footprint(g, max_entry, scale);
        if (foot <= budget)
            break;
        scale *= fmin(0.9, sqrt(budget / foot));
    }
    return scale;
}

/* A whole-box trim's loops, flattened at half its texel (or for exact edges at k_exact_flat_px),
 * and the face's fat borders. */
static sw_result plan_whole_box(sw__fr_tess *t, size_t i, double tol, sw_status *status)
{
    pending_trim *p = &t->geo->trims[i];
    int64_t loops = -1;
    sw_result r = sw__fr_face_loops(t, p->occ.face, tol, &loops, status);
    p->loops = loops;
    if (r == SW_OK) /* the borders add untrimmed draws: p stays where it is */
        r = sw__fr_loop_borders(t, &p->occ, loops, p->cell, status);
    return r;
}

/* A trim's exact edges, when it wants them (sw__fr_exact_edges): a whole box's loops flattened
 * for them (and its fat borders), the grid built. A grid that cannot be made leaves a trim
 * texture (counted). */
static sw_result plan_exact(sw__fr_tess *t, size_t i, int32_t max_entry, sw_status *status)
{
    pending_trim *p = &t->geo->trims[i];
    const sw__fr_env *env = t->env;
    p->grid = -1;
    if (!sw__fr_exact_edges(env, p->width, p->height, max_entry))
        return SW_OK;
    const double *ub = env->sv->faces[p->occ.face].uv_box;
    sw_result r = SW_OK;
    if (!p->clip)
        r = plan_whole_box(t, i,
                           fmin(sw__fr_trim_flat_tol(env, ub[1] - ub[0], p->width, 1, max_entry),
                                sw__fr_trim_flat_tol(env, ub[3] - ub[2], p->height, 1, max_entry)),
                           status);
    if (r != SW_OK)
        return r;
    const face_loops *fl = &t->geo->loops[p->loops];
    r = sw__gpu_edge_grid_add(&t->geo->edges, fl->loops, fl->n, p->clip ? p->rect : ub, &p->grid,
                              status);
    if (r == SW_OK && p->grid >= 0) {
        t->geo->draws[p->draw].edge_grid = p->grid;
        if (env->lod_colors)
            sw__fr_lod_color(-2, t->geo->draws[p->draw].color);
        t->st->trim_exact++;
    } else if (r == SW_OK) {
        t->st->trim_exact_fallbacks++;
    }
    return r;
}

sw_result sw__fr_trim_plan(const sw__fr_env *env, sw__fr_geometry *geo, sw_gpu_frame_stats *st,
                           sw_status *status)
{
    sw__fr_tess t;
    memset(&t, 0, sizeof t);
    t.env = env;
    t.st = st;
    t.geo = geo;
    const int32_t max_entry = sw__gpu_atlas_max_entry(env->ctx);
    sw__gpu_edge_grids_empty(&geo->edges);
    sw_result r = SW_OK;
    for (size_t i = 0; i < geo->n_trims && r == SW_OK; ++i)
        r = plan_exact(&t, i, max_entry, status);
    const double scale = trim_scale(geo, max_entry, env->ctx->atlas_frame_texels);
    for (size_t i = 0; i < geo->n_trims && r == SW_OK; ++i) {
        pending_trim *p = &geo->trims[i];
        if (p->grid >= 0)
            continue;
        p->w = sw__fr_class_texels(p->width * scale, max_entry);
        p->h = sw__fr_class_texels(p->height * scale, max_entry);
        /* coarser than its need (the budget's scale, an entry's size limit): its edge may move by
         * more than the object tolerance, which the error bound and occlusion culling assume */
        if (p->w < p->width || p->h < p->height) {
            st->bound_exceeded++;
            st->budget_coarsened += scale < 1.0;
        }
        if (!p->clip && p->loops < 0) {
            const double *ub = env->sv->faces[p->occ.face].uv_box;
            r = plan_whole_box(&t, i, 0.5 * fmin((ub[1] - ub[0]) / p->w, (ub[3] - ub[2]) / p->h),
                               status);
        }
    }
    for (size_t i = 0; i < geo->n_shares; ++i)
        geo->draws[geo->shares[2 * i]].edge_grid = geo->draws[geo->shares[2 * i + 1]].edge_grid;
    return r;
}

/* ---- the atlas (GL thread) --------------------------------------------------------------------
 */
static sw__gpu_trim_key trim_key(const sw_sg_scene *scene, uint32_t face, const sw_sg_face_rec *rec,
                                 const double rect[4])
{
    return (sw__gpu_trim_key){sw_sg_scene_serial(scene),
                              face,
                              rec->first_loop,
                              rec->n_loops,
                              {rect[0], rect[1], rect[2], rect[3]}};
}

/* A clipped texture's loops: the face's, clipped to the rectangle grown by one texel. */
static sw_result add_clipped(sw_gpu_context *ctx, const sw__gpu_trim_key *key,
                             const pending_trim *p, const face_loops *fl, int32_t *id,
                             sw_status *status)
{
    const double *r = p->rect;
    const double mu = (r[1] - r[0]) / p->w, mv = (r[3] - r[2]) / p->h;
    const double g[4] = {r[0] - mu, r[1] + mu, r[2] - mv, r[3] + mv};
    sw_sg_polyline *clipped = sw__calloc(fl->n ? fl->n : 1, sizeof *clipped);
    if (!clipped)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", p->occ.face);
    sw_result res = sw__gpu_trim_clip_loops(fl->loops, fl->n, g, clipped, status);
    if (res == SW_OK) {
        res = sw__gpu_atlas_add(ctx, key, p->w, p->h, clipped, fl->n, id, status);
        for (uint32_t k = 0; k < fl->n; ++k)
            sw_sg_polyline_free(&clipped[k]);
    }
    sw__free(clipped);
    return res;
}

static sw_result atlas_entry(sw_gpu_context *ctx, const sw_sg_scene *scene, sw__fr_geometry *g,
                             const pending_trim *p, sw_status *status)
{
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(scene)->faces[p->occ.face];
    const sw__gpu_trim_key key = trim_key(scene, p->occ.face, rec, p->clip ? p->rect : rec->uv_box);
    int32_t id = sw__gpu_atlas_find(ctx, &key, p->w, p->h);
    sw_result r = SW_OK;
    if (id < 0) {
        const face_loops *fl = &g->loops[p->loops];
        r = p->clip ? add_clipped(ctx, &key, p, fl, &id, status)
                    : sw__gpu_atlas_add(ctx, &key, p->w, p->h, fl->loops, fl->n, &id, status);
    }
    g->draws[p->draw].trim_entry = id;
    return r;
}

sw_result sw__fr_trim_atlas(sw_gpu_context *ctx, const sw_sg_scene *scene, sw__fr_geometry *geo,
                            sw_gpu_frame_stats *st, sw_status *status)
{
    sw_result r = sw__gpu_atlas_begin(ctx, status);
    for (size_t i = 0; i < geo->n_trims && r == SW_OK; ++i)
        if (geo->trims[i].grid < 0)
            r = atlas_entry(ctx, scene, geo, &geo->trims[i], status);
    sw__gpu_atlas_stats as;
    memset(&as, 0, sizeof as);
    if (r == SW_OK)
        r = sw__gpu_atlas_commit(ctx, &as, status);
    for (size_t i = 0; i < geo->n_shares; ++i)
        geo->draws[geo->shares[2 * i]].trim_entry = geo->draws[geo->shares[2 * i + 1]].trim_entry;
    st->trim_textures = as.entries;
    st->trim_texels = as.entry_texels;
    st->trim_reused = as.reused;
    st->atlas_pages = as.pages;
    st->atlas_texels = (uint64_t)as.pages * (uint64_t)as.side * (uint64_t)as.side;
    st->atlas_switches = as.switches;
    st->atlas_allocations = as.allocations;
    return r;
}

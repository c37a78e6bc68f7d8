/* SPDX-License-Identifier: MIT */
/* The tessellate stage for unit instances drawn at a static level (Kumar et al. 1997 §4; the
 * level is chosen by stage_select.c): the level's triangles under the instance's transform — a
 * draw of the GPU copy the context keeps of the level (gpu/resident.c), or with residency off
 * the triangles moved into the frame's mesh — and the fat borders of its shown faces.
 *
 * Cracks. A unit drawn at level k meets its neighbours — other units at other levels, faces of
 * the per-frame path, and its own faces (level 0 triangulates face by face) — along borders that
 * each side approximates within its own tolerance, all within ε_img on screen. Kumar §4.2-§4.3
 * closes the static-static joins with boundary strips stepped between shared chains (Theorem 1);
 * our chains are per face (each face's CDT places its own border vertices, and two faces of a
 * B-rep edge meet only within the edge's tolerance), so no chain is shared to step along. We close
 * every join the way the per-frame path closes its own (Guthe §7.1): each statically drawn face
 * gets its fat border along its exact trim loops, the ribbon of width 2 ε_img that covers a crack
 * between two sides each within ε_img (gpu/crack_fill.c argues the width). The overlap is sized
 * from both sides' errors because both are bounded by the same ε_img. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <string.h>

/* Fat-border sampling of a statically drawn face: its uv box cut into cells of about
 * k_border_px pixels of its unit's screen extent, between 2 and 32 per side. A chord over
 * 4 px of a curve of radius r px strays 2 / r px from it: within the ribbon's quarter width at
 * ε_img = 0.5 for r >= 8 px (tighter turns are features of a few pixels). Not rigorous between
 * samples, as gpu/crack_fill.c says of its own sampling; cost now follows the screen size. */
enum { STATIC_BORDER_MIN_CELLS = 2, STATIC_BORDER_MAX_CELLS = 32 };
static const double k_border_px = 4.0;

/* The level as a draw of the context's GPU copy (gpu/resident.c): its placement composed in
 * double, the unit's box centre moved to eye-relative world space. */
static sw_result resident_level(sw__fr_tess *t, const occurrence *o, uint32_t unit,
                                const sw_lod_static_level *lv, int32_t level, sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    if (g->n_resident == g->cap_resident &&
        !sw__grow((void **)&g->resident, &g->cap_resident, g->n_resident + 1, sizeof *g->resident))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static levels: out of memory");
    const double *box = sw_lod_static_set_unit(t->env->statics, unit)->box, *m = o->world;
    sw__gpu_resident_draw *d = &g->resident[g->n_resident++];
    d->level = lv;
    d->unit = unit;
    d->index = level;
    d->lines = NULL;
    d->n_lines = 0;
    d->draw_lines = 0;
    const double centre[4] = {0.5 * (box[0] + box[3]), 0.5 * (box[1] + box[4]),
                              0.5 * (box[2] + box[5]), 1.0};
    double off[4];
    sw__fr_xform_h(m, t->env->view.eye, centre, off);
    for (int r = 0; r < 3; ++r) {
        d->centre[r] = centre[r];
        d->off[r] = (float)off[r];
        for (int c = 0; c < 3; ++c)
            d->rot[3 * r + c] = (float)m[4 * r + c];
    }
    memcpy(d->color, o->color, sizeof d->color);
    if (t->env->lod_colors)
        sw__fr_lod_color(level, d->color);
    g->resident_triangles += lv->n_triangles;
    t->st->static_triangles += lv->n_triangles;
    return SW_OK;
}

/* Appends the level's triangles, transformed to eye-relative world space, as one draw of the
 * frame's mesh. */
static sw_result append_level(sw__fr_tess *t, const occurrence *o, const sw_lod_static_level *lv,
                              int32_t level, sw_status *status)
{
    const double *m = o->world;
    /* rigid and similarity transforms keep normals along M n; shading is two-sided */
    sw__fr_triangles tr = {.positions = lv->positions,
                           .normals_f = lv->normals,
                           .normal_matrix = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]},
                           .n_vertices = lv->n_vertices,
                           .n_triangles = lv->n_triangles,
                           .triangles = lv->triangles};
    occurrence shown = *o;
    if (t->env->lod_colors)
        sw__fr_lod_color(level, shown.color);
    sw_result r = sw__fr_append_triangles(t, &shown, &tr, status);
    t->st->static_triangles += lv->n_triangles;
    return r;
}

/* The fat borders of one statically drawn face occurrence (see the top of the file). */
static sw_result face_borders(sw__fr_tess *t, const occurrence *o, double extent_px,
                              sw_status *status)
{
    if (t->env->ctx->crack_fill_off)
        return SW_OK;
    const sw_sg_face_rec *rec = &t->env->sv->faces[o->face];
    const double *ub = rec->uv_box;
    const double cells =
        fmin(fmax(ceil(extent_px / k_border_px), STATIC_BORDER_MIN_CELLS), STATIC_BORDER_MAX_CELLS);
    const double cell[2] = {(ub[1] - ub[0]) / cells, (ub[3] - ub[2]) / cells};
    if (!sw__fr_face_trimmed(t->env, o->face))
        return sw__fr_box_border(t, o, cell, status);
    const double tol = 0.25 * fmin(cell[0], cell[1]);
    /* the loops serve the borders only: the cache's own, no copy in the frame's geometry */
    const sw__fr_border_entry *e = sw__fr_border_entry_get(t->env, o->face, tol);
    if (e) {
        sw__fr_border_entry_count(t, e);
        return sw__fr_border_entry_ribbons(t, o, e, cell, NULL, 0, status);
    }
    int64_t idx = -1;
    sw_result r = sw__fr_face_loops(t, o->face, tol, &idx, status);
    return r == SW_OK ? sw__fr_loop_borders(t, o, idx, cell, status) : r;
}

sw_result sw__fr_tess_static(sw__fr_tess *t, const sw__fr_visible *vis,
                             const sw__fr_static_pick *pick, sw_status *status)
{
    const sw__fr_instance *vi = &vis->instances[pick->instance];
    const sw_lod_static_instances *ins = sw_lod_static_set_instances(t->env->statics);
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(ins->bvh, vi->item, &view);
    const sw_sg_bvh_item_view *it = &view;
    const sw_lod_static_occ *oc0 = &ins->occs[ins->instances[it->face].first_occ];
    occurrence first;
    sw__fr_occurrence_init(&first, oc0->face, it->world, oc0->color);
    const sw_lod_static_level *lv = &pick->chain->levels[pick->level];
    const uint32_t unit = ins->instances[it->face].unit;
    sw_result r = !t->env->ctx->resident_off && pick->level < SW__GPU_RESIDENT_LEVELS
                      ? resident_level(t, &first, unit, lv, pick->level, status)
                      : append_level(t, &first, lv, pick->level, status);
    t->st->static_units_drawn++;
    t->st->static_levels_used |= 1u << (pick->level < 31 ? pick->level : 31);
    for (size_t k = vi->first_face; k < vi->first_face + vi->n_faces && r == SW_OK; ++k) {
        occurrence o = vis->unit_faces.occ[k];
        if (t->env->lod_colors)
            sw__fr_lod_color(-1, o.color); /* borders as the per-frame path colours its faces */
        r = face_borders(t, &o, pick->extent_px, status);
        t->st->static_faces++;
        t->st->faces_drawn++;
    }
    return r;
}

/* ---- cluster proxies (lod/static/sw_lod_proxy.h) -----------------------------------------------
 * A proxy is drawn as it is: in the world (its positions relative to its centre), each part a
 * draw in its colour, no fat border. Its bound holds both ways within the tolerance the cut chose
 * it for, as a static level's does, so a crack between it and a neighbour drawn otherwise lies
 * within the neighbour's fat borders (that neighbour is a static or per-frame face, and borders
 * every face it draws); the clustering welds what lies inside one proxy across its cells. */
static sw_result proxy_part(sw__fr_tess *t, const sw_lod_proxy *p, uint32_t k, sw_status *status)
{
    const sw_lod_static_level *lv = &p->parts[k];
    occurrence o;
    const double world[12] = {1, 0, 0, p->centre[0], 0, 1, 0, p->centre[1], 0, 0, 1, p->centre[2]};
    sw__fr_occurrence_init(&o, 0, world, p->colors[k]);
    if (t->env->lod_colors)
        sw__fr_lod_color(SW__FR_PROXY_COLOR, o.color);
    t->st->proxy_triangles += lv->n_triangles;
    if (t->env->ctx->resident_off) {
        const sw__fr_triangles tr = {.positions = lv->positions,
                                     .normals_f = lv->normals,
                                     .normal_matrix = {1, 0, 0, 0, 1, 0, 0, 0, 1},
                                     .n_vertices = lv->n_vertices,
                                     .n_triangles = lv->n_triangles,
                                     .triangles = lv->triangles};
        return sw__fr_append_triangles(t, &o, &tr, status);
    }
    sw__fr_geometry *g = t->geo;
    if (g->n_resident == g->cap_resident &&
        !sw__grow((void **)&g->resident, &g->cap_resident, g->n_resident + 1, sizeof *g->resident))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "proxies: out of memory");
    sw__gpu_resident_draw *d = &g->resident[g->n_resident++];
    memset(d, 0, sizeof *d);
    d->level = lv;
    /* numbered after the units: one table keys both */
    d->unit = sw_lod_static_set_unit_count(t->env->statics) + p->key + k;
    d->index = 0;
    for (int r = 0; r < 3; ++r) {
        d->off[r] = (float)(p->centre[r] - t->env->view.eye[r]);
        d->rot[4 * r] = 1.0f;
    }
    memcpy(d->color, o.color, sizeof d->color);
    d->lines = p->lines[k];
    d->n_lines = p->n_lines[k];
    d->draw_lines = !t->env->ctx->crack_fill_off; /* the proxies' crack fill */
    g->resident_triangles += lv->n_triangles;
    return SW_OK;
}

sw_result sw__fr_tess_proxies(sw__fr_tess *t, const sw__fr_visible *vis, sw_status *status)
{
    sw_result r = SW_OK;
    for (size_t i = 0; i < vis->n_proxies && r == SW_OK; ++i) {
        const sw_lod_proxy *p = sw_lod_static_set_proxy(t->env->statics, vis->proxies[i]);
        for (uint32_t k = 0; k < p->n_parts && r == SW_OK; ++k)
            r = proxy_part(t, p, k, status);
        t->st->proxies_drawn++;
        t->st->proxy_instances += p->instances;
        t->st->proxy_faces += p->faces;
        t->st->faces_drawn += p->faces;
    }
    return r;
}

/* The merge of Kumar et al. 1997 with the per-frame path: per visible unit (a super-surface of
 * whole faces, lod/sw_lod_static_set.h) and instance, the static LOD level whose declared ε_k meets
 * the object-space tolerance its nearest point needs, else the faces' own per-frame path (the
 * trim-texture tessellation of their hierarchies). The visible instances, their class and the
 * back-facing ones come from the set's BVH of unit instances (Kumar §4.4; the section "the
 * unit-instance BVH" below), which replaces the faces' BVH in frames with static LODs.
 *
 * The tolerance. A displacement d of a point at depth z (along the view axis) and off-axis
 * tangents (t_x, t_y) moves its image by at most focal_px |d| sqrt(1 + t_x^2 + t_y^2) / z pixels
 * (the projection's Jacobian [[1, 0, -t_x], [0, 1, -t_y]] f / z has that spectral norm). Every
 * visible point of the unit has z >= the nearest depth of its world box (clamped by the near
 * plane) and tangents within the frustum's corner, so a level within
 *     ε_world = ε_img z_min / (focal_px sqrt(1 + tan_corner^2))
 * of the exact surface is within ε_img pixels wherever it shows; in the faces' object space that
 * is ε_world / s, s the bound of the instance transform's stretch the hierarchy path uses too
 * (sw__fr_stretch_bound: 1 for a rigid one). Kumar §4.4 measures the distance to the box's centre
 * ("the distance of the super-surface from the viewer"): it is no bound for a large unit seen
 * from close by, so we take the box's nearest depth.
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
#include "frame_internal.h"
#include "sw_hooks.h"
#include "sw_lod_static_set.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Fat-border sampling of a statically drawn face: its uv box cut into cells of about
 * STATIC_BORDER_PX pixels of its unit's screen extent, between 2 and 32 per side. A chord over
 * 4 px of a curve of radius r px strays 2 / r px from it: within the ribbon's quarter width at
 * ε_img = 0.5 for r >= 8 px (tighter turns are features of a few pixels). Not rigorous between
 * samples, as gpu/crack_fill.c says of its own sampling; cost now follows the screen size. */
enum { STATIC_BORDER_MIN_CELLS = 2, STATIC_BORDER_MAX_CELLS = 32 };
static const double k_border_px = 4.0;

/* Colours of LOD colouring: static levels fine -> coarse, then the per-frame path. */
static const float k_level_colors[6][4] = {
    {0.20f, 0.45f, 0.90f, 1.0f}, {0.15f, 0.70f, 0.70f, 1.0f}, {0.30f, 0.75f, 0.30f, 1.0f},
    {0.80f, 0.75f, 0.20f, 1.0f}, {0.90f, 0.50f, 0.15f, 1.0f}, {0.85f, 0.25f, 0.55f, 1.0f},
};
static const float k_dynamic_color[4] = {0.75f, 0.75f, 0.78f, 1.0f};

void sw__fr_lod_color(int32_t level, float out[4])
{
    const float *c = level < 0 ? k_dynamic_color : k_level_colors[level > 5 ? 5 : level];
    memcpy(out, c, 4 * sizeof *out);
}

/* Eye-relative world box of the unit's object box under the occurrence's transform. */
static void unit_eye_box(const frame *f, const double obj[6], const double m[12], double out[6])
{
    sw__fr_box_empty(out);
    for (int c = 0; c < 8; ++c) {
        const double h[4] = {obj[(c & 1) ? 3 : 0], obj[(c & 2) ? 4 : 1], obj[(c & 4) ? 5 : 2], 1.0};
        double w[4];
        sw__fr_xform_h(m, f->view.eye, h, w);
        sw__fr_box_add(out, w);
    }
}

/* The object-space tolerance the unit needs under this occurrence (see the top of the file),
 * and (extent_px) a bound of its size on screen. */
static double unit_tolerance(const frame *f, const sw_lod_static_unit *un, const double m[12],
                             double *extent_px)
{
    double eb[6];
    unit_eye_box(f, un->box, m, eb);
    const double z = sw__gpu_view_box_depth(&f->view, eb);
    const double t = hypot(f->view.tan_x, f->view.tan_y);
    const double diag = sqrt((eb[3] - eb[0]) * (eb[3] - eb[0]) + (eb[4] - eb[1]) * (eb[4] - eb[1]) +
                             (eb[5] - eb[2]) * (eb[5] - eb[2]));
    *extent_px = diag * f->view.focal_px * sqrt(1.0 + t * t) / z;
    return f->eps_px * z / (f->view.focal_px * sqrt(1.0 + t * t)) / sw__fr_stretch_bound(m);
}

/* A static level is drawn only when it has at most this many triangles per Bézier patch: its
 * vertices are sent every frame, while the per-frame path evaluates each patch's grid in the
 * vertex shader from 16 control points, so a fine static level (a rigorous level 0 has 100-500
 * per patch on the sample models) costs more than the patches it replaces; the per-frame
 * path drew ~40 per patch on the 64-CrankArm grid's orbit. Kumar §4 meant static LODs for the far
 * field, where few triangles do. */
static const double k_static_max_tri_per_patch = 24.0;

/* Coarsest level within tol, -1 when none. */
static int32_t level_for(const sw_lod_static_chain *c, double tol)
{
    for (int32_t k = c->n_levels - 1; k >= 0; --k)
        if (c->levels[k].eps <= tol && c->levels[k].n_triangles > 0)
            return k;
    return -1;
}

/* The level to draw for tol: the coarsest within it, if cheap enough (see above). */
static int32_t level_to_draw(const sw_lod_static_chain *c, double tol)
{
    const int32_t k = level_for(c, tol);
    if (k < 0 || c->levels[k].n_triangles > k_static_max_tri_per_patch * c->n_patches)
        return -1;
    return k;
}

/* The chain to use, asked for when missing: walkthrough frames only queue the build (drawn by
 * the per-frame path meanwhile), converged frames wait for it. */
static const sw_lod_static_chain *unit_chain(frame *f, uint32_t unit)
{
    sw_lod_static_set *set = f->statics;
    const sw_lod_static_chain *c = sw_lod_static_set_get(set, unit);
    if (c)
        return c;
    if (sw_lod_static_set_state(set, unit) != SW_LOD_STATIC_EMPTY &&
        sw_lod_static_set_state(set, unit) != SW_LOD_STATIC_QUEUED)
        return NULL;
    if (f->walkthrough) {
        if (sw_lod_static_set_state(set, unit) == SW_LOD_STATIC_EMPTY)
            f->st.static_requests++;
        sw_lod_static_set_request(set, unit, SW_TH_PRIORITY_BACKGROUND);
        return NULL;
    }
    f->st.static_waits++;
    sw_lod_static_set_wait(set, unit);
    return sw_lod_static_set_get(set, unit);
}

/* The level a unit is drawn at under one occurrence, -1 for the per-frame path. */
static int32_t choose_level(frame *f, uint32_t unit, const double m[12],
                            const sw_lod_static_chain **chain, double *extent_px)
{
    const sw_lod_static_unit *un = sw_lod_static_set_unit(f->statics, unit);
    *chain = NULL;
    const double tol = unit_tolerance(f, un, m, extent_px);
    if (f->static_force > 0) {
        /* tests: neighbours at different levels, each within the view's tolerance, and beside
         * the per-frame path: unit i takes choice (i + k) mod (valid levels + 1) */
        const sw_lod_static_chain *c = unit_chain(f, unit);
        if (!c)
            return -1;
        const uint32_t n_valid = (uint32_t)(level_for(c, tol) + 1);
        const uint32_t k = (unit + (uint32_t)f->static_force) % (n_valid + 1);
        *chain = c;
        return k == n_valid ? -1 : (int32_t)k;
    }
    if (un->delta > tol)
        return -1; /* not even level 0 would do: do not build it for this view */
    const sw_lod_static_chain *c = unit_chain(f, unit);
    if (!c)
        return -1;
    *chain = c;
    return level_to_draw(c, tol);
}

/* Appends the level's triangles, transformed to eye-relative world space, as one draw. */
static sw_result append_level(frame *f, const occurrence *o, const sw_lod_static_level *lv,
                              int32_t level, sw_status *status)
{
    const double *m = o->world;
    /* rigid and similarity transforms keep normals along M n; shading is two-sided */
    sw__fr_triangles t = {.positions = lv->positions,
                          .normals_f = lv->normals,
                          .normal_matrix = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]},
                          .n_vertices = lv->n_vertices,
                          .n_triangles = lv->n_triangles,
                          .triangles = lv->triangles};
    occurrence shown = *o;
    if (f->lod_colors)
        sw__fr_lod_color(level, shown.color);
    sw_result r = sw__fr_append_triangles(f, &shown, &t, status);
    f->st.static_triangles += lv->n_triangles;
    return r;
}

/* The fat borders of one statically drawn face occurrence (see the top of the file). */
static sw_result face_borders(frame *f, const occurrence *o, double extent_px, sw_status *status)
{
    if (f->ctx->crack_fill_off)
        return SW_OK;
    const sw_sg_face_rec *rec = &f->sv->faces[o->face];
    const double *ub = rec->uv_box;
    const double cells =
        fmin(fmax(ceil(extent_px / k_border_px), STATIC_BORDER_MIN_CELLS), STATIC_BORDER_MAX_CELLS);
    const double cell[2] = {(ub[1] - ub[0]) / cells, (ub[3] - ub[2]) / cells};
    if (!((rec->flags & SW_SG_FACE_TRIMMED) && rec->n_loops > 0)) {
        const double box_loop[8] = {ub[0], ub[2], ub[1], ub[2], ub[1], ub[3], ub[0], ub[3]};
        return sw__fr_fat_border(f, o, box_loop, 4, 1, cell, NULL, 0, status);
    }
    int64_t idx = -1;
    sw_result r = sw__fr_face_loops(f, o->face, 0.25 * fmin(cell[0], cell[1]), &idx, status);
    for (uint32_t k = 0; r == SW_OK && k < f->loops[idx].n; ++k) {
        const face_loops *fl = &f->loops[idx];
        r = sw__fr_fat_border(f, o, fl->loops[k].uv, fl->loops[k].count,
                              sw__fr_left_is_inside(fl->loops, fl->n, k), cell, NULL, 0, status);
    }
    return r;
}

/* ---- the unit-instance BVH (Kumar §4.4) ------------------------------------------------------
 * With static LODs the frame culls the set's BVH whose leaves are unit instances
 * (lod/sw_lod_static_set.h: the face occurrences grouped by (unit, transform) once, when the set
 * was made), not the faces' BVH: an instance is what gets a level, so its classification, its
 * back-patch test and its level are decided once, at its leaf. A visible instance is then drawn
 * at a static level, or hands its face occurrences to the per-frame path. Partly visible, each of
 * them is classified against the frustum by its own box (the box and test of the faces' BVH, so
 * the per-frame path gets the faces it got from that BVH and asks no hierarchy for the others).
 * Wholly inside, none is tested: each face's drawn surface lies in the unit's box, so inside the
 * frustum, and the face's control-net box holds that surface, so no plane can have the box wholly
 * behind it — the test could only answer "not outside". */

typedef struct instance_taker {
    frame *f;
    const sw_lod_static_instances *in;
    const sw_lod_face_cones *fc; /* NULL: no back-patch culling */
    sw_sg_frustum fr;
    double **boxes;
    size_t cap_boxes;
    uint64_t occs_seen; /* face occurrences of the instances reported */
    sw_result r;
    sw_status *status;
} instance_taker;

/* Kumar §4.4 back-patch culling of a whole instance: the unit's outward cone in the world faces
 * away from every view direction into the instance's box (sound for an eye outside the solids, as
 * the face test is; the cone is the full one unless the unit is part of a closed shell). */
static int instance_back_facing(const frame *f, const sw_lod_static_unit *un,
                                const sw_sg_bvh_item *it)
{
    sw_lod_cone w;
    if (!sw_lod_cone_to_world(&un->cone, it->world, &w))
        return 0;
    double eb[6];
    for (int k = 0; k < 3; ++k) {
        eb[k] = it->box[k] - f->view.eye[k];
        eb[3 + k] = it->box[3 + k] - f->view.eye[k];
    }
    return sw_lod_cone_back_facing(&w, eb);
}

/* Face occurrence k of an instance: its occurrence and world box; 0 when the instance is partly
 * visible and the face's box is outside the frustum. */
static int instance_face(const instance_taker *t, const sw_lod_static_instance *in,
                         const sw_sg_bvh_item *it, uint32_t k, sw_sg_cull_class cls, occurrence *o,
                         double world_box[6])
{
    const sw_lod_static_occ *oc = &t->in->occs[in->first_occ + k];
    sw_sg_box_transform(it->world, t->in->face_boxes + 6 * (size_t)oc->face, world_box);
    if (cls != SW_SG_CULL_INSIDE && sw_sg_frustum_classify(&t->fr, world_box) == SW_SG_CULL_OUTSIDE)
        return 0;
    sw__fr_occurrence_init(o, oc->face, it->world, oc->color);
    return 1;
}

/* The per-frame path's share of a visible instance: its visible face occurrences. */
static sw_result hand_faces(instance_taker *t, const sw_lod_static_instance *in,
                            const sw_sg_bvh_item *it, sw_sg_cull_class cls)
{
    frame *f = t->f;
    for (uint32_t k = 0; k < in->n_occ; ++k) {
        occurrence o;
        double wb[6];
        if (!instance_face(t, in, it, k, cls, &o, wb)) {
            f->st.faces_culled++;
            continue;
        }
        const sw_lod_static_occ *oc = &t->in->occs[in->first_occ + k];
        if (!sw__fr_take_occurrence(f, oc->face, it->world, oc->color, wb, t->boxes, &t->cap_boxes))
            return sw__fail(t->status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    }
    return SW_OK;
}

enum { FACE_OUTSIDE = 0, FACE_BACK = 1, FACE_SHOWN = 2 };

/* Whether face occurrence k of an instance is outside the frustum (only tested when the instance
 * is partly visible), back-facing on its own (with cones), or shown; o is set unless outside. */
static int face_shown(const instance_taker *t, const sw_lod_static_instance *in,
                      const sw_sg_bvh_item *it, uint32_t k, sw_sg_cull_class cls, occurrence *o)
{
    double wb[6], eb[6];
    if (!instance_face(t, in, it, k, cls, o, wb))
        return FACE_OUTSIDE;
    for (int a = 0; a < 3; ++a) {
        eb[a] = wb[a] - t->f->view.eye[a];
        eb[3 + a] = wb[3 + a] - t->f->view.eye[a];
    }
    return t->fc && sw__fr_face_back_facing(t->fc, o, eb) ? FACE_BACK : FACE_SHOWN;
}

/* Culls an instance none of whose faces is shown (the faces' BVH and back-patch test would have
 * dropped them all, and with them the instance: no level is chosen, asked for or drawn). */
static int culled_by_faces(instance_taker *t, const sw_lod_static_instance *in,
                           const sw_sg_bvh_item *it, sw_sg_cull_class cls)
{
    occurrence o;
    for (uint32_t k = 0; k < in->n_occ; ++k)
        if (face_shown(t, in, it, k, cls, &o) == FACE_SHOWN)
            return 0;
    for (uint32_t k = 0; k < in->n_occ; ++k) {
        t->f->st.faces_backculled += face_shown(t, in, it, k, cls, &o) == FACE_BACK;
        t->f->st.faces_culled++;
    }
    return 1;
}

/* A visible instance drawn at a static level: the level once, and the fat borders of its faces
 * that are shown (those the per-frame path would draw). */
static sw_result draw_static(instance_taker *t, const sw_lod_static_instance *in,
                             const sw_sg_bvh_item *it, sw_sg_cull_class cls,
                             const sw_lod_static_chain *chain, int32_t level, double extent_px)
{
    frame *f = t->f;
    occurrence first;
    sw__fr_occurrence_init(&first, t->in->occs[in->first_occ].face, it->world,
                           t->in->occs[in->first_occ].color);
    sw_result r = append_level(f, &first, &chain->levels[level], level, t->status);
    f->st.static_units_drawn++;
    f->st.static_levels_used |= 1u << (level < 31 ? level : 31);
    for (uint32_t k = 0; k < in->n_occ && r == SW_OK; ++k) {
        occurrence o;
        const int shown = face_shown(t, in, it, k, cls, &o);
        f->st.faces_backculled += shown == FACE_BACK;
        if (shown != FACE_SHOWN) {
            f->st.faces_culled++;
            continue;
        }
        if (f->lod_colors)
            sw__fr_lod_color(-1, o.color); /* borders as the per-frame path colours its faces */
        r = face_borders(f, &o, extent_px, t->status);
        f->st.static_faces++;
        f->st.faces_drawn++;
    }
    return r;
}

/* One visible instance (sw_sg_bvh_cull's callback): back-culled, drawn statically, or handed to
 * the per-frame path. */
static int take_instance(void *ctx, uint32_t item, sw_sg_cull_class cls)
{
    instance_taker *t = ctx;
    frame *f = t->f;
    const sw_sg_bvh_item *it = &t->in->bvh->items[item];
    const sw_lod_static_instance *in = &t->in->instances[it->face];
    t->occs_seen += in->n_occ;
    int32_t level = -1;
    const sw_lod_static_chain *chain = NULL;
    double extent_px = 0.0;
    if (in->unit != SW_LOD_STATIC_NO_UNIT) {
        const sw_lod_static_unit *un = sw_lod_static_set_unit(f->statics, in->unit);
        if (t->fc && instance_back_facing(f, un, it)) {
            f->st.faces_backculled += in->n_occ;
            f->st.faces_culled += in->n_occ;
            return 0;
        }
        if (culled_by_faces(t, in, it, cls))
            return 0;
        level = choose_level(f, in->unit, it->world, &chain, &extent_px);
    }
    t->r = level >= 0 ? draw_static(t, in, it, cls, chain, level, extent_px)
                      : hand_faces(t, in, it, cls);
    return t->r != SW_OK;
}

sw_result sw__fr_static_collect(frame *f, const sw_lod_face_cones *fc, double **boxes,
                                sw_status *status)
{
    if (fc) {
        sw_result r = sw__fr_check_cones(f, fc, status);
        if (r != SW_OK)
            return r;
    }
    instance_taker t;
    memset(&t, 0, sizeof t);
    t.f = f;
    t.in = sw_lod_static_set_instances(f->statics);
    t.fc = fc;
    t.boxes = boxes;
    t.status = status;
    sw__fr_frustum(f, &t.fr);
    sw_sg_bvh_cull_stats cs;
    sw_sg_bvh_cull(t.in->bvh, &t.fr, take_instance, &t, &cs);
    sw__fr_bvh_stats(f, &cs);
    if (t.r == SW_OK)
        f->st.faces_culled += t.in->n_occs - t.occs_seen; /* in instances outside the frustum */
    return t.r;
}

/* The merge of Kumar et al. 1997 with the per-frame path: per visible unit (a super-surface of
 * whole faces, lod/sw_lod_static_set.h) and instance, the static LOD level whose declared ε_k meets
 * the object-space tolerance its nearest point needs, else the faces' own per-frame path (the
 * trim-texture tessellation of their hierarchies).
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
 * vertex shader from 16 control points, so a fine static level (level 0 within δ = 1e-3 of the
 * diagonal has ~160 per patch on CrankArm) costs more than the patches it replaces; the per-frame
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
    sw_result r = sw__gpu_mesh_reserve(&f->mesh, lv->n_vertices, 3 * (size_t)lv->n_triangles, status);
    if (r != SW_OK)
        return r;
    const size_t base = f->mesh.n_v, first = f->mesh.n_idx;
    const double *m = o->world;
    for (uint32_t i = 0; i < lv->n_vertices; ++i) {
        const double *p = lv->positions + 3 * i;
        const float *n = lv->normals + 3 * i;
        sw__gpu_vertex *v = &f->mesh.v[f->mesh.n_v++];
        for (int a = 0; a < 3; ++a) {
            v->pos[a] = (float)(m[4 * a] * p[0] + m[4 * a + 1] * p[1] + m[4 * a + 2] * p[2] +
                                (m[4 * a + 3] - f->view.eye[a]));
            /* rigid and similarity transforms keep normals along M n; shading is two-sided */
            v->nrm[a] = (float)(m[4 * a] * n[0] + m[4 * a + 1] * n[1] + m[4 * a + 2] * n[2]);
        }
        v->st[0] = v->st[1] = 0.0f;
    }
    for (uint32_t t = 0; t < 3 * lv->n_triangles; ++t)
        f->mesh.idx[f->mesh.n_idx++] = (uint32_t)base + lv->triangles[t];
    trim_need none = {0.0, 0.0};
    const double cell[2] = {0.0, 0.0};
    occurrence shown = *o;
    if (f->lod_colors)
        sw__fr_lod_color(level, shown.color);
    r = sw__fr_add_draw(f, &shown, first, 0, &none, cell, status);
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
    const double cells = fmin(fmax(ceil(extent_px / k_border_px), STATIC_BORDER_MIN_CELLS),
                              STATIC_BORDER_MAX_CELLS);
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

/* ---- (unit, instance) groups of the visible occurrences ------------------------------------- */

typedef struct group {
    uint32_t unit;
    int32_t level; /* -1: per-frame path */
    int drawn;     /* the level's triangles are in the frame */
    double extent_px; /* the unit's size on screen, bounded */
    double world[12];
    const sw_lod_static_chain *chain;
} group;

typedef struct group_map {
    group *slots;
    size_t cap; /* power of two */
} group_map;

static uint64_t group_hash(uint32_t unit, const double m[12])
{
    uint64_t h = 1469598103934665603ull ^ unit;
    const unsigned char *b = (const unsigned char *)m;
    for (size_t i = 0; i < 12 * sizeof *m; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/* The group of (unit, the transform of occurrence occ), made (level chosen) on first sight. The
 * transform is copied: the list is compacted while it is walked. */
static group *group_of(frame *f, group_map *gm, uint32_t unit, size_t occ)
{
    const double *m = f->occ[occ].world;
    for (size_t i = group_hash(unit, m) & (gm->cap - 1);; i = (i + 1) & (gm->cap - 1)) {
        group *g = &gm->slots[i];
        if (g->unit == SW_LOD_STATIC_NO_UNIT) {
            g->unit = unit;
            g->drawn = 0;
            memcpy(g->world, m, sizeof g->world);
            g->level = choose_level(f, unit, m, &g->chain, &g->extent_px);
            return g;
        }
        if (g->unit == unit && memcmp(g->world, m, sizeof g->world) == 0)
            return g;
    }
}

/* Draws the statically chosen occurrences and removes them (and their boxes) from the frame's
 * list, so the per-frame path asks no hierarchy for them. */
sw_result sw__fr_static_draw(frame *f, double *boxes, sw_status *status)
{
    if (!f->statics || f->exact || f->n_occ == 0)
        return SW_OK;
    group_map gm = {NULL, 16};
    while (gm.cap < 2 * f->n_occ)
        gm.cap *= 2;
    gm.slots = sw__malloc(gm.cap * sizeof *gm.slots);
    if (!gm.slots)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    for (size_t i = 0; i < gm.cap; ++i)
        gm.slots[i].unit = SW_LOD_STATIC_NO_UNIT;
    sw_result r = SW_OK;
    size_t kept = 0;
    for (size_t i = 0; i < f->n_occ && r == SW_OK; ++i) {
        const uint32_t unit = sw_lod_static_set_unit_of(f->statics, f->occ[i].face);
        group *g = unit == SW_LOD_STATIC_NO_UNIT ? NULL : group_of(f, &gm, unit, i);
        if (!g || g->level < 0) {
            if (kept != i) {
                f->occ[kept] = f->occ[i];
                memcpy(boxes + 6 * kept, boxes + 6 * i, 6 * sizeof *boxes);
            }
            kept++;
            continue;
        }
        if (!g->drawn) {
            r = append_level(f, &f->occ[i], &g->chain->levels[g->level], g->level, status);
            g->drawn = 1;
            f->st.static_units_drawn++;
            f->st.static_levels_used |= 1u << (g->level < 31 ? g->level : 31);
        }
        if (r == SW_OK)
            r = face_borders(f, &f->occ[i], g->extent_px, status);
        f->st.static_faces++;
        f->st.faces_drawn++;
    }
    sw__free(gm.slots);
    if (r == SW_OK)
        f->n_occ = kept;
    return r;
}

/* SPDX-License-Identifier: MIT */
/* The tessellate stage: the selection made into geometry the GPU draws — CPU grids and
 * triangles in the frame's mesh, vertex-shader patch records (Guthe et al. 2005 §4.2: rational
 * Bézier patches evaluated on predefined grids), one draw record per colour and trim lookup,
 * fat borders along drawn faces' boundaries (§7.1, crack_fill.c) and the trim textures the
 * trimmed draws need (made by the trim stage).
 *
 * Order: static levels (stage_tessellate_static.c), then the per-frame faces by their hierarchy
 * cut (stage_tessellate_hierarchy.c) or their own Bézier patches (stage_tessellate_direct.c),
 * then meshes (stage_tessellate_mesh.c). Grid densities come from one rigorous bound
 * (lod/bezier/sampling.c's sw_lod_screen_segments) over the grid classes' segment counts. */
#include "frame_stages.h"
#include "sw_crc32c.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void sw__fr_geometry_free(sw__fr_geometry *g)
{
    sw__fr_geometry_empty(g); /* the trim loops and outlines it owns */
    sw__free(g->shapes);
    sw__free(g->draws);
    sw__free(g->trims);
    sw__free(g->shares);
    sw__free(g->loops);
    sw__free(g->recs);
    sw__free(g->places);
    sw__free(g->cps);
    sw__free(g->pieces);
    sw__free(g->knots);
    sw__free(g->dcps);
    sw__free(g->resident);
    sw__gpu_edge_grids_free(&g->edges);
    sw__gpu_mesh_free(&g->mesh);
    memset(g, 0, sizeof *g);
}

void sw__fr_geometry_empty(sw__fr_geometry *g)
{
    for (size_t i = 0; i < g->n_loops; ++i) {
        for (uint32_t k = 0; k < g->loops[i].n; ++k)
            sw_sg_polyline_free(&g->loops[i].loops[k]);
        sw__free(g->loops[i].loops);
    }
    g->mesh.n_v = g->mesh.n_idx = 0;
    g->mesh.border_capped = 0;
    g->n_draws = g->n_trims = g->n_shares = g->n_loops = 0;
    g->n_recs = g->n_cps = g->n_pieces = g->n_knots = g->n_dcps = 0;
    g->gpu_vertices = 0.0;
    g->border_triangles = 0;
    g->n_resident = 0;
    g->resident_triangles = 0;
    sw__gpu_edge_grids_empty(&g->edges);
    sw__fr_shapes_empty(g);
}

void sw__fr_chunk_geometry_take(sw_gpu_context *ctx, sw__fr_geometry *dst)
{
    sw__fr_geometry *held = sw__gpu_stash_take(ctx, SW__GPU_STASH_CHUNK);
    if (!held) {
        memset(dst, 0, sizeof *dst);
        return;
    }
    *dst = *held;
    sw__free(held);
}

void sw__fr_chunk_geometry_give(sw_gpu_context *ctx, sw__fr_geometry *g)
{
    sw__fr_geometry *held = ctx ? sw__malloc(sizeof *held) : NULL;
    if (held) {
        sw__fr_geometry_empty(g);
        *held = *g;
        if (sw__gpu_stash_put(ctx, SW__GPU_STASH_CHUNK, held)) {
            memset(g, 0, sizeof *g);
            return;
        }
        sw__free(held);
    }
    sw__fr_geometry_free(g);
}

int sw__fr_face_trimmed(const sw__fr_env *env, uint32_t face)
{
    const sw_sg_face_rec *rec = &env->sv->faces[face];
    return (rec->flags & SW_SG_FACE_TRIMMED) && rec->n_loops > 0;
}

double sw__fr_normal_sign(const sw__fr_env *env, const occurrence *o)
{
    double sign = (env->sv->faces[o->face].flags & SW_SG_FACE_REVERSED) ? -1.0 : 1.0;
    return sw__fr_det3(o->world) < 0.0 ? -sign : sign;
}

sw_result sw__fr_check_budget(const sw__fr_tess *t, sw_status *status)
{
    if ((double)t->geo->mesh.n_v + t->geo->gpu_vertices > k_max_frame_vertices)
        return sw__fail(status, SW_ERR_LIMIT,
                        "frame needs more than %.0f grid vertices (error %g px too small for this "
                        "view?)",
                        k_max_frame_vertices, t->env->eps_px);
    return SW_OK;
}

sw_result sw__fr_add_draw(sw__fr_tess *t, const occurrence *o, size_t first_idx, int trimmed,
                          const trim_need *need, const double cell[2], sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    if (!sw__grow((void **)&g->draws, &g->cap_draws, g->n_draws + 1, sizeof *g->draws) ||
        (trimmed && !sw__grow((void **)&g->trims, &g->cap_trims, g->n_trims + 1, sizeof *g->trims)))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame draws: out of memory");
    sw__gpu_draw *d = &g->draws[g->n_draws];
    d->first_idx = first_idx;
    d->n_idx = g->mesh.n_idx - first_idx;
    memcpy(d->color, o->color, sizeof d->color);
    d->trim_entry = -1;
    d->edge_grid = -1;
    /* a face's CPU grids carry st over its uv box (fat borders: sw__fr_fat_border; triangle
     * meshes and static levels, st = 0: sw__fr_append_triangles) */
    memset(d->uv_map, 0, sizeof d->uv_map);
    if (o->face < t->env->sv->n_faces) {
        const double *ub = t->env->sv->faces[o->face].uv_box;
        const float uv_map[4] = {(float)ub[0], (float)ub[2], (float)(ub[1] - ub[0]),
                                 (float)(ub[3] - ub[2])};
        memcpy(d->uv_map, uv_map, sizeof uv_map);
    }
    if (trimmed) {
        pending_trim *p = &g->trims[g->n_trims++];
        memset(p, 0, sizeof *p);
        p->draw = g->n_draws;
        p->occ = *o;
        p->width = need->u;
        p->height = need->v;
        p->cell[0] = cell[0];
        p->cell[1] = cell[1];
        p->loops = -1;
        p->grid = -1;
    }
    g->n_draws++;
    return SW_OK;
}

/* Hands one drawn patch piece to the context's debug hook. */
void sw__fr_report_patch(const sw__fr_tess *t, const occurrence *o, const sw__gpu_patch *pt,
                         double s0, double s1, double t0, double t1, int32_t nu, int32_t nv,
                         int gpu, int trimmed)
{
    sw__gpu_drawn_patch d = {
        &t->env->view, o->face, o->world, pt->deg_u, pt->deg_v, pt->cpw, pt->u0, pt->u1,
        pt->v0,        pt->v1,  s0,       s1,        t0,        t1,      nu,     nv,
        gpu,           trimmed, pt->eps};
    t->env->ctx->patch_hook(t->env->ctx->patch_hook_user, &d);
}

/* Smallest grid class with at least n segments (n <= SW__GPU_GRID_MAX). */
static int32_t class_for(int32_t n)
{
    int32_t l = 0;
    while (sw__gpu_grid_segments[l] < n)
        ++l;
    return l;
}

/* Pieces a direction of n segments is cut into so that each fits the largest grid class, and the
 * class of a piece: at least n / pieces segments each, so the Filip bound still holds (§5.2). */
static void split_class(int32_t n, int32_t *pieces, int32_t *level)
{
    *pieces = (n + SW__GPU_GRID_MAX - 1) / SW__GPU_GRID_MAX;
    *level = class_for((n + *pieces - 1) / *pieces);
}

/* The largest |P| of homogeneous points over their weights. */
static double radius_of(const double *cpw, size_t n)
{
    double r = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double *p = cpw + 4 * i;
        r = fmax(r, sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) / fabs(p[3]));
    }
    return r;
}

double sw__fr_float_error_px(const sw__fr_env *env, const double *cpw, size_t n,
                             const double box[6])
{
    double r = radius_of(cpw, n);
    if (env->grids_resident)
        r *= 3.0; /* evaluated around a centre, then placed (frame_stages.h) */
    const double z = fmax(sw__gpu_view_box_depth(&env->view, box), env->view.near_plane);
    const double px = 16.0 * FLT_EPSILON * r * env->view.focal_px / z;
    return isfinite(px) ? px : INFINITY;
}

void sw__fr_screen_less(sw__fr_tess *t, double spent_px, sw_lod_screen_view *scr)
{
    const double eps = t->env->eps_px;
    *scr = t->env->screen;
    scr->eps_px = fmax(eps - spent_px, 0.25 * eps);
    const double excess_px = spent_px + scr->eps_px - eps;
    if (excess_px > 0.0) {
        t->st->bound_exceeded++;
        t->st->bound_excess_px = fmax(t->st->bound_excess_px, excess_px);
    }
}

int32_t sw__fr_class_segments(int32_t n)
{
    int32_t pieces, level;
    split_class(n, &pieces, &level);
    return pieces * sw__gpu_grid_segments[level];
}

/* Exact path: the face occurrence's knot vectors and eye-relative homogeneous control points
 * (double), appended once per occurrence. */
static sw_result exact_net(sw__fr_tess *t, const occurrence *o, sw_status *status)
{
    if (t->ex_occ == o)
        return SW_OK;
    sw__fr_geometry *g = t->geo;
    sw_sg_surface s;
    sw_sg_scene_face_surface(t->env->scene, o->face, &s);
    size_t nku = (size_t)s.n_u + (size_t)s.deg_u + 1, nkv = (size_t)s.n_v + (size_t)s.deg_v + 1;
    size_t ncp = (size_t)s.n_u * (size_t)s.n_v;
    if (g->n_knots + nku + nkv > UINT32_MAX || g->n_dcps + ncp > UINT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "face %u: exact evaluation buffers over 2^32",
                        o->face);
    if (!sw__grow((void **)&g->knots, &g->cap_knots, g->n_knots + nku + nkv, sizeof *g->knots) ||
        !sw__grow((void **)&g->dcps, &g->cap_dcps, 4 * (g->n_dcps + ncp), sizeof *g->dcps))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    sw__gpu_exact_piece *b = &t->ex_base;
    memset(b, 0, sizeof *b);
    b->ku = (uint32_t)g->n_knots;
    b->kv = (uint32_t)(g->n_knots + nku);
    b->cp = (uint32_t)g->n_dcps;
    b->stride = s.n_u;
    b->deg_u = s.deg_u;
    b->deg_v = s.deg_v;
    memcpy(g->knots + g->n_knots, s.knots_u, nku * sizeof *g->knots);
    memcpy(g->knots + g->n_knots + nku, s.knots_v, nkv * sizeof *g->knots);
    g->n_knots += nku + nkv;
    for (size_t i = 0; i < ncp; ++i)
        sw__fr_xform_h(o->world, t->env->view.eye, s.cpw + 4 * i, g->dcps + 4 * (g->n_dcps + i));
    g->n_dcps += ncp;
    t->ex_srf = s;
    t->ex_occ = o;
    return SW_OK;
}

/* Exact path: the piece (knot spans) of one Bézier patch of the current occurrence; its index
 * goes into the records' cp. */
static sw_result exact_piece(sw__fr_tess *t, const occurrence *o, const sw__gpu_patch *pt,
                             uint32_t *index, sw_status *status)
{
    sw_result r = exact_net(t, o, status);
    if (r != SW_OK)
        return r;
    sw__fr_geometry *g = t->geo;
    if (!sw__grow((void **)&g->pieces, &g->cap_pieces, g->n_pieces + 1, sizeof *g->pieces))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    const sw_sg_surface *s = &t->ex_srf;
    sw__gpu_exact_piece *q = &g->pieces[g->n_pieces];
    *q = t->ex_base;
    q->u0 = pt->u0;
    q->u1 = pt->u1;
    q->v0 = pt->v0;
    q->v1 = pt->v1;
    /* the midpoint lies inside the patch's span whatever the half-open convention */
    q->span_u = sw_sg_knots_find_span(s->knots_u, s->deg_u, s->n_u, 0.5 * (pt->u0 + pt->u1));
    q->span_v = sw_sg_knots_find_span(s->knots_v, s->deg_v, s->n_v, 0.5 * (pt->v0 + pt->v1));
    *index = (uint32_t)g->n_pieces++;
    return SW_OK;
}

/* The patch's control points around its centre (object space: x - w c, w), in float, when its
 * grid may be kept: a patch larger than its distance from the eye (s R_local > R, s the
 * occurrence's stretch) is not (the float bound of sw__fr_float_error_px). 0: not kept. */
static int local_points(const occurrence *o, const sw__gpu_patch *pt, size_t n, float *out)
{
    if (!pt->cpo || n > 16)
        return 0;
    double local[64] = {0};
    for (size_t i = 0; i < n; ++i) {
        const double *p = pt->cpo + 4 * i;
        for (int k = 0; k < 3; ++k)
            local[4 * i + k] = p[k] - p[3] * pt->centre[k];
        local[4 * i + 3] = p[3];
    }
    if (!(sw_sg_stretch_bound(o->world) * radius_of(local, n) <= radius_of(pt->cpw, n)))
        return 0;
    for (size_t i = 0; i < 4 * n; ++i)
        out[i] = (float)local[i];
    return 1;
}

/* The placement of a kept grid of occurrence o: its 3 x 3 rows with the centre's eye-relative
 * position (double, then float) and the cofactor rows (normals of any affine map). */
static void place_of(const sw__fr_env *env, const occurrence *o, const double centre[3],
                     sw__gpu_grid_place *pl)
{
    const double *m = o->world; /* rows: m[4 r + c], translation in m[4 r + 3] */
    const double at[4] = {centre[0], centre[1], centre[2], 1.0};
    double off[4];
    sw__fr_xform_h(m, env->view.eye, at, off);
    double cof[9];
    sw__fr_cofactor3(m, cof);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            pl->rot[4 * r + c] = (float)m[4 * r + c];
            pl->cof[4 * r + c] = (float)cof[3 * r + c];
        }
        pl->rot[4 * r + 3] = (float)off[r];
        pl->cof[4 * r + 3] = 0.0f;
    }
}

/* Appends the control points of a visible patch (float, eye-relative homogeneous) and one record
 * per piece of its sampled domain (§4.2). Pieces share their edge parameters bit for bit. */
sw_result sw__fr_gpu_patch(sw__fr_tess *t, const occurrence *o, const sw__gpu_patch *pt,
                           const double ub[4], double sign, int32_t draw, int trimmed,
                           sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    const int exact = t->env->exact;
    size_t n_cp = exact ? 0 : (size_t)(pt->deg_u + 1) * (size_t)(pt->deg_v + 1);
    uint32_t cp_index = (uint32_t)g->n_cps;
    if (exact) {
        sw_result r = exact_piece(t, o, pt, &cp_index, status);
        if (r != SW_OK)
            return r;
    }
    int32_t ku, kv, lu, lv;
    split_class(pt->nu, &ku, &lu);
    split_class(pt->nv, &kv, &lv);
    size_t n_rec = (size_t)ku * (size_t)kv;
    if (!sw__grow((void **)&g->cps, &g->cap_cps, 4 * (g->n_cps + n_cp), sizeof *g->cps) ||
        !sw__grow((void **)&g->recs, &g->cap_recs, g->n_recs + n_rec, sizeof *g->recs) ||
        !sw__grow((void **)&g->places, &g->cap_places, g->n_recs + n_rec, sizeof *g->places))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    float *cps = g->cps + 4 * g->n_cps;
    sw__gpu_grid_place place;
    memset(&place, 0, sizeof place);
    /* env->grids_resident is off on the exact path */
    place.resident = t->env->grids_resident && local_points(o, pt, n_cp, cps);
    if (place.resident) { /* the key of its grid: what it is evaluated from (st: per piece) */
        place_of(t->env, o, pt->centre, &place);
        const int32_t deg[2] = {pt->deg_u, pt->deg_v};
        place.hash = sw__crc32c(sw__crc32c(0, cps, 4 * n_cp * sizeof *cps), deg, sizeof deg);
    } else
        for (size_t i = 0; i < 4 * n_cp; ++i)
            cps[i] = (float)pt->cpw[i];
    double bw = ub[1] - ub[0], bh = ub[3] - ub[2];
    float map[4] = {(float)((pt->u0 - ub[0]) / bw), (float)((pt->u1 - pt->u0) / bw),
                    (float)((pt->v0 - ub[2]) / bh), (float)((pt->v1 - pt->v0) / bh)};
    const float uv_map[4] = {(float)pt->u0, (float)pt->v0, (float)(pt->u1 - pt->u0),
                             (float)(pt->v1 - pt->v0)};
    for (int32_t b = 0; b < kv; ++b) {
        for (int32_t a = 0; a < ku; ++a) {
            sw__gpu_patch_rec *rec = &g->recs[g->n_recs++];
            memset(rec, 0, sizeof *rec);
            rec->st[0] = (float)(pt->s0 + (pt->s1 - pt->s0) * a / ku);
            rec->st[1] = (float)(a + 1 == ku ? pt->s1 : pt->s0 + (pt->s1 - pt->s0) * (a + 1) / ku);
            rec->st[2] = (float)(pt->t0 + (pt->t1 - pt->t0) * b / kv);
            rec->st[3] = (float)(b + 1 == kv ? pt->t1 : pt->t0 + (pt->t1 - pt->t0) * (b + 1) / kv);
            memcpy(rec->trim_map, map, sizeof map);
            rec->cp = cp_index;
            rec->deg_u = pt->deg_u;
            rec->deg_v = pt->deg_v;
            rec->normal_sign = (float)sign;
            rec->draw = draw;
            rec->level_u = lu;
            rec->level_v = lv;
            memcpy(rec->uv_map, uv_map, sizeof uv_map);
            sw__gpu_grid_place *pl = &g->places[g->n_recs - 1];
            *pl = place;
            if (place.resident)
                pl->hash = sw__crc32c(place.hash, rec->st, sizeof rec->st);
            if (t->env->ctx->patch_hook)
                sw__fr_report_patch(t, o, pt, rec->st[0], rec->st[1], rec->st[2], rec->st[3],
                                    sw__gpu_grid_segments[lu], sw__gpu_grid_segments[lv], 1,
                                    trimmed);
        }
    }
    g->n_cps += n_cp;
    int32_t su = sw__gpu_grid_segments[lu], sv = sw__gpu_grid_segments[lv];
    g->gpu_vertices += (double)n_rec * (double)(su + 1) * (double)(sv + 1);
    t->st->triangles += (uint64_t)n_rec * 2u * (uint64_t)su * (uint64_t)sv;
    return SW_OK;
}

/* The ribbon appended to the mesh from index `first` as its own draw (none when empty). */
static sw_result ribbon_draw(sw__fr_tess *t, const occurrence *o, size_t first, uint64_t capped,
                             uint64_t away, const double cell[2], const double *st_box,
                             const double *st_rect, size_t share, sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    t->st->border_quads_away += g->mesh.border_quads_away - away;
    /* sampled coarser than its cells (the view's sample budget): it may leave a crack open */
    t->st->borders_capped += g->mesh.border_capped - capped;
    t->st->bound_exceeded += g->mesh.border_capped - capped;
    if (g->mesh.n_idx == first)
        return SW_OK;
    trim_need none = {0.0, 0.0};
    size_t draw = g->n_draws;
    sw_result r = sw__fr_add_draw(t, o, first, 0, &none, cell, status);
    if (r == SW_OK) {
        const double *b = st_rect;
        const float uv_map[4] = {(float)b[0], (float)b[2], (float)(b[1] - b[0]),
                                 (float)(b[3] - b[2])};
        memcpy(g->draws[draw].uv_map, uv_map, sizeof uv_map);
    }
    t->st->triangles += (g->mesh.n_idx - first) / 3;
    g->border_triangles += (g->mesh.n_idx - first) / 3;
    if (r == SW_OK && st_box) {
        if (!sw__grow((void **)&g->shares, &g->cap_shares, 2 * (g->n_shares + 1),
                      sizeof *g->shares))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame draws: out of memory");
        g->shares[2 * g->n_shares] = draw;
        g->shares[2 * g->n_shares + 1] = share;
        g->n_shares++;
    }
    return r;
}

/* The side of occurrence o's face the eye sees, when the frame may leave out the back of its
 * ribbons: a face bounding a closed shell, in a frame whose eye is found outside the solids (the
 * premise of back-patch culling). NULL otherwise. */
static const sw__gpu_ribbon_facing *facing_of(const sw__fr_tess *t, const occurrence *o,
                                              sw__gpu_ribbon_facing *f)
{
    const uint32_t flags = t->env->sv->faces[o->face].flags;
    if (t->env->eye_shells != SW__FR_EYE_OUTSIDE || t->env->ctx->back_ribbons_kept ||
        !(flags & SW_SG_FACE_CLOSED_SHELL) ||
        !sw_sg_to_local(o->world, t->env->view.eye, NULL, f->eye, NULL))
        return NULL;
    f->outward = flags & SW_SG_FACE_REVERSED ? -1.0 : 1.0;
    return f;
}

/* §7.1: a fat border along one closed uv loop of a drawn face, as its own draw. */
sw_result sw__fr_fat_border(sw__fr_tess *t, const occurrence *o, const double *uv, size_t n,
                            int left_inside, const double cell[2], const double *st_box,
                            size_t share, sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    sw_sg_surface srf;
    sw_sg_scene_face_surface(t->env->scene, o->face, &srf);
    const size_t first = g->mesh.n_idx;
    const uint64_t capped = g->mesh.border_capped, away = g->mesh.border_quads_away;
    /* st over the face's uv box when the ribbon is drawn untrimmed: no lookup reads it, but the
     * shading's uv (u_uv_map) does */
    const double *st_rect = st_box ? st_box : t->env->sv->faces[o->face].uv_box;
    sw__gpu_ribbon_facing f;
    sw_result r = sw__gpu_fat_border(
        &t->env->view, &srf, o->world, uv, n, left_inside, cell[0], cell[1], 2.0 * t->env->eps_px,
        st_rect, !t->env->ctx->border_affine_off, facing_of(t, o, &f), &g->mesh, status);
    return r == SW_OK ? ribbon_draw(t, o, first, capped, away, cell, st_box, st_rect, share, status)
                      : r;
}

sw_result sw__fr_placed_border(sw__fr_tess *t, const occurrence *o, const sw__gpu_border_loop *bl,
                               const double cell[2], const double *st_box, size_t share,
                               sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    const size_t first = g->mesh.n_idx;
    const uint64_t capped = g->mesh.border_capped, away = g->mesh.border_quads_away;
    const double *st_rect = st_box ? st_box : t->env->sv->faces[o->face].uv_box;
    sw__gpu_ribbon_facing f;
    sw_result r = sw__gpu_fat_border_of(&t->env->view, o->world, bl, 2.0 * t->env->eps_px, st_rect,
                                        facing_of(t, o, &f), &g->mesh, status);
    return r == SW_OK ? ribbon_draw(t, o, first, capped, away, cell, st_box, st_rect, share, status)
                      : r;
}

/* The entry's loops copied into fl (the trim stage draws from them on the submitting thread,
 * after the cache may have moved on). */
static sw_result copy_loops(face_loops *fl, const sw__fr_border_entry *e, sw_status *status)
{
    uint32_t n = 0;
    const sw_sg_polyline *src = sw__fr_border_entry_loops(e, &n);
    for (; fl->n < n; ++fl->n) {
        sw_sg_polyline *d = &fl->loops[fl->n];
        *d = src[fl->n];
        d->uv = sw__malloc((src[fl->n].count ? src[fl->n].count : 1) * 2 * sizeof *d->uv);
        if (!d->uv)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", fl->face);
        memcpy(d->uv, src[fl->n].uv, src[fl->n].count * 2 * sizeof *d->uv);
    }
    return SW_OK;
}

/* A knot span or item narrower than this fraction of the face's trim box is a sliver: knots a
 * rounding apart, left by exporters and unit conversions (IGES copies and scaled B-reps of OCCT's
 * samples hold spans of 1e-8 and 7e-16 of the box). One grid segment spans it, so its cell says
 * nothing of how finely the face's loops must be flattened or its borders sampled; taken as the
 * face's cell it cut a loop into 3e9 border samples. */
#define SLIVER_FRACTION 1e-6

int sw__fr_sliver(double extent, double box_extent)
{
    return !(extent > SLIVER_FRACTION * box_extent);
}

size_t sw__fr_grid_cell(const sw__gpu_patch *pt, size_t n, const double ub[4], double cell[2])
{
    size_t visible = 0;
    cell[0] = cell[1] = INFINITY;
    for (size_t p = 0; p < n; ++p) {
        if (!pt[p].visible)
            continue;
        ++visible;
        double wu = (pt[p].u1 - pt[p].u0) * (pt[p].s1 - pt[p].s0);
        double wv = (pt[p].v1 - pt[p].v0) * (pt[p].t1 - pt[p].t0);
        if (!sw__fr_sliver(wu, ub[1] - ub[0]))
            cell[0] = fmin(cell[0], wu / pt[p].nu);
        if (!sw__fr_sliver(wv, ub[3] - ub[2]))
            cell[1] = fmin(cell[1], wv / pt[p].nv);
    }
    if (!(cell[0] < INFINITY) || !(cell[1] < INFINITY)) { /* slivers only */
        cell[0] = fmin(cell[0], ub[1] - ub[0]);
        cell[1] = fmin(cell[1], ub[3] - ub[2]);
    }
    return visible;
}

sw_result sw__fr_face_loops(sw__fr_tess *t, uint32_t face, double tol, int64_t *index,
                            sw_status *status)
{
    sw__fr_geometry *g = t->geo;
    const sw_sg_face_rec *rec = &t->env->sv->faces[face];
    if (!sw__grow((void **)&g->loops, &g->cap_loops, g->n_loops + 1, sizeof *g->loops))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", face);
    face_loops *fl = &g->loops[g->n_loops];
    fl->n = 0;
    fl->face = face;
    fl->tol = tol;
    fl->loops = sw__calloc(rec->n_loops ? rec->n_loops : 1, sizeof *fl->loops);
    if (!fl->loops)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", face);
    *index = (int64_t)g->n_loops++;
    const sw__fr_border_entry *e = sw__fr_border_entry_get(t->env, face, tol);
    if (e) {
        sw__fr_border_entry_count(t, e);
        return copy_loops(fl, e, status);
    }
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < rec->n_loops && r == SW_OK; ++k, ++fl->n) {
        r = sw_sg_trim_flatten_loop(t->env->scene, rec->first_loop + k, tol, MAX_TRIM_LOOP_VERTICES,
                                    &fl->loops[k], status);
        if (r == SW_OK && (fl->loops[k].below_floor || fl->loops[k].depth_capped)) {
            t->st->trim_loops_floored++; /* farther than tol from the exact loop somewhere */
            t->st->bound_exceeded++;
        }
    }
    return r;
}

sw_result sw__fr_loop_borders(sw__fr_tess *t, const occurrence *o, int64_t loops,
                              const double cell[2], sw_status *status)
{
    const face_loops *fl = &t->geo->loops[loops];
    const sw__fr_border_entry *e = sw__fr_border_entry_get(t->env, fl->face, fl->tol);
    if (e)
        return sw__fr_border_entry_ribbons(t, o, e, cell, NULL, 0, status);
    sw_result r = SW_OK;
    for (uint32_t k = 0; r == SW_OK && !t->env->ctx->crack_fill_off && k < fl->n; ++k)
        r = sw__fr_fat_border(t, o, fl->loops[k].uv, fl->loops[k].count,
                              sw__fr_left_is_inside(fl->loops, fl->n, k), cell, NULL, 0, status);
    return r;
}

sw_result sw__fr_rect_border(sw__fr_tess *t, const occurrence *o, const double rect[4],
                             const double cell[2], const double *st_box, size_t share,
                             sw_status *status)
{
    const sw__fr_border_entry *e = sw__fr_border_rect_get(t->env, o->face, rect);
    if (e)
        return sw__fr_border_entry_ribbons(t, o, e, cell, st_box, share, status);
    const double *b = rect;
    const double loop[8] = {b[0], b[2], b[1], b[2], b[1], b[3], b[0], b[3]};
    return sw__fr_fat_border(t, o, loop, 4, 1, cell, st_box, share, status);
}

sw_result sw__fr_box_border(sw__fr_tess *t, const occurrence *o, const double cell[2],
                            sw_status *status)
{
    return sw__fr_rect_border(t, o, t->env->sv->faces[o->face].uv_box, cell, NULL, 0, status);
}

sw_result sw__fr_tess_face(sw__fr_tess *t, const sw__fr_selection *sel, const sw__fr_face_pick *p,
                           sw_status *status)
{
    if (!p->hierarchy)
        return sw__fr_tess_direct(t, &p->occ, status);
    return sw__fr_tess_hierarchy(t, &p->occ, sel->items + p->first_item, p->n_items, status);
}

sw_result sw__fr_tessellate(const sw__fr_env *env, const sw__fr_visible *vis,
                            const sw__fr_selection *sel, sw__fr_geometry *geo,
                            sw_gpu_frame_stats *st, sw_status *status)
{
    sw__fr_tess t;
    memset(&t, 0, sizeof t);
    t.env = env;
    t.st = st;
    t.geo = geo;
    t.bez = sw__calloc(env->sv->n_faces ? env->sv->n_faces : 1, sizeof *t.bez);
    if (!t.bez)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame: out of memory");
    sw_result r = sw__fr_tess_picks(&t, vis, sel, status);
    if (r == SW_OK)
        r = sw__fr_tess_proxies(&t, vis, status);
    if (r == SW_OK)
        r = sw__fr_tess_meshes(&t, vis, status);
    for (uint32_t i = 0; i < env->sv->n_faces; ++i) {
        sw_sg_bezier_set *set = atomic_load_explicit(&t.bez[i], memory_order_relaxed);
        if (set) {
            sw_sg_bezier_set_free(set);
            sw__free(set);
        }
    }
    sw__free(t.bez);
    return r;
}

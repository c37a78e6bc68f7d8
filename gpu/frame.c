/* One converged frame of a scene (Guthe et al. 2005 §7, without the bicubic hierarchy in this
 * slice): traverse the scene, cull face occurrences and then their rational Bézier patches against
 * the view frustum by their control-net boxes, choose each patch's grid density so that its
 * triangles stay within ε_img on screen (§5.2 and §7 in one rigorous bound, lod/sampling.c's
 * sw_lod_screen_segments, over the grid classes' segment counts), evaluate the grids, add fat
 * borders along every drawn face's boundary to close cracks between faces (§7.1, crack_fill.c),
 * make one trim texture per trimmed face occurrence at a resolution from its on-screen size (§5.3),
 * rounded up to a power-of-two class, in the context's trim atlas (§4.4) by fan parity on the GPU
 * (§4), draw, read back.
 *
 * Phases are timed separately: tessellate (extraction, bounds, grids), trim (flattening and
 * texture generation, waited for), draw (upload and draw until glFinish), readback.
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_lod_face_cones.h"
#include "sw_lod_sampling.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "frame_internal.h"
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"

void sw__fr_occurrence_init(occurrence *o, uint32_t face, const double world[12],
                            const float color[4])
{
    o->face = face;
    memcpy(o->world, world, sizeof o->world);
    static const float k_default[4] = {0.72f, 0.72f, 0.76f, 1.0f};
    memcpy(o->color, color && color[3] >= 0.0f ? color : k_default, sizeof o->color);
}

static int collect(void *user, uint32_t face, const double world[12], const float color[4])
{
    frame *f = user;
    if (!sw__gpu_grow((void **)&f->occ, &f->cap_occ, f->n_occ + 1, sizeof *f->occ)) {
        f->oom = 1;
        return 1;
    }
    sw__fr_occurrence_init(&f->occ[f->n_occ++], face, world, color);
    return 0;
}

/* Homogeneous control point mapped to eye-relative world space: w x' = R (w x) + w (t - eye). */
void sw__fr_xform_h(const double m[12], const double eye[3], const double in[4], double out[4])
{
    for (int r = 0; r < 3; ++r)
        out[r] = m[4 * r] * in[0] + m[4 * r + 1] * in[1] + m[4 * r + 2] * in[2] +
                 in[3] * (m[4 * r + 3] - eye[r]);
    out[3] = in[3];
}

void sw__fr_box_empty(double box[6])
{
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
}

void sw__fr_box_add(double box[6], const double h[4])
{
    for (int k = 0; k < 3; ++k) {
        double x = h[k] / h[3];
        box[k] = fmin(box[k], x);
        box[3 + k] = fmax(box[3 + k], x);
    }
}

static void occurrence_box(const frame *f, const occurrence *o, double box[6])
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(f->scene, o->face, &s);
    sw__fr_box_empty(box);
    size_t n = (size_t)s.n_u * (size_t)s.n_v;
    for (size_t i = 0; i < n; ++i) {
        double h[4];
        sw__fr_xform_h(o->world, f->view.eye, s.cpw + 4 * i, h);
        sw__fr_box_add(box, h);
    }
}

/* An upper bound of the spectral norm of the occurrence's linear part, sqrt(|M|_1 |M|_inf): 1 for
 * a rigid transform (the Frobenius norm would give sqrt(3) and make every tolerance 1.7x tighter).
 */
double sw__fr_stretch_bound(const double m[12])
{
    double col = 0.0, row = 0.0;
    for (int i = 0; i < 3; ++i) {
        double c = 0.0, r = 0.0;
        for (int j = 0; j < 3; ++j) {
            c += fabs(m[4 * j + i]);
            r += fabs(m[4 * i + j]);
        }
        col = fmax(col, c);
        row = fmax(row, r);
    }
    return sqrt(col * row);
}

double sw__fr_det3(const double m[12])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

static sw_result face_bezier(frame *f, uint32_t face, const sw_sg_bezier_set **out,
                             sw_status *status)
{
    if (!f->bez[face]) {
        sw_sg_bezier_set *set = sw__calloc(1, sizeof *set);
        if (!set)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", face);
        const double *b = f->sv->faces[face].uv_box;
        sw_sg_surface s;
        sw_sg_scene_face_surface(f->scene, face, &s);
        sw_result r = sw_sg_surface_extract_bezier_in(&s, b[0], b[1], b[2], b[3], set, status);
        if (r != SW_OK) {
            sw__free(set);
            return r;
        }
        f->bez[face] = set;
    }
    *out = f->bez[face];
    return SW_OK;
}

/* Sets up one patch: eye-relative control points, clipping to the uv box, culling, density. */
static void patch_setup(frame *f, const occurrence *o, const sw_sg_bezier_patch *bp,
                        const double ub[4], int class_grids, double *cpw, sw__gpu_patch *pt,
                        trim_need *need)
{
    size_t n = (size_t)(bp->deg_u + 1) * (size_t)(bp->deg_v + 1);
    double box[6];
    sw__fr_box_empty(box);
    for (size_t i = 0; i < n; ++i) {
        sw__fr_xform_h(o->world, f->view.eye, bp->cpw + 4 * i, cpw + 4 * i);
        sw__fr_box_add(box, cpw + 4 * i);
    }
    memset(pt, 0, sizeof *pt);
    pt->deg_u = bp->deg_u;
    pt->deg_v = bp->deg_v;
    pt->cpw = cpw;
    pt->u0 = bp->u0;
    pt->u1 = bp->u1;
    pt->v0 = bp->v0;
    pt->v1 = bp->v1;
    pt->nu = pt->nv = 1;
    double du = bp->u1 - bp->u0, dv = bp->v1 - bp->v0;
    pt->s0 = fmax(0.0, (ub[0] - bp->u0) / du);
    pt->s1 = fmin(1.0, (ub[1] - bp->u0) / du);
    pt->t0 = fmax(0.0, (ub[2] - bp->v0) / dv);
    pt->t1 = fmin(1.0, (ub[3] - bp->v0) / dv);
    if (!(pt->s1 > pt->s0) || !(pt->t1 > pt->t0) || !sw__gpu_view_box_visible(&f->view, box))
        return;
    pt->visible = 1;
    const double range[4] = {pt->s0, pt->s1, pt->t0, pt->t1};
    const segment_set *set = class_grids ? &f->gpu_segments : &f->cpu_segments;
    sw_lod_screen_density d;
    sw_lod_screen_segments(bp->deg_u, bp->deg_v, cpw, range, &f->screen, set->n, set->count,
                           MAX_BOUND_SUBDIVISION, &d);
    pt->eps = d.eps_obj;
    pt->nu = d.nu;
    pt->nv = d.nv;
    need->u = fmax(need->u, sw_lod_trim_texels(ub[1] - ub[0], d.d1[0], du, d.eps_obj));
    need->v = fmax(need->v, sw_lod_trim_texels(ub[3] - ub[2], d.d1[1], dv, d.eps_obj));
}

/* One u-density per patch column and one v-density per row: grids meet vertex to vertex. */

static void unify_densities(sw__gpu_patch *pt, int32_t n_cols, int32_t n_rows)
{
    for (int32_t a = 0; a < n_cols; ++a) {
        int32_t m = 1;
        for (int32_t b = 0; b < n_rows; ++b)
            if (pt[b * n_cols + a].visible && pt[b * n_cols + a].nu > m)
                m = pt[b * n_cols + a].nu;
        for (int32_t b = 0; b < n_rows; ++b)
            pt[b * n_cols + a].nu = m;
    }
    for (int32_t b = 0; b < n_rows; ++b) {
        int32_t m = 1;
        for (int32_t a = 0; a < n_cols; ++a)
            if (pt[b * n_cols + a].visible && pt[b * n_cols + a].nv > m)
                m = pt[b * n_cols + a].nv;
        for (int32_t a = 0; a < n_cols; ++a)
            pt[b * n_cols + a].nv = m;
    }
}

sw_result sw__fr_add_draw(frame *f, const occurrence *o, size_t first_idx, int trimmed,
                          const trim_need *need, const double cell[2], sw_status *status)
{
    if (!sw__gpu_grow((void **)&f->draws, &f->cap_draws, f->n_draws + 1, sizeof *f->draws) ||
        (trimmed &&
         !sw__gpu_grow((void **)&f->trims, &f->cap_trims, f->n_trims + 1, sizeof *f->trims)))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame draws: out of memory");
    sw__gpu_draw *d = &f->draws[f->n_draws];
    d->first_idx = first_idx;
    d->n_idx = f->mesh.n_idx - first_idx;
    memcpy(d->color, o->color, sizeof d->color);
    d->trim_entry = -1;
    /* a face's CPU grids carry st over its uv box (fat borders: sw__fr_fat_border; triangle
     * meshes and static levels, st = 0: sw__fr_append_triangles) */
    memset(d->uv_map, 0, sizeof d->uv_map);
    if (o->face < f->sv->n_faces) {
        const double *ub = f->sv->faces[o->face].uv_box;
        const float uv_map[4] = {(float)ub[0], (float)ub[2], (float)(ub[1] - ub[0]),
                                 (float)(ub[3] - ub[2])};
        memcpy(d->uv_map, uv_map, sizeof uv_map);
    }
    if (trimmed)
        f->trims[f->n_trims++] = (pending_trim){f->n_draws,
                                                o->face,
                                                need->u,
                                                need->v,
                                                (size_t)(o - f->occ),
                                                {cell[0], cell[1]},
                                                -1,
                                                {0.0, 0.0, 0.0, 0.0}};
    f->n_draws++;
    return SW_OK;
}

/* Hands one drawn patch piece to the context's debug hook. */
void sw__fr_report_patch(const frame *f, const occurrence *o, const sw__gpu_patch *pt, double s0,
                         double s1, double t0, double t1, int32_t nu, int32_t nv, int gpu,
                         int trimmed)
{
    sw__gpu_drawn_patch d = {&f->view, o->face, o->world, pt->deg_u, pt->deg_v, pt->cpw, pt->u0,
                             pt->u1,   pt->v0,  pt->v1,   s0,        s1,        t0,      t1,
                             nu,       nv,      gpu,      trimmed,   pt->eps};
    f->ctx->patch_hook(f->ctx->patch_hook_user, &d);
}

void sw__gpu_set_patch_hook(sw_gpu_context *ctx, sw__gpu_patch_hook fn, void *user)
{
    ctx->patch_hook = fn;
    ctx->patch_hook_user = user;
}

/* Smallest grid class with at least n segments (n <= SW__GPU_GRID_MAX). */
static int32_t level_for(int32_t n)
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
    *level = level_for((n + *pieces - 1) / *pieces);
}

/* Exact path: the face occurrence's knot vectors and eye-relative homogeneous control points
 * (double), appended once per occurrence. */
static sw_result exact_net(frame *f, const occurrence *o, sw_status *status)
{
    if (f->ex_occ == o)
        return SW_OK;
    sw_sg_surface s;
    sw_sg_scene_face_surface(f->scene, o->face, &s);
    size_t nku = (size_t)s.n_u + (size_t)s.deg_u + 1, nkv = (size_t)s.n_v + (size_t)s.deg_v + 1;
    size_t ncp = (size_t)s.n_u * (size_t)s.n_v;
    if (f->n_knots + nku + nkv > UINT32_MAX || f->n_dcps + ncp > UINT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT, "face %u: exact evaluation buffers over 2^32",
                        o->face);
    if (!sw__gpu_grow((void **)&f->knots, &f->cap_knots, f->n_knots + nku + nkv,
                      sizeof *f->knots) ||
        !sw__gpu_grow((void **)&f->dcps, &f->cap_dcps, 4 * (f->n_dcps + ncp), sizeof *f->dcps))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    sw__gpu_exact_piece *b = &f->ex_base;
    memset(b, 0, sizeof *b);
    b->ku = (uint32_t)f->n_knots;
    b->kv = (uint32_t)(f->n_knots + nku);
    b->cp = (uint32_t)f->n_dcps;
    b->stride = s.n_u;
    b->deg_u = s.deg_u;
    b->deg_v = s.deg_v;
    memcpy(f->knots + f->n_knots, s.knots_u, nku * sizeof *f->knots);
    memcpy(f->knots + f->n_knots + nku, s.knots_v, nkv * sizeof *f->knots);
    f->n_knots += nku + nkv;
    for (size_t i = 0; i < ncp; ++i)
        sw__fr_xform_h(o->world, f->view.eye, s.cpw + 4 * i, f->dcps + 4 * (f->n_dcps + i));
    f->n_dcps += ncp;
    f->ex_srf = s;
    f->ex_occ = o;
    return SW_OK;
}

/* Exact path: the piece (knot spans) of one Bézier patch of the current occurrence; its index
 * goes into the records' cp. */
static sw_result exact_piece(frame *f, const occurrence *o, const sw__gpu_patch *pt,
                             uint32_t *index, sw_status *status)
{
    sw_result r = exact_net(f, o, status);
    if (r != SW_OK)
        return r;
    if (!sw__gpu_grow((void **)&f->pieces, &f->cap_pieces, f->n_pieces + 1, sizeof *f->pieces))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    const sw_sg_surface *s = &f->ex_srf;
    sw__gpu_exact_piece *q = &f->pieces[f->n_pieces];
    *q = f->ex_base;
    q->u0 = pt->u0;
    q->u1 = pt->u1;
    q->v0 = pt->v0;
    q->v1 = pt->v1;
    /* the midpoint lies inside the patch's span whatever the half-open convention */
    q->span_u = sw_sg_knots_find_span(s->knots_u, s->deg_u, s->n_u, 0.5 * (pt->u0 + pt->u1));
    q->span_v = sw_sg_knots_find_span(s->knots_v, s->deg_v, s->n_v, 0.5 * (pt->v0 + pt->v1));
    *index = (uint32_t)f->n_pieces++;
    return SW_OK;
}

/* Appends the control points of a visible patch (float, eye-relative homogeneous) and one record
 * per piece of its sampled domain (§4.2). Pieces share their edge parameters bit for bit. */
sw_result sw__fr_gpu_patch(frame *f, const occurrence *o, const sw__gpu_patch *pt,
                           const double ub[4], double sign, int32_t draw, int trimmed,
                           sw_status *status)
{
    size_t n_cp = f->exact ? 0 : (size_t)(pt->deg_u + 1) * (size_t)(pt->deg_v + 1);
    uint32_t cp_index = (uint32_t)f->n_cps;
    if (f->exact) {
        sw_result r = exact_piece(f, o, pt, &cp_index, status);
        if (r != SW_OK)
            return r;
    }
    int32_t ku, kv, lu, lv;
    split_class(pt->nu, &ku, &lu);
    split_class(pt->nv, &kv, &lv);
    size_t n_rec = (size_t)ku * (size_t)kv;
    if (!sw__gpu_grow((void **)&f->cps, &f->cap_cps, 4 * (f->n_cps + n_cp), sizeof *f->cps) ||
        !sw__gpu_grow((void **)&f->recs, &f->cap_recs, f->n_recs + n_rec, sizeof *f->recs))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    for (size_t i = 0; i < 4 * n_cp; ++i)
        f->cps[4 * f->n_cps + i] = (float)pt->cpw[i];
    double bw = ub[1] - ub[0], bh = ub[3] - ub[2];
    float map[4] = {(float)((pt->u0 - ub[0]) / bw), (float)((pt->u1 - pt->u0) / bw),
                    (float)((pt->v0 - ub[2]) / bh), (float)((pt->v1 - pt->v0) / bh)};
    const float uv_map[4] = {(float)pt->u0, (float)pt->v0, (float)(pt->u1 - pt->u0),
                             (float)(pt->v1 - pt->v0)};
    for (int32_t b = 0; b < kv; ++b) {
        for (int32_t a = 0; a < ku; ++a) {
            sw__gpu_patch_rec *rec = &f->recs[f->n_recs++];
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
            if (f->ctx->patch_hook)
                sw__fr_report_patch(f, o, pt, rec->st[0], rec->st[1], rec->st[2], rec->st[3],
                                    sw__gpu_grid_segments[lu], sw__gpu_grid_segments[lv], 1,
                                    trimmed);
        }
    }
    f->n_cps += n_cp;
    int32_t su = sw__gpu_grid_segments[lu], sv = sw__gpu_grid_segments[lv];
    f->gpu_vertices += (double)n_rec * (double)(su + 1) * (double)(sv + 1);
    f->st.triangles += (uint64_t)n_rec * 2u * (uint64_t)su * (uint64_t)sv;
    return SW_OK;
}

/* GPU evaluation of a face's patches: one draw record for its colour and trim texture, one
 * patch record per visible patch (or piece). */
static sw_result gpu_face(frame *f, const occurrence *o, const sw__gpu_patch *pt, size_t n,
                          double sign, int trimmed, const trim_need *need, const double cell[2],
                          sw_status *status)
{
    int32_t d = (int32_t)f->n_draws;
    sw_result r = sw__fr_add_draw(f, o, f->mesh.n_idx, trimmed, need, cell, status);
    const double *ub = f->sv->faces[o->face].uv_box;
    for (size_t p = 0; p < n && r == SW_OK; ++p)
        if (pt[p].visible)
            r = sw__fr_gpu_patch(f, o, &pt[p], ub, sign, d, trimmed, status);
    return r;
}

/* Which path draws a face: the vertex shader takes rational Bézier patches of degree <= 3 x 3
 * (§4.2); higher degrees stay CPU grids (patch_grid.c) until the bicubic hierarchy feeds them. */
int sw__fr_face_gpu_eligible(const sw_sg_bezier_set *set)
{
    if (set->n_u * set->n_v == 0)
        return 0;
    return set->patches[0].deg_u <= 3 && set->patches[0].deg_v <= 3;
}

int sw__fr_face_on_gpu(const frame *f, const sw_sg_bezier_set *set)
{
    if (f->exact)
        return 1;
    return f->ctx->eval_mode == SW__GPU_EVAL_AUTO && sw__fr_face_gpu_eligible(set);
}

/* Smallest cell of the face's visible grids, in face parameters. */
/* Smallest cell of the face's visible grids, in face parameters. Slivers (a patch column or row
 * below 1e-9 of the trim box, left by knots a rounding apart) are skipped: their cells say
 * nothing about how far apart the border may be sampled, and would cut every loop segment into
 * thousands of pieces. */
static void grid_cell(const sw__gpu_patch *pt, size_t n, const double ub[4], double cell[2])
{
    const double min_u = 1e-9 * (ub[1] - ub[0]), min_v = 1e-9 * (ub[3] - ub[2]);
    cell[0] = cell[1] = INFINITY;
    for (size_t p = 0; p < n; ++p) {
        if (!pt[p].visible)
            continue;
        double wu = (pt[p].u1 - pt[p].u0) * (pt[p].s1 - pt[p].s0);
        double wv = (pt[p].v1 - pt[p].v0) * (pt[p].t1 - pt[p].t0);
        if (wu > min_u)
            cell[0] = fmin(cell[0], wu / pt[p].nu);
        if (wv > min_v)
            cell[1] = fmin(cell[1], wv / pt[p].nv);
    }
    if (!(cell[0] < INFINITY) || !(cell[1] < INFINITY)) { /* slivers only */
        cell[0] = fmin(cell[0], ub[1] - ub[0]);
        cell[1] = fmin(cell[1], ub[3] - ub[2]);
    }
}

/* §7.1: a fat border along one closed uv loop of a drawn face, as its own draw. */
sw_result sw__fr_fat_border(frame *f, const occurrence *o, const double *uv, size_t n,
                            int left_inside, const double cell[2], const double *st_box,
                            size_t share, sw_status *status)
{
    sw_sg_surface srf;
    sw_sg_scene_face_surface(f->scene, o->face, &srf);
    size_t first = f->mesh.n_idx;
    /* st over the face's uv box when the ribbon is drawn untrimmed: no lookup reads it, but the
     * shading's uv (u_uv_map) does */
    const double *st_rect = st_box ? st_box : f->sv->faces[o->face].uv_box;
    sw_result r = sw__gpu_fat_border(&f->view, &srf, o->world, uv, n, left_inside, cell[0], cell[1],
                                     2.0 * f->eps_px, st_rect, &f->mesh, status);
    if (r == SW_OK && f->mesh.n_idx > first) {
        trim_need none = {0.0, 0.0};
        size_t draw = f->n_draws;
        r = sw__fr_add_draw(f, o, first, 0, &none, cell, status);
        if (r == SW_OK) {
            const double *b = st_rect;
            const float uv_map[4] = {(float)b[0], (float)b[2], (float)(b[1] - b[0]),
                                     (float)(b[3] - b[2])};
            memcpy(f->draws[draw].uv_map, uv_map, sizeof uv_map);
        }
        f->st.triangles += (f->mesh.n_idx - first) / 3;
        f->border_triangles += (f->mesh.n_idx - first) / 3;
        if (r == SW_OK && st_box) {
            if (!sw__gpu_grow((void **)&f->shares, &f->cap_shares, 2 * (f->n_shares + 1),
                              sizeof *f->shares))
                return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame draws: out of memory");
            f->shares[2 * f->n_shares] = draw;
            f->shares[2 * f->n_shares + 1] = share;
            f->n_shares++;
        }
    }
    return r;
}

void sw__gpu_set_crack_fill(sw_gpu_context *ctx, int on)
{
    ctx->crack_fill_off = !on;
}

/* ---- tiled trim boxes (§5.3, §7: trim textures finer than one texture per face can hold) ----
 * A face whose trim texture would need more than k_tile_texels per direction has its trim box
 * cut into ku x kv equal tiles (powers of two). Only tiles whose part of the surface meets the
 * frustum are kept (found by bisection on the sub-patch control-net boxes); each kept tile is
 * one draw with its own trim texture over the tile's rectangle, at the resolution its own part
 * of the surface needs; tiles no loop crosses need no texture (inside) or are dropped (outside).
 * The patches are cut at the tile boundaries into cells; cell densities are unified per column
 * and row of the refined grid (every tile of a column shares its u breaks), so neighbouring
 * cells meet vertex to vertex as whole patches do. */
typedef struct tile {
    double rect[4];
    int32_t i, j;           /* tile indices */
    int32_t a0, a1, b0, b1; /* patch columns and rows it overlaps (inclusive) */
    size_t first_cell;      /* (a1 - a0 + 1) x (b1 - b0 + 1) cells, column fastest */
    trim_need need;
    int cls; /* sw__gpu_trim_rect_class */
} tile;

typedef struct tiling {
    frame *f;
    const occurrence *o;
    const sw_sg_bezier_set *set;
    const sw__gpu_patch *pt;
    const double *ub;
    int32_t ku, kv, class_grids;
    tile *tiles;
    size_t n_tiles, cap_tiles;
    sw__gpu_patch *cells;
    size_t n_cells, cap_cells;
    double *scratch; /* restricted control net */
} tiling;

static double tile_edge(const double *ub, int lo, int32_t i, int32_t k)
{
    return i == k ? ub[lo + 1] : ub[lo] + (ub[lo + 1] - ub[lo]) * (double)i / (double)k;
}

static void tile_rect(const tiling *t, int32_t i0, int32_t i1, int32_t j0, int32_t j1, double r[4])
{
    r[0] = tile_edge(t->ub, 0, i0, t->ku);
    r[1] = tile_edge(t->ub, 0, i1, t->ku);
    r[2] = tile_edge(t->ub, 2, j0, t->kv);
    r[3] = tile_edge(t->ub, 2, j1, t->kv);
}

/* Patch columns (dir 0) or rows (dir 1) overlapping [lo, hi]; *first > *last when none. */
static void patch_span(const sw_sg_bezier_set *set, int dir, double lo, double hi, int32_t *first,
                       int32_t *last)
{
    int32_t n = dir ? set->n_v : set->n_u;
    *first = n;
    *last = -1;
    for (int32_t a = 0; a < n; ++a) {
        const sw_sg_bezier_patch *bp =
            &set->patches[dir ? (size_t)a * (size_t)set->n_u : (size_t)a];
        double p0 = dir ? bp->v0 : bp->u0, p1 = dir ? bp->v1 : bp->u1;
        if (p1 > lo && p0 < hi) {
            *first = a < *first ? a : *first;
            *last = a;
        }
    }
}

/* The cell of patch p inside rect r (local range restricted); visible when its sub-net's box
 * meets the frustum. */
static void make_cell(const tiling *t, size_t p, const double r[4], sw__gpu_patch *c)
{
    *c = t->pt[p];
    if (!c->visible)
        return;
    double du = c->u1 - c->u0, dv = c->v1 - c->v0;
    c->s0 = fmax(c->s0, (r[0] - c->u0) / du);
    c->s1 = fmin(c->s1, (r[1] - c->u0) / du);
    c->t0 = fmax(c->t0, (r[2] - c->v0) / dv);
    c->t1 = fmin(c->t1, (r[3] - c->v0) / dv);
    c->visible = 0;
    if (!(c->s1 > c->s0) || !(c->t1 > c->t0))
        return;
    const double range[4] = {c->s0, c->s1, c->t0, c->t1};
    sw_lod_bez_restrict(c->deg_u, c->deg_v, 4, c->cpw, range, t->scratch);
    double box[6];
    sw__fr_box_empty(box);
    size_t n = (size_t)(c->deg_u + 1) * (size_t)(c->deg_v + 1);
    for (size_t i = 0; i < n; ++i)
        sw__fr_box_add(box, t->scratch + 4 * i);
    c->visible = sw__gpu_view_box_visible(&t->f->view, box);
}

static int rect_visible(const tiling *t, const double r[4])
{
    int32_t a0, a1, b0, b1;
    patch_span(t->set, 0, r[0], r[1], &a0, &a1);
    patch_span(t->set, 1, r[2], r[3], &b0, &b1);
    for (int32_t b = b0; b <= b1; ++b)
        for (int32_t a = a0; a <= a1; ++a) {
            sw__gpu_patch c;
            make_cell(t, (size_t)b * (size_t)t->set->n_u + (size_t)a, r, &c);
            if (c.visible)
                return 1;
        }
    return 0;
}

/* Bisection over tile index ranges: keeps the visible tiles (at most MAX_TILES_PER_FACE). */
static int find_tiles(tiling *t, int32_t i0, int32_t i1, int32_t j0, int32_t j1)
{
    double r[4];
    tile_rect(t, i0, i1, j0, j1, r);
    if (!rect_visible(t, r))
        return 1;
    if (i1 - i0 > 1 || j1 - j0 > 1) {
        if (i1 - i0 >= j1 - j0)
            return find_tiles(t, i0, (i0 + i1) / 2, j0, j1) &&
                   find_tiles(t, (i0 + i1) / 2, i1, j0, j1);
        return find_tiles(t, i0, i1, j0, (j0 + j1) / 2) && find_tiles(t, i0, i1, (j0 + j1) / 2, j1);
    }
    if (t->n_tiles >= MAX_TILES_PER_FACE ||
        !sw__gpu_grow((void **)&t->tiles, &t->cap_tiles, t->n_tiles + 1, sizeof *t->tiles))
        return 0;
    tile *tl = &t->tiles[t->n_tiles++];
    memset(tl, 0, sizeof *tl);
    memcpy(tl->rect, r, sizeof r);
    tl->i = i0;
    tl->j = j0;
    return 1;
}

/* Cells of one tile with their densities and the tile's wanted texels. */
static int tile_cells(tiling *t, tile *tl)
{
    frame *f = t->f;
    patch_span(t->set, 0, tl->rect[0], tl->rect[1], &tl->a0, &tl->a1);
    patch_span(t->set, 1, tl->rect[2], tl->rect[3], &tl->b0, &tl->b1);
    size_t n = (size_t)(tl->a1 - tl->a0 + 1) * (size_t)(tl->b1 - tl->b0 + 1);
    if (!sw__gpu_grow((void **)&t->cells, &t->cap_cells, t->n_cells + n, sizeof *t->cells))
        return 0;
    tl->first_cell = t->n_cells;
    tl->need = (trim_need){1.0, 1.0};
    const segment_set *set = t->class_grids ? &f->gpu_segments : &f->cpu_segments;
    for (int32_t b = tl->b0; b <= tl->b1; ++b)
        for (int32_t a = tl->a0; a <= tl->a1; ++a) {
            sw__gpu_patch *c = &t->cells[t->n_cells++];
            make_cell(t, (size_t)b * (size_t)t->set->n_u + (size_t)a, tl->rect, c);
            c->col = a;
            c->row = b;
            if (!c->visible)
                continue;
            const double range[4] = {c->s0, c->s1, c->t0, c->t1};
            sw_lod_screen_density d;
            sw_lod_screen_segments(c->deg_u, c->deg_v, c->cpw, range, &f->screen, set->n,
                                   set->count, MAX_BOUND_SUBDIVISION, &d);
            c->eps = d.eps_obj;
            c->nu = d.nu;
            c->nv = d.nv;
            tl->need.u = fmax(tl->need.u, sw_lod_trim_texels(tl->rect[1] - tl->rect[0], d.d1[0],
                                                             c->u1 - c->u0, d.eps_obj));
            tl->need.v = fmax(tl->need.v, sw_lod_trim_texels(tl->rect[3] - tl->rect[2], d.d1[1],
                                                             c->v1 - c->v0, d.eps_obj));
        }
    return 1;
}

typedef struct cell_key {
    int64_t key;
    size_t cell;
} cell_key;

static int cell_key_cmp(const void *a, const void *b)
{
    int64_t x = ((const cell_key *)a)->key, y = ((const cell_key *)b)->key;
    return x < y ? -1 : x > y;
}

/* Unifies nu over every cell of a refined column (dir 0) or nv over a row (dir 1). */
static int unify_cells(tiling *t, int dir)
{
    cell_key *k = sw__malloc((t->n_cells ? t->n_cells : 1) * sizeof *k);
    if (!k)
        return 0;
    size_t m = 0;
    for (size_t ti = 0; ti < t->n_tiles; ++ti) {
        const tile *tl = &t->tiles[ti];
        size_t n = (size_t)(tl->a1 - tl->a0 + 1) * (size_t)(tl->b1 - tl->b0 + 1);
        for (size_t c = tl->first_cell; c < tl->first_cell + n; ++c) {
            const sw__gpu_patch *p = &t->cells[c];
            int64_t key =
                dir ? (int64_t)tl->j * t->set->n_v + p->row : (int64_t)tl->i * t->set->n_u + p->col;
            if (p->visible)
                k[m++] = (cell_key){key, c};
        }
    }
    qsort(k, m, sizeof *k, cell_key_cmp);
    for (size_t a = 0; a < m;) {
        size_t b = a;
        int32_t mx = 1;
        for (; b < m && k[b].key == k[a].key; ++b)
            mx = dir ? (t->cells[k[b].cell].nv > mx ? t->cells[k[b].cell].nv : mx)
                     : (t->cells[k[b].cell].nu > mx ? t->cells[k[b].cell].nu : mx);
        for (; a < b; ++a)
            *(dir ? &t->cells[k[a].cell].nv : &t->cells[k[a].cell].nu) = mx;
    }
    sw__free(k);
    return 1;
}

/* Flattens the face's loops once, finely enough for its finest tile texture, and classifies
 * the tiles against them (a margin of 1 % of a tile so that a loop on a tile's edge counts). */
sw_result sw__fr_face_loops(frame *f, uint32_t face, double tol, int64_t *index, sw_status *status)
{
    const sw_sg_face_rec *rec = &f->sv->faces[face];
    if (!sw__gpu_grow((void **)&f->loops, &f->cap_loops, f->n_loops + 1, sizeof *f->loops))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", face);
    face_loops *fl = &f->loops[f->n_loops];
    fl->n = 0;
    fl->loops = sw__calloc(rec->n_loops ? rec->n_loops : 1, sizeof *fl->loops);
    if (!fl->loops)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", face);
    *index = (int64_t)f->n_loops++;
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < rec->n_loops && r == SW_OK; ++k, ++fl->n)
        r = sw_sg_trim_flatten_loop(f->scene, rec->first_loop + k, tol, MAX_TRIM_LOOP_VERTICES,
                                    &fl->loops[k], status);
    return r;
}

static sw_result tile_loops(tiling *t, int64_t *index, sw_status *status)
{
    frame *f = t->f;
    int32_t max_entry = sw__gpu_atlas_max_entry(f->ctx);
    double tol = INFINITY;
    for (size_t i = 0; i < t->n_tiles; ++i) {
        const tile *tl = &t->tiles[i];
        tol = fmin(tol,
                   0.5 * (tl->rect[1] - tl->rect[0]) / sw__fr_class_texels(tl->need.u, max_entry));
        tol = fmin(tol,
                   0.5 * (tl->rect[3] - tl->rect[2]) / sw__fr_class_texels(tl->need.v, max_entry));
    }
    sw_result r = sw__fr_face_loops(f, t->o->face, tol, index, status);
    const face_loops *fl = r == SW_OK ? &f->loops[*index] : NULL;
    for (size_t i = 0; i < t->n_tiles && r == SW_OK; ++i) {
        tile *tl = &t->tiles[i];
        double mu = 0.01 * (tl->rect[1] - tl->rect[0]), mv = 0.01 * (tl->rect[3] - tl->rect[2]);
        double g[4] = {tl->rect[0] - mu, tl->rect[1] + mu, tl->rect[2] - mv, tl->rect[3] + mv};
        tl->cls = sw__gpu_trim_rect_class(fl->loops, fl->n, g);
    }
    return r;
}

/* One tile's draw: its cells as vertex-shader records or one CPU grid. */
static sw_result tile_draw(tiling *t, const tile *tl, int64_t loops, double sign, int on_gpu,
                           const double cell[2], sw_status *status)
{
    frame *f = t->f;
    int trimmed = tl->cls == 0;
    int32_t n_cols = tl->a1 - tl->a0 + 1, n_rows = tl->b1 - tl->b0 + 1;
    size_t n = (size_t)n_cols * (size_t)n_rows, first = f->mesh.n_idx;
    const sw__gpu_patch *c = t->cells + tl->first_cell;
    int32_t d = (int32_t)f->n_draws;
    sw_result r = SW_OK;
    if (on_gpu) {
        r = sw__fr_add_draw(f, t->o, first, trimmed, &tl->need, cell, status);
        for (size_t p = 0; p < n && r == SW_OK; ++p)
            if (c[p].visible)
                r = sw__fr_gpu_patch(f, t->o, &c[p], tl->rect, sign, d, trimmed, status);
    } else {
        r = sw__gpu_tessellate_face(c, n_cols, n_rows, sign, tl->rect, &f->mesh, status);
        for (size_t p = 0; p < n && f->ctx->patch_hook; ++p)
            if (c[p].visible)
                sw__fr_report_patch(f, t->o, &c[p], c[p].s0, c[p].s1, c[p].t0, c[p].t1, c[p].nu,
                                    c[p].nv, 0, trimmed);
        if (r == SW_OK)
            r = sw__fr_add_draw(f, t->o, first, trimmed, &tl->need, cell, status);
    }
    if (r == SW_OK && trimmed) {
        pending_trim *pt = &f->trims[f->n_trims - 1];
        pt->loops = loops;
        memcpy(pt->rect, tl->rect, sizeof pt->rect);
    }
    return r;
}

static sw_result tiled_draws(tiling *t, double sign, int on_gpu, sw_status *status)
{
    frame *f = t->f;
    int64_t loops = -1;
    sw_result r = tile_loops(t, &loops, status);
    double cell[2] = {INFINITY, INFINITY};
    for (size_t i = 0; i < t->n_cells; ++i)
        if (t->cells[i].visible) {
            const sw__gpu_patch *c = &t->cells[i];
            cell[0] = fmin(cell[0], (c->u1 - c->u0) * (c->s1 - c->s0) / c->nu);
            cell[1] = fmin(cell[1], (c->v1 - c->v0) * (c->t1 - c->t0) / c->nv);
        }
    for (size_t i = 0; i < t->n_tiles && r == SW_OK; ++i)
        if (t->tiles[i].cls >= 0)
            r = tile_draw(t, &t->tiles[i], loops, sign, on_gpu, cell, status);
    const face_loops *fl = loops >= 0 ? &f->loops[loops] : NULL;
    for (uint32_t k = 0; r == SW_OK && fl && !f->ctx->crack_fill_off && k < fl->n; ++k)
        r = sw__fr_fat_border(f, t->o, fl->loops[k].uv, fl->loops[k].count,
                              sw__fr_left_is_inside(fl->loops, fl->n, k), cell, NULL, 0, status);
    return r;
}

static int32_t tiles_for(double need)
{
    int32_t k = 1;
    while (k < MAX_TILES_PER_DIR && need / k > k_tile_texels)
        k *= 2;
    return k;
}

static sw_result tiled_face(frame *f, const occurrence *o, const sw_sg_bezier_set *set,
                            const sw__gpu_patch *pt, const trim_need *need, double sign, int on_gpu,
                            int class_grids, sw_status *status)
{
    tiling t = {f,
                o,
                set,
                pt,
                f->sv->faces[o->face].uv_box,
                tiles_for(need->u),
                tiles_for(need->v),
                class_grids,
                NULL,
                0,
                0,
                NULL,
                0,
                0,
                NULL};
    int32_t md = 0;
    for (size_t p = 0; p < (size_t)set->n_u * (size_t)set->n_v; ++p)
        md = md > (set->patches[p].deg_u + 1) * (set->patches[p].deg_v + 1)
                 ? md
                 : (set->patches[p].deg_u + 1) * (set->patches[p].deg_v + 1);
    t.scratch = sw__malloc((size_t)md * 4 * sizeof *t.scratch);
    int ok = t.scratch != NULL;
    while (ok && !find_tiles(&t, 0, t.ku, 0, t.kv) && t.n_tiles >= MAX_TILES_PER_FACE) {
        t.n_tiles = 0; /* too many visible tiles: coarser ones */
        t.ku = t.ku > 1 ? t.ku / 2 : 1;
        t.kv = t.kv > 1 ? t.kv / 2 : 1;
    }
    ok = ok && t.n_tiles < MAX_TILES_PER_FACE;
    for (size_t i = 0; i < t.n_tiles && ok; ++i)
        ok = tile_cells(&t, &t.tiles[i]);
    ok = ok && unify_cells(&t, 0) && unify_cells(&t, 1);
    sw_result r =
        ok ? tiled_draws(&t, sign, on_gpu, status)
           : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u tiles: out of memory", o->face);
    sw__free(t.scratch);
    sw__free(t.tiles);
    sw__free(t.cells);
    return r;
}

sw_result sw__fr_draw_face(frame *f, const occurrence *o, sw_status *status)
{
    const sw_sg_face_rec *rec = &f->sv->faces[o->face];
    const sw_sg_bezier_set *set = NULL;
    sw_result r = face_bezier(f, o->face, &set, status);
    if (r != SW_OK)
        return r;
    if (f->exact) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(f->scene, o->face, &s);
        if (s.deg_u > SW_GPU_EXACT_MAX_DEGREE || s.deg_v > SW_GPU_EXACT_MAX_DEGREE)
            return sw__fail(status, SW_ERR_LIMIT,
                            "face %u: degree %d x %d above %d, the exact evaluator's limit",
                            o->face, s.deg_u, s.deg_v, SW_GPU_EXACT_MAX_DEGREE);
    }
    int32_t n_cols = set->n_u, n_rows = set->n_v;
    size_t n = (size_t)n_cols * (size_t)n_rows, n_cp = 0;
    for (size_t p = 0; p < n; ++p)
        n_cp += (size_t)(set->patches[p].deg_u + 1) * (size_t)(set->patches[p].deg_v + 1);
    sw__gpu_patch *pt = sw__calloc(n ? n : 1, sizeof *pt);
    double *cpw = sw__malloc((n_cp ? n_cp : 1) * 4 * sizeof *cpw);
    if (!pt || !cpw) {
        sw__free(pt);
        sw__free(cpw);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    }
    trim_need need = {1.0, 1.0};
    size_t at = 0, drawn = 0;
    int on_gpu = sw__fr_face_on_gpu(f, set);
    /* CPU_GRIDS mode draws the grids the vertex shader would (the reference of §4.2's path). */
    int class_grids = f->exact || sw__fr_face_gpu_eligible(set);
    for (size_t p = 0; p < n; ++p) {
        const sw_sg_bezier_patch *bp = &set->patches[p];
        patch_setup(f, o, bp, rec->uv_box, class_grids, cpw + at, &pt[p], &need);
        pt[p].col = (int32_t)(p % (size_t)n_cols);
        pt[p].row = (int32_t)(p / (size_t)n_cols);
        at += (size_t)(bp->deg_u + 1) * (size_t)(bp->deg_v + 1) * 4;
        drawn += (size_t)pt[p].visible;
    }
    f->st.patches_culled += n - drawn;
    int trimmed = (rec->flags & SW_SG_FACE_TRIMMED) && rec->n_loops > 0;
    if (drawn > 0) {
        unify_densities(pt, n_cols, n_rows);
        double sign = (rec->flags & SW_SG_FACE_REVERSED) ? -1.0 : 1.0;
        if (sw__fr_det3(o->world) < 0.0)
            sign = -sign;
        size_t first = f->mesh.n_idx;
        double cell[2];
        grid_cell(pt, n, rec->uv_box, cell);
        if (trimmed && (need.u > k_tile_texels || need.v > k_tile_texels)) {
            r = tiled_face(f, o, set, pt, &need, sign, on_gpu, class_grids, status);
            if (on_gpu)
                f->st.patches_gpu_evaluated += drawn;
        } else if (on_gpu) {
            r = gpu_face(f, o, pt, n, sign, trimmed, &need, cell, status);
            f->st.patches_gpu_evaluated += drawn;
        } else {
            r = sw__gpu_tessellate_face(pt, n_cols, n_rows, sign, rec->uv_box, &f->mesh, status);
            for (size_t p = 0; p < n && f->ctx->patch_hook; ++p)
                if (pt[p].visible)
                    sw__fr_report_patch(f, o, &pt[p], pt[p].s0, pt[p].s1, pt[p].t0, pt[p].t1,
                                        pt[p].nu, pt[p].nv, 0, trimmed);
            if (r == SW_OK)
                r = sw__fr_add_draw(f, o, first, trimmed, &need, cell, status);
        }
        if (f->exact)
            f->st.patches_exact += drawn;
        if (r == SW_OK && !trimmed && !f->ctx->crack_fill_off) {
            const double *b = rec->uv_box;
            const double box_loop[8] = {b[0], b[2], b[1], b[2], b[1], b[3], b[0], b[3]};
            r = sw__fr_fat_border(f, o, box_loop, 4, 1, cell, NULL, 0,
                                  status); /* counter-clockwise */
        }
        f->st.faces_drawn++;
        if (trimmed)
            f->st.patches_trimmed += drawn;
        else
            f->st.patches_untrimmed += drawn;
    } else {
        f->st.faces_culled++;
    }
    sw__free(pt);
    sw__free(cpw);
    if (r == SW_OK && (double)f->mesh.n_v + f->gpu_vertices > k_max_frame_vertices)
        r = sw__fail(status, SW_ERR_LIMIT,
                     "frame needs more than %.0f grid vertices (error %g px too small for this "
                     "view?)",
                     k_max_frame_vertices, f->eps_px);
    return r;
}

/* Effective segments of a direction of n segments drawn by split_class's pieces. */
static int32_t class_segments(int32_t n)
{
    int32_t pieces, level;
    split_class(n, &pieces, &level);
    return pieces * sw__gpu_grid_segments[level];
}

static void screen_view_init(frame *f)
{
    const sw__gpu_view *v = &f->view;
    sw_lod_screen_view *s = &f->screen;
    memcpy(s->right, v->right, sizeof s->right);
    memcpy(s->up, v->up, sizeof s->up);
    memcpy(s->fwd, v->fwd, sizeof s->fwd);
    s->focal_px = v->focal_px;
    s->tan_corner = hypot(v->tan_x, v->tan_y);
    s->near_plane = v->near_plane;
    s->eps_px = f->eps_px;
    f->cpu_segments.count = f->gpu_segments.count = 0;
    for (int32_t n = 1; n <= MAX_SEGMENTS; ++n) {
        f->cpu_segments.n[f->cpu_segments.count++] = n;
        int32_t c = class_segments(n);
        segment_set *g = &f->gpu_segments;
        if (c <= MAX_SEGMENTS && (g->count == 0 || g->n[g->count - 1] < c))
            g->n[g->count++] = c;
    }
}

/* Collects occurrences, sets the view (near plane from the scene's box) and tessellates. */
/* Every occurrence, with its eye-relative control-net box (the scene traversal, all control points
 * transformed: the path without a BVH). */
static sw_result collect_all(frame *f, const sw_gpu_frame_desc *desc, double **boxes_out,
                             double scene_box[6], sw_status *status)
{
    for (size_t i = 0; desc->occurrences && i < desc->n_occurrences && !f->oom; ++i) {
        const sw_gpu_occurrence *o = &desc->occurrences[i];
        if (o->face >= f->sv->n_faces)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "frame: occurrence %zu names face %u of %u", i, o->face,
                            f->sv->n_faces);
        collect(f, o->face, o->world, o->color);
    }
    if ((!desc->occurrences && sw_sg_scene_traverse(f->scene, collect, f) != SW_OK) || f->oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "scene traversal: out of memory");
    double *boxes = sw__malloc((f->n_occ ? f->n_occ : 1) * 6 * sizeof *boxes);
    if (!boxes)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "scene traversal: out of memory");
    sw__fr_box_empty(scene_box);
    for (size_t i = 0; i < f->n_occ; ++i) {
        occurrence_box(f, &f->occ[i], boxes + 6 * i);
        for (int k = 0; k < 3; ++k) {
            scene_box[k] = fmin(scene_box[k], boxes[6 * i + k]);
            scene_box[3 + k] = fmax(scene_box[3 + k], boxes[6 * i + 3 + k]);
        }
    }
    *boxes_out = boxes;
    return SW_OK;
}

static void eye_box(const frame *f, const double world[6], double out[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = world[k] - f->view.eye[k];
        out[3 + k] = world[3 + k] - f->view.eye[k];
    }
}

int sw__fr_take_occurrence(frame *f, uint32_t face, const double world[12], const float color[4],
                           const double world_box[6], double **boxes, size_t *cap_boxes)
{
    const size_t at = f->n_occ;
    if (collect(f, face, world, color) != 0 ||
        !sw__gpu_grow((void **)boxes, cap_boxes, 6 * (at + 1), sizeof **boxes))
        return 0;
    eye_box(f, world_box, *boxes + 6 * at);
    return 1;
}

void sw__fr_frustum(const frame *f, sw_sg_frustum *fr)
{
    memcpy(fr->origin, f->view.eye, sizeof fr->origin);
    memcpy(fr->planes, f->view.planes, sizeof f->view.planes);
    fr->n_planes = (int32_t)(sizeof f->view.planes / sizeof f->view.planes[0]);
}

void sw__fr_bvh_stats(frame *f, const sw_sg_bvh_cull_stats *cs)
{
    f->st.bvh_nodes_visited += cs->nodes_visited;
    f->st.bvh_nodes_inside += cs->nodes_inside;
    f->st.bvh_nodes_partly += cs->nodes_partly;
    f->st.bvh_nodes_outside += cs->nodes_outside;
    f->st.bvh_items_tested += cs->items_tested;
    f->st.bvh_items_visible += cs->items_visible;
    f->st.bvh_items_inside += cs->items_inside;
}

typedef struct bvh_taker {
    frame *f;
    const sw_sg_bvh *bvh;
    double **boxes;
    size_t cap_boxes;
} bvh_taker;

/* Appends one visible BVH item as an occurrence with its eye-relative box. */
static int bvh_take(void *ctx, uint32_t item, sw_sg_cull_class cls)
{
    (void)cls;
    bvh_taker *t = ctx;
    const sw_sg_bvh_item *it = &t->bvh->items[item];
    return !sw__fr_take_occurrence(t->f, it->face, it->world, it->color, it->box, t->boxes,
                                   &t->cap_boxes);
}

/* Kumar §4.4: the occurrences whose boxes may meet the frustum, by the BVH (sw_sg_bvh_cull: a node
 * outside is culled with its subtree, a node inside takes its subtree untested). */
static sw_result collect_bvh(frame *f, const sw_sg_bvh *bvh, double **boxes, sw_status *status)
{
    sw_sg_frustum fr;
    sw__fr_frustum(f, &fr);
    bvh_taker t = {f, bvh, boxes, 0};
    sw_sg_bvh_cull_stats cs;
    const int stopped = sw_sg_bvh_cull(bvh, &fr, bvh_take, &t, &cs);
    f->st.faces_culled += bvh->n_items - cs.items_visible;
    sw__fr_bvh_stats(f, &cs);
    if (stopped)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    return SW_OK;
}

int sw__fr_face_back_facing(const sw_lod_face_cones *fc, const occurrence *o, const double box[6])
{
    sw_lod_cone w;
    return sw_lod_cone_to_world(&fc->cones[o->face], o->world, &w) &&
           sw_lod_cone_back_facing(&w, box);
}

sw_result sw__fr_check_cones(const frame *f, const sw_lod_face_cones *fc, sw_status *status)
{
    if (fc->n_faces != f->sv->n_faces)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: face cones of %u faces for a scene of %u", fc->n_faces,
                        f->sv->n_faces);
    return SW_OK;
}

/* Kumar §4.4's back-patch culling: drops (compacting occ and boxes) the occurrences of closed-shell
 * faces whose outward cone, in the world, faces away from every view direction into their box.
 * Done before the hierarchies are asked for, so culled faces cost nothing further. Sound only for
 * an eye outside the solids: from inside a solid's material its back faces are what one sees. */
static sw_result cull_back_faces(frame *f, const sw_lod_face_cones *fc, double *boxes,
                                 sw_status *status)
{
    sw_result r = sw__fr_check_cones(f, fc, status);
    if (r != SW_OK)
        return r;
    size_t k = 0;
    for (size_t i = 0; i < f->n_occ; ++i) {
        if (sw__fr_face_back_facing(fc, &f->occ[i], boxes + 6 * i)) {
            f->st.faces_backculled++;
            f->st.faces_culled++;
            continue;
        }
        if (k != i) {
            f->occ[k] = f->occ[i];
            memcpy(boxes + 6 * k, boxes + 6 * i, 6 * sizeof *boxes);
        }
        k++;
    }
    f->n_occ = k;
    return SW_OK;
}

/* Sets the view (near plane from the scene's box), finds the visible occurrences and tessellates.
 */
static sw_result tessellate(frame *f, const sw_gpu_frame_desc *desc, sw_status *status)
{
    memcpy(f->view.eye, desc->camera.eye, sizeof f->view.eye);
    double *boxes = NULL, scene_box[6];
    sw_result r = SW_OK;
    /* immediate draws (desc.occurrences) bring their own occurrences: no BVH culls them. With
     * static LODs the unit-instance BVH culls (frame_static.c); its scene box is the face BVH's
     * root box, so both give the same near plane */
    const sw_sg_bvh *bvh = desc->occurrences ? NULL : desc->bvh;
    const sw_lod_static_instances *units = f->statics && !f->exact && !desc->occurrences
                                               ? sw_lod_static_set_instances(f->statics)
                                               : NULL;
    if (bvh || units) {
        sw__fr_box_empty(scene_box);
        if (bvh && bvh->n_nodes)
            eye_box(f, bvh->nodes[0].box, scene_box);
        else if (!bvh && units->n_occs)
            eye_box(f, units->scene_box, scene_box);
    } else {
        r = collect_all(f, desc, &boxes, scene_box, status);
    }
    sw__fr_meshes meshes;
    if (r == SW_OK)
        r = sw__fr_meshes_collect(f, &meshes, scene_box, status);
    else
        memset(&meshes, 0, sizeof meshes);
    static const double k_origin[3] = {0.0, 0.0, 0.0};
    double near_plane = desc->near_plane > 0.0         ? desc->near_plane
                        : scene_box[0] <= scene_box[3] ? sw__gpu_near_plane(k_origin, scene_box)
                                                       : 1.0;
    if (r == SW_OK)
        r = sw__gpu_view_init(&f->view, &desc->camera, desc->width, desc->height, near_plane,
                              status);
    screen_view_init(f);
    if (r == SW_OK && units)
        r = sw__fr_static_collect(f, desc->face_cones, &boxes, status);
    else if (r == SW_OK && bvh)
        r = collect_bvh(f, bvh, &boxes, status);
    if (r == SW_OK && desc->face_cones && boxes)
        r = cull_back_faces(f, desc->face_cones, boxes, status);
    for (size_t i = 0; f->lod_colors && i < f->n_occ; ++i)
        sw__fr_lod_color(-1, f->occ[i].color);
    int hierarchy = f->cache && !f->exact;
    if (r == SW_OK && hierarchy)
        r = sw__fr_hlod_prepare(f, boxes, desc->walkthrough, status);
    for (size_t i = 0; i < f->n_occ && r == SW_OK; ++i) {
        if (!sw__gpu_view_box_visible(&f->view, boxes + 6 * i)) {
            f->st.faces_culled++;
            continue;
        }
        r = hierarchy ? sw__fr_hlod_draw_face(f, &f->occ[i], status)
                      : sw__fr_draw_face(f, &f->occ[i], status);
    }
    if (r == SW_OK)
        r = sw__fr_meshes_draw(f, &meshes, status);
    sw__fr_meshes_free(&meshes);
    sw__free(boxes);
    return r;
}

/* Texels of a resolution class: footprints (texture plus gutters) are powers of two, so that a
 * class changes only when the wanted resolution doubles or halves, and pages pack them tightly. */
int32_t sw__fr_class_texels(double want, int32_t max_entry)
{
    int32_t foot = 16;
    while (foot - 2 * SW__GPU_ATLAS_GUTTER < want && foot - 2 * SW__GPU_ATLAS_GUTTER < max_entry)
        foot *= 2;
    int32_t n = foot - 2 * SW__GPU_ATLAS_GUTTER;
    return n < max_entry ? n : max_entry;
}

/* Whether the trimmed region lies to the left of loop k's direction: classified just left of
 * the middle of its longest edge (loops are simple, so one point decides for the whole loop). */
int sw__fr_left_is_inside(const sw_sg_polyline *loops, uint32_t n_loops, uint32_t k)
{
    const sw_sg_polyline *l = &loops[k];
    uint32_t best = 0;
    double best_len = -1.0;
    for (uint32_t i = 0; i < l->count; ++i) {
        const double *a = l->uv + 2 * i, *b = l->uv + 2 * ((i + 1) % l->count);
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        if (len > best_len) {
            best_len = len;
            best = i;
        }
    }
    if (l->count < 2 || !(best_len > 0.0))
        return 1;
    const double *a = l->uv + 2 * best, *b = l->uv + 2 * ((best + 1) % l->count);
    double t[2] = {(b[0] - a[0]) / best_len, (b[1] - a[1]) / best_len}, step = 1e-3 * best_len;
    double u = 0.5 * (a[0] + b[0]) - t[1] * step, v = 0.5 * (a[1] + b[1]) + t[0] * step;
    return sw_sg_trim_classify(loops, n_loops, u, v);
}

static sw__gpu_trim_key trim_key(const frame *f, uint32_t face, const sw_sg_face_rec *rec,
                                 const double rect[4])
{
    return (sw__gpu_trim_key){sw_sg_scene_serial(f->scene),
                              face,
                              rec->first_loop,
                              rec->n_loops,
                              {rect[0], rect[1], rect[2], rect[3]}};
}

/* A tile's trim texture: the face's loops clipped to the tile grown by one texel (the clipped
 * border then falls in the entry's gutter), keyed by the tile's rectangle. */
static sw_result make_tile_trim(frame *f, const pending_trim *t, double scale, sw_status *status)
{
    const sw_sg_face_rec *rec = &f->sv->faces[t->face];
    int32_t max_entry = sw__gpu_atlas_max_entry(f->ctx);
    int32_t w = sw__fr_class_texels(t->width * scale, max_entry);
    int32_t h = sw__fr_class_texels(t->height * scale, max_entry);
    const double *r = t->rect;
    const sw__gpu_trim_key key = trim_key(f, t->face, rec, r);
    int32_t id = sw__gpu_atlas_find(f->ctx, &key, w, h);
    f->draws[t->draw].trim_entry = id;
    if (id >= 0)
        return SW_OK;
    const face_loops *fl = &f->loops[t->loops];
    double mu = (r[1] - r[0]) / w, mv = (r[3] - r[2]) / h;
    const double g[4] = {r[0] - mu, r[1] + mu, r[2] - mv, r[3] + mv};
    sw_sg_polyline *clipped = sw__calloc(fl->n ? fl->n : 1, sizeof *clipped);
    if (!clipped)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", t->face);
    sw_result res = sw__gpu_trim_clip_loops(fl->loops, fl->n, g, clipped, status);
    if (res == SW_OK) {
        res = sw__gpu_atlas_add(f->ctx, &key, w, h, clipped, fl->n, &id, status);
        f->draws[t->draw].trim_entry = id;
        for (uint32_t k = 0; k < fl->n; ++k)
            sw_sg_polyline_free(&clipped[k]);
    }
    sw__free(clipped);
    return res;
}

static sw_result make_trim(frame *f, const pending_trim *t, double scale, sw_status *status)
{
    if (t->loops >= 0)
        return make_tile_trim(f, t, scale, status);
    const sw_sg_face_rec *rec = &f->sv->faces[t->face];
    int32_t max_entry = sw__gpu_atlas_max_entry(f->ctx);
    int32_t w = sw__fr_class_texels(t->width * scale, max_entry);
    int32_t h = sw__fr_class_texels(t->height * scale, max_entry);
    const double *ub = rec->uv_box;
    const sw__gpu_trim_key key = trim_key(f, t->face, rec, ub);
    int32_t id = sw__gpu_atlas_find(f->ctx, &key, w, h);
    f->draws[t->draw].trim_entry = id;
    int border = !f->ctx->crack_fill_off;
    if (id >= 0 && !border)
        return SW_OK;
    double tol = 0.5 * fmin((ub[1] - ub[0]) / w, (ub[3] - ub[2]) / h);
    sw_sg_polyline *loops = sw__calloc(rec->n_loops, sizeof *loops);
    if (!loops)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u trim: out of memory", t->face);
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < rec->n_loops && r == SW_OK; ++k)
        r = sw_sg_trim_flatten_loop(f->scene, rec->first_loop + k, tol, MAX_TRIM_LOOP_VERTICES,
                                    &loops[k], status);
    if (r == SW_OK && id < 0) {
        r = sw__gpu_atlas_add(f->ctx, &key, w, h, loops, rec->n_loops, &id, status);
        f->draws[t->draw].trim_entry = id;
    }
    for (uint32_t k = 0; k < rec->n_loops && r == SW_OK && border; ++k)
        r = sw__fr_fat_border(f, &f->occ[t->occ], loops[k].uv, loops[k].count,
                              sw__fr_left_is_inside(loops, rec->n_loops, k), t->cell, NULL, 0,
                              status);
    for (uint32_t k = 0; k < rec->n_loops; ++k)
        sw_sg_polyline_free(&loops[k]);
    sw__free(loops);
    return r;
}

/* Atlas texels the frame's trims take at `scale`: their classes' footprints, gutters included. */
static double trim_footprint(const frame *f, double scale)
{
    const int32_t max_entry = sw__gpu_atlas_max_entry(f->ctx), g2 = 2 * SW__GPU_ATLAS_GUTTER;
    double sum = 0.0;
    for (size_t i = 0; i < f->n_trims; ++i)
        sum += (double)(sw__fr_class_texels(f->trims[i].width * scale, max_entry) + g2) *
               (double)(sw__fr_class_texels(f->trims[i].height * scale, max_entry) + g2);
    return sum;
}

/* The common scale of the wanted trim resolutions that keeps the frame's atlas footprints within
 * k_max_frame_texels. The wanted texels alone are no bound: rounding up to classes and the gutters
 * make the footprints up to ~4x larger (a 10^6-surface building wanted 3.4e8 texels, scaled to the
 * budget, and still needed 5.7e8, more than the atlas holds). Each step shrinks the scale by at
 * least 10 %; when every trim is at the smallest class the footprints cannot shrink further and the
 * atlas reports the overflow. */
static double trim_scale(const frame *f)
{
    double total = 0.0;
    for (size_t i = 0; i < f->n_trims; ++i)
        total += f->trims[i].width * f->trims[i].height;
    double scale = total > k_max_frame_texels ? sqrt(k_max_frame_texels / total) : 1.0;
    for (int step = 0; step < 64; ++step) {
        const double foot = trim_footprint(f, scale);
        if (foot <= k_max_frame_texels)
            break;
        scale *= fmin(0.9, sqrt(k_max_frame_texels / foot));
    }
    return scale;
}

/* Trim textures for every drawn trimmed face through the atlas (§4.4), scaled down together if
 * over the frame budget. */
static sw_result make_trims(frame *f, sw_status *status)
{
    const double scale = trim_scale(f);
    sw_result r = sw__gpu_atlas_begin(f->ctx, status);
    for (size_t i = 0; i < f->n_trims && r == SW_OK; ++i)
        r = make_trim(f, &f->trims[i], scale, status);
    sw__gpu_atlas_stats as;
    memset(&as, 0, sizeof as);
    if (r == SW_OK)
        r = sw__gpu_atlas_commit(f->ctx, &as, status);
    for (size_t i = 0; i < f->n_shares; ++i)
        f->draws[f->shares[2 * i]].trim_entry = f->draws[f->shares[2 * i + 1]].trim_entry;
    f->st.trim_textures = as.entries;
    f->st.trim_texels = as.entry_texels;
    f->st.trim_reused = as.reused;
    f->st.atlas_pages = as.pages;
    f->st.atlas_texels = (uint64_t)as.pages * (uint64_t)as.side * (uint64_t)as.side;
    f->st.atlas_switches = as.switches;
    glFinish();
    return r;
}

/* Fills the records' colour and trim rectangle from their draws (trim entries are known after the
 * atlas commit) and sorts them by grid class into ctx->recs_sorted (counting sort). */
static sw_result build_batch(frame *f, sw_status *status)
{
    sw_gpu_context *ctx = f->ctx;
    sw__gpu_patch_batch *b = &f->batch;
    memset(b, 0, sizeof *b);
    if (f->n_recs == 0)
        return SW_OK;
    if (!sw__gpu_grow((void **)&ctx->recs_sorted, &ctx->cap_recs_sorted, f->n_recs,
                      sizeof *ctx->recs_sorted))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    for (size_t i = 0; i < f->n_recs; ++i) {
        sw__gpu_patch_rec *rec = &f->recs[i];
        const sw__gpu_draw *d = &f->draws[rec->draw];
        memcpy(rec->color, d->color, sizeof rec->color);
        if (d->trim_entry >= 0) {
            sw__gpu_trim_rect tr;
            sw__gpu_atlas_rect(ctx, d->trim_entry, &tr);
            rec->trim_rect[0] = (float)tr.x0;
            rec->trim_rect[1] = (float)tr.y0;
            rec->trim_rect[2] = (float)tr.w;
            rec->trim_rect[3] = (float)tr.h;
            rec->layer = (float)tr.layer;
        }
        b->count[rec->level_v][rec->level_u]++;
    }
    uint32_t at = 0, next[SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    for (int v = 0; v < SW__GPU_GRID_CLASSES; ++v)
        for (int u = 0; u < SW__GPU_GRID_CLASSES; ++u) {
            b->first[v][u] = next[v][u] = at;
            at += b->count[v][u];
        }
    int keep = ctx->capture_max > 0;
    if (keep && !sw__gpu_grow((void **)&ctx->rec_source, &ctx->cap_rec_source, f->n_recs,
                              sizeof *ctx->rec_source))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    for (size_t i = 0; i < f->n_recs; ++i) {
        const sw__gpu_patch_rec *rec = &f->recs[i];
        uint32_t slot = next[rec->level_v][rec->level_u]++;
        ctx->recs_sorted[slot] = *rec;
        if (keep)
            ctx->rec_source[slot] = (uint32_t)i;
    }
    b->recs = ctx->recs_sorted;
    b->n_recs = f->n_recs;
    b->cps = f->cps;
    b->n_cps = f->n_cps;
    b->exact = f->exact;
    b->pieces = f->pieces;
    b->n_pieces = f->n_pieces;
    b->knots = f->knots;
    b->n_knots = f->n_knots;
    b->dcps = f->dcps;
    b->n_dcps = f->n_dcps;
    return SW_OK;
}

void sw__gpu_set_eval_mode(sw_gpu_context *ctx, sw__gpu_eval_mode mode)
{
    ctx->eval_mode = (int32_t)mode;
}

static void frame_free(frame *f)
{
    if (f->bez) {
        for (uint32_t i = 0; i < f->sv->n_faces; ++i) {
            if (f->bez[i]) {
                sw_sg_bezier_set_free(f->bez[i]);
                sw__free(f->bez[i]);
            }
        }
    }
    sw__free(f->bez);
    sw__free(f->occ);
    sw__free(f->draws);
    sw__free(f->trims);
    for (size_t i = 0; i < f->n_loops; ++i) {
        for (uint32_t k = 0; k < f->loops[i].n; ++k)
            sw_sg_polyline_free(&f->loops[i].loops[k]);
        sw__free(f->loops[i].loops);
    }
    sw__free(f->loops);
    sw__free(f->pieces);
    sw__free(f->knots);
    sw__free(f->dcps);
    sw__free(f->shares);
    sw__free(f->recs);
    sw__free(f->cps);
    sw__gpu_mesh_free(&f->mesh);
}

/* Visibility, selection and tessellation of a frame are GL-free (the plan is plain memory),
 * so that the visibility thread can run them for frame i+1 while the submitting thread draws
 * frame i (Kumar et al. 1997 §5.2). */
struct sw_gpu_frame_plan {
    frame f;
    sw_gpu_frame_desc desc;
    double ms_prepare;
};

static void plan_release_reader(sw_gpu_frame_plan *p)
{
    frame *f = &p->f;
    if (!f->cache || f->reader < 0)
        return;
    sw_lod_cache_reader_leave(f->cache, f->reader);
    sw_lod_cache_reader_remove(f->cache, f->reader);
    f->reader = -1;
}

void sw_gpu_frame_plan_free(sw_gpu_frame_plan *plan)
{
    if (!plan)
        return;
    plan_release_reader(plan);
    frame_free(&plan->f);
    sw__free(plan);
}

double sw_gpu_frame_plan_ms(const sw_gpu_frame_plan *plan)
{
    return plan->ms_prepare;
}

static sw_result plan_init(sw_gpu_frame_plan *p, sw_gpu_context *ctx, const sw_sg_scene *scene,
                           sw_status *status)
{
    frame *f = &p->f;
    f->ctx = ctx;
    f->scene = scene;
    f->sv = sw_sg_scene_view_ptr(scene);
    f->eps_px = p->desc.error_px;
    f->exact = p->desc.eval_exact != 0;
    f->reader = -1;
    f->walkthrough = p->desc.walkthrough != 0;
    f->statics = p->desc.static_lods;
    f->static_force = p->desc.static_force;
    f->lod_colors = p->desc.lod_colors != 0;
    if (f->statics && sw_lod_static_set_scene(f->statics) != scene)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: the static LODs belong to another scene");
    f->bez = sw__calloc(f->sv->n_faces ? f->sv->n_faces : 1, sizeof *f->bez);
    if (!f->bez)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame: out of memory");
    if (!p->desc.hierarchies)
        return SW_OK;
    if (sw_lod_cache_scene(p->desc.hierarchies) != scene)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: the hierarchy cache belongs to another scene");
    f->cache = p->desc.hierarchies;
    /* A slot per plan: the plans of two overlapping frames are read at the same time. */
    f->reader = sw_lod_cache_reader_add(f->cache);
    if (f->reader < 0)
        return sw__fail(status, SW_ERR_LIMIT, "frame: no free reader slot in the cache");
    sw_lod_cache_reader_enter(f->cache, f->reader);
    return SW_OK;
}

sw_result sw_gpu_frame_prepare(sw_gpu_context *ctx, const sw_sg_scene *scene,
                               const sw_gpu_frame_desc *desc, sw_gpu_frame_plan **out,
                               sw_status *status)
{
    *out = NULL;
    double t0 = sw__gpu_now_ms();
    sw_gpu_frame_plan *p = sw__calloc(1, sizeof *p);
    if (!p)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame: out of memory");
    sw__gpu_desc_defaults(desc, &p->desc);
    sw_result r = plan_init(p, ctx, scene, status);
    if (r == SW_OK)
        r = tessellate(&p->f, &p->desc, status);
    if (r != SW_OK) {
        sw_gpu_frame_plan_free(p);
        return r;
    }
    p->ms_prepare = sw__gpu_now_ms() - t0;
    p->f.st.ms_tessellate = p->ms_prepare - p->f.st.ms_hierarchy; /* the waits are counted apart */
    *out = p;
    return SW_OK;
}

sw_result sw_gpu_frame_submit(sw_gpu_context *ctx, sw_gpu_frame_plan *plan, sw_gpu_image *out,
                              sw_gpu_frame_stats *stats, sw_status *status)
{
    memset(out, 0, sizeof *out);
    sw__gpu_make_current(ctx);
    frame *f = &plan->f;
    const sw_gpu_frame_desc *desc = &plan->desc;
    sw_result r = f->ctx == ctx ? SW_OK
                                : sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                                           "frame: the plan was prepared for another context");
    sw__gpu_host_state host;
    const int host_state = desc->present || sw__gpu_context_adopted(ctx);
    if (host_state)
        sw__gpu_host_state_save(&host);
    double t1 = sw__gpu_now_ms();
    /* GPU time of the trim textures and the draw, by two GL_TIMESTAMP queries (the second one
     * is after the draw's glFinish, so its result is there without a wait of its own). A
     * GL_TIME_ELAPSED query gave 7.5e6 ms for the first frame of a context on llvmpipe. */
    GLuint query[2] = {0, 0};
    glGenQueries(2, query);
    glQueryCounter(query[0], GL_TIMESTAMP);
    if (r == SW_OK)
        r = make_trims(f, status);
    double t2 = sw__gpu_now_ms();
    if (r == SW_OK)
        r = build_batch(f, status);
    if (r == SW_OK)
        r = sw__gpu_draw_frame(ctx, &f->view, desc, &f->mesh, f->draws, f->n_draws, &f->batch,
                               status);
    glQueryCounter(query[1], GL_TIMESTAMP);
    GLuint64 ns[2] = {0, 0};
    glGetQueryObjectui64v(query[0], GL_QUERY_RESULT, &ns[0]);
    glGetQueryObjectui64v(query[1], GL_QUERY_RESULT, &ns[1]);
    glDeleteQueries(2, query);
    f->st.ms_gpu = ns[1] > ns[0] ? 1e-6 * (double)(ns[1] - ns[0]) : 0.0;
    double t3 = sw__gpu_now_ms();
    if (r == SW_OK && desc->present)
        r = sw__gpu_present(ctx, &f->view, desc->present_depth, &host, status);
    if (r == SW_OK && !desc->no_readback)
        r = sw__gpu_readback(ctx, &f->view, desc->want_depth, out, status);
    if (host_state)
        sw__gpu_host_state_restore(&host);
    double t4 = sw__gpu_now_ms();

    f->st.triangles += f->mesh.n_idx / 3 - f->border_triangles;
    f->st.ms_trim = t2 - t1;
    f->st.ms_draw = t3 - t2;
    f->st.ms_readback = t4 - t3;
    f->st.near_plane = f->view.near_plane;
    if (stats)
        *stats = f->st;
    sw_lod_cache *cache = f->cache;
    plan_release_reader(plan);
    if (cache)
        sw_lod_cache_collect(cache);
    sw_gpu_frame_plan_free(plan);
    if (r == SW_OK)
        sw__status_ok(status);
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

/* SPDX-License-Identifier: MIT */
/* The tessellate stage for a face's hierarchy cut (Guthe et al. 2005 §7; the cut is chosen by
 * stage_hierarchy.c).
 *
 * The error budget of a drawn node is rigorous, not the paper's 50/50 guess: the node's bound e
 * (distance between the exact surface and the bicubic at the same parameters,
 * lod/bezier/error_bound.c) projects to at most e_px = ε_img e / ε_obj(z_min) pixels, and the grid
 * density is chosen for the rest, ε_img - e_px (sw_lod_screen_segments, which bounds the grid
 * against the bicubic on screen). Each drawn node gets its own trim texture over its rectangle when
 * the face's one texture would be too large (nodes wholly inside the trimmed region need none;
 * nodes outside it are not drawn) and, when the face is drawn as more than one node, a fat border
 * along its rectangle, since neighbouring nodes are different bicubics sampled at different
 * densities (§7.1); the border carries the node's trim lookup, so that it does not show in
 * trimmed-away parts. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* One face occurrence's cut being drawn. */
typedef struct hl_face {
    sw__fr_tess *f;
    const occurrence *o;
    hl_choice *chosen; /* the cut (a copy: the trim needs are tightened per item, and an item
                          whose grid the segment limit caps is replaced by its halves) */
    size_t n_chosen, cap_chosen;
    int trimmed;
} hl_face;

/* ---- exact degree of a node's bicubic ----------------------------------------------------------
 * Planes, cylinders and cones reach the hierarchy as degree-elevated bicubics. Their derivative
 * bounds (lod/bezier/sampling.c, products of degree 3p x 3q) cost ~6x more at degree 3 than at the
 * true degree, and the bound is the same surface's: so the density is computed at the lowest degree
 * that reproduces the net exactly (up to rounding). */
static int near(const double *a, const double *b, double tol)
{
    for (int k = 0; k < 4; ++k)
        if (!(fabs(a[k] - b[k]) <= tol))
            return 0;
    return 1;
}

/* The cubic row (4 homogeneous points, stride `st` doubles) as a row of degree d (1 or 2) when it
 * is one exactly (within tol): out gets d + 1 points; returns 0 when it is not. Elevation from
 * degree 2: P0 = Q0, P1 = (Q0 + 2 Q1) / 3, P2 = (2 Q1 + Q2) / 3, P3 = Q2; from degree 1 the inner
 * points sit at the thirds. */
static int row_at_degree(const double *p, size_t st, int d, double tol, double *out)
{
    const double *p0 = p, *p1 = p + st, *p2 = p + 2 * st, *p3 = p + 3 * st;
    double a[4], b[4], q1[4];
    for (int k = 0; k < 4; ++k) {
        q1[k] = 0.5 * (3.0 * p1[k] - p0[k]);
        a[k] = d == 1 ? (2.0 * p0[k] + p3[k]) / 3.0 : p1[k];
        b[k] = d == 1 ? (p0[k] + 2.0 * p3[k]) / 3.0 : (2.0 * q1[k] + p3[k]) / 3.0;
    }
    if (!near(a, p1, tol) || !near(b, p2, tol))
        return 0;
    memcpy(out, p0, 4 * sizeof *out);
    if (d == 2)
        memcpy(out + 4, q1, sizeof q1);
    memcpy(out + 4 * d, p3, 4 * sizeof *out);
    return 1;
}

/* The lowest d in {1, 2} at which every one of n rows (start i * row_st, point stride st) is
 * exact, or 3. */
static int rows_degree(const double *p, int n, size_t row_st, size_t st, double tol)
{
    double scratch[12];
    for (int d = 1; d <= 2; ++d) {
        int all = 1;
        for (int i = 0; i < n && all; ++i)
            all = row_at_degree(p + (size_t)i * row_st, st, d, tol, scratch);
        if (all)
            return d;
    }
    return 3;
}

/* The net at its lowest exact degrees (*du, *dv <= 3) into low ((du+1)(dv+1) points, u fastest). */
static void lowest_degree(const double cpw[64], double low[64], int32_t *du, int32_t *dv)
{
    double scale = 0.0;
    for (int i = 0; i < 64; ++i)
        scale = fmax(scale, fabs(cpw[i]));
    const double tol = 1e-12 * scale;
    const int d = rows_degree(cpw, 4, 16, 4, tol); /* u: the 4 rows */
    double tmp[64];
    for (int j = 0; j < 4; ++j) {
        if (d == 3)
            memcpy(tmp + 16 * j, cpw + 16 * j, 16 * sizeof *tmp);
        else
            row_at_degree(cpw + 16 * j, 4, d, tol, tmp + 4 * (d + 1) * j);
    }
    const size_t row = 4 * (size_t)(d + 1);             /* doubles per row of tmp */
    const int e = rows_degree(tmp, d + 1, 4, row, tol); /* v: the d + 1 columns */
    for (int i = 0; i <= d; ++i) {
        double col[16];
        if (e == 3)
            for (int j = 0; j < 4; ++j)
                memcpy(col + 4 * j, tmp + row * j + 4 * i, 4 * sizeof *col);
        else
            row_at_degree(tmp + 4 * i, row, e, tol, col);
        for (int j = 0; j <= e; ++j)
            memcpy(low + row * j + 4 * i, col + 4 * j, 4 * sizeof *col);
    }
    *du = d;
    *dv = e;
}

/* Halvings of an item whose grid reaches the segment limit (2^8 x the limit per direction), or
 * whose float evaluation error takes more than a quarter of ε_img; and the items a face may be
 * drawn as once halved (the selection's own cap, stage_hierarchy.c): past either, an item is drawn
 * as it is and counted. */
enum { MAX_GRID_SPLITS = 8, MAX_HALVED_ITEMS = 16384 };

/* The eye-relative box of an item's control points (its surface's, for positive weights). */
static void item_box(const hl_choice *c, double box[6])
{
    sw__fr_box_empty(box);
    for (int i = 0; i < 16; ++i)
        sw__fr_box_add(box, c->cpw + 4 * i);
}

/* ---- drawing the chosen items ------------------------------------------------------------------
 */
/* The item as a patch of the direct path: clipped to the face's trim box, density for what its
 * approximation and float errors leave of ε_img. Returns the directions (bit 0: u, bit 1: v) in
 * which to halve it (its density capped by the segment limit, or its float error too large), 0
 * when the grid keeps the bound. */
static int item_patch(const hl_face *hf, hl_choice *c, sw__gpu_patch *pt)
{
    sw__fr_tess *f = hf->f;
    const double *ub = f->env->sv->faces[hf->o->face].uv_box;
    memset(pt, 0, sizeof *pt);
    pt->deg_u = pt->deg_v = 3;
    pt->cpw = c->cpw;
    pt->cpo = c->cpo;
    for (int k = 0; k < 3; ++k) /* nodes share no edges bit for bit: each its own centre */
        pt->centre[k] = c->cpo[k] / c->cpo[3];
    pt->u0 = c->rect[0];
    pt->u1 = c->rect[1];
    pt->v0 = c->rect[2];
    pt->v1 = c->rect[3];
    double du = pt->u1 - pt->u0, dv = pt->v1 - pt->v0;
    pt->s0 = fmax(0.0, (ub[0] - pt->u0) / du);
    pt->s1 = fmin(1.0, (ub[1] - pt->u0) / du);
    pt->t0 = fmax(0.0, (ub[2] - pt->v0) / dv);
    pt->t1 = fmin(1.0, (ub[3] - pt->v0) / dv);
    pt->nu = pt->nv = 1;
    if (!(pt->s1 > pt->s0) || !(pt->t1 > pt->t0))
        return 0;
    pt->visible = 1;
    double box[6];
    item_box(c, box);
    /* ε_img less the approximation's error and the float evaluation's; the float error shrinks
     * with the item (it follows its control points' distance from the eye): an item where it
     * takes more than a quarter of ε_img and leaves less than a quarter is halved instead, as a
     * capped grid is */
    const double approx_px = f->env->eps_px * c->err_w / c->eps_obj;
    const double float_px = sw__fr_float_error_px(f->env, c->cpw, 16, box);
    if (approx_px + float_px > 0.75 * f->env->eps_px && float_px > 0.25 * f->env->eps_px &&
        c->grid_splits < MAX_GRID_SPLITS && hf->n_chosen + 3 <= MAX_HALVED_ITEMS)
        return 3;
    sw_lod_screen_view scr;
    sw__fr_screen_less(f, approx_px + float_px, &scr);
    const double range[4] = {pt->s0, pt->s1, pt->t0, pt->t1};
    double low[64];
    int32_t deg_u, deg_v;
    lowest_degree(c->cpw, low, &deg_u, &deg_v);
    sw_lod_screen_density d;
    const int kept = sw_lod_screen_segments(deg_u, deg_v, low, range, &scr, f->env->gpu_segments.n,
                                            f->env->gpu_segments.count, MAX_BOUND_SUBDIVISION, &d);
    const int32_t most = f->env->gpu_segments.n[f->env->gpu_segments.count - 1];
    pt->eps = d.eps_obj;
    pt->nu = d.nu;
    pt->nv = d.nv;
    if (hf->trimmed) { /* tighter than the node's constants: bounds of this range, at full ε_img */
        double eps_t = d.eps_obj * f->env->eps_px / scr.eps_px;
        c->need.u = sw_lod_trim_texels(1.0, d.d1[0], 1.0, eps_t); /* over the item */
        c->need.v = sw_lod_trim_texels(1.0, d.d1[1], 1.0, eps_t);
    }
    if (kept)
        return 0;
    const int dirs = (d.nu >= most ? 1 : 0) | (d.nv >= most ? 2 : 0);
    return dirs ? dirs : 3; /* not kept below the limit (the derivative bounds): both */
}

/* The item halved in the capped directions (bit 0: u, bit 1: v): the same bicubic restricted to
 * each piece, with the same error bound and tolerance (its nearest depth is no nearer than the
 * whole item's). The pieces are drawn as items of their own, joined by fat borders as nodes are
 * (§7.1), each grid within the limit where the whole one was capped. Writes 2 or 4 pieces. */
static int halve_item(const hl_choice *c, int dirs, hl_choice out[4])
{
    const int nu = dirs & 1 ? 2 : 1, nv = dirs & 2 ? 2 : 1;
    for (int b = 0; b < nv; ++b)
        for (int a = 0; a < nu; ++a) {
            const double r[4] = {(double)a / nu, (double)(a + 1) / nu, (double)b / nv,
                                 (double)(b + 1) / nv};
            hl_choice *p = &out[b * nu + a];
            *p = *c;
            sw_lod_bez_restrict(3, 3, 4, c->cpw, r, p->cpw);
            sw_lod_bez_restrict(3, 3, 4, c->cpo, r, p->cpo);
            const double du = c->rect[1] - c->rect[0], dv = c->rect[3] - c->rect[2];
            const double iu = c->it.range[1] - c->it.range[0], iv = c->it.range[3] - c->it.range[2];
            p->rect[0] = c->rect[0] + du * r[0];
            p->rect[1] = a + 1 == nu ? c->rect[1] : c->rect[0] + du * r[1];
            p->rect[2] = c->rect[2] + dv * r[2];
            p->rect[3] = b + 1 == nv ? c->rect[3] : c->rect[2] + dv * r[3];
            p->it.range[0] = c->it.range[0] + iu * r[0];
            p->it.range[1] = a + 1 == nu ? c->it.range[1] : c->it.range[0] + iu * r[1];
            p->it.range[2] = c->it.range[2] + iv * r[2];
            p->it.range[3] = b + 1 == nv ? c->it.range[3] : c->it.range[2] + iv * r[3];
            p->grid_splits = c->grid_splits + 1;
        }
    return nu * nv;
}

/* Whether a piece of an item is in view, by the selection's rule (stage_hierarchy.c): the box of
 * its control points grown by its error bound. A piece behind the eye is not drawn (nor its fat
 * border, whose screen-space ribbon would be meaningless there). */
static int piece_visible(const sw__fr_env *env, const hl_choice *c)
{
    double box[6];
    item_box(c, box);
    for (int k = 0; k < 3; ++k) {
        box[k] -= c->err_w;
        box[3 + k] += c->err_w;
    }
    return sw__gpu_view_box_visible(&env->view, box);
}

/* The items' patches; an item whose grid the segment limit caps is replaced by its halves in view
 * (up to MAX_GRID_SPLITS times; at that depth it is drawn capped and counted: the bound is not
 * kept). */
static sw_result item_patches(hl_face *hf, sw__gpu_patch **pts, size_t *cap_pts, size_t *cap_chosen,
                              sw_status *status)
{
    for (size_t i = 0; i < hf->n_chosen;) {
        if (!sw__grow((void **)pts, cap_pts, hf->n_chosen, sizeof **pts))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", hf->o->face);
        const int capped = item_patch(hf, &hf->chosen[i], &(*pts)[i]);
        if (!capped) {
            i++;
            continue;
        }
        if (hf->chosen[i].grid_splits >= MAX_GRID_SPLITS || hf->n_chosen + 3 > MAX_HALVED_ITEMS) {
            hf->f->st->bound_exceeded++; /* capped at the largest grid: the bound is not kept */
            i++;
            continue;
        }
        if (!sw__grow((void **)&hf->chosen, cap_chosen, hf->n_chosen + 3, sizeof *hf->chosen))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", hf->o->face);
        hl_choice pieces[4];
        const int n = halve_item(&hf->chosen[i], capped, pieces);
        hf->chosen[i] = hf->chosen[--hf->n_chosen]; /* i is looked at again */
        for (int k = 0; k < n; ++k) {
            if (piece_visible(hf->f->env, &pieces[k]))
                hf->chosen[hf->n_chosen++] = pieces[k];
            else
                hf->f->st->patches_culled++;
        }
    }
    /* a patch points at its item's control points, which growing the items may have moved */
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        (*pts)[i].cpw = hf->chosen[i].cpw;
        (*pts)[i].cpo = hf->chosen[i].cpo;
    }
    return SW_OK;
}

static void item_cell(const sw__gpu_patch *pt, double cell[2])
{
    cell[0] = (pt->u1 - pt->u0) * (pt->s1 - pt->s0) / pt->nu;
    cell[1] = (pt->v1 - pt->v0) * (pt->t1 - pt->t0) / pt->nv;
}

/* Trim class of the item against the face's loops: 1 inside, -1 outside, 0 crossing (a margin of
 * 1 % so that a loop on its edge counts as crossing). */
static int item_class(const face_loops *fl, const double r[4])
{
    double mu = 0.01 * (r[1] - r[0]), mv = 0.01 * (r[3] - r[2]);
    const double g[4] = {r[0] - mu, r[1] + mu, r[2] - mv, r[3] + mv};
    return sw__gpu_trim_rect_class(fl->loops, fl->n, g);
}

static void count_item(hl_face *hf, const sw__gpu_patch *pt, int on_gpu, int trimmed)
{
    sw__fr_tess *f = hf->f;
    if (!on_gpu && f->env->ctx->patch_hook)
        sw__fr_report_patch(f, hf->o, pt, pt->s0, pt->s1, pt->t0, pt->t1, pt->nu, pt->nv, 0,
                            trimmed);
    f->st->hlod_nodes++;
    f->st->patches_gpu_evaluated += (uint64_t)on_gpu;
    *(trimmed ? &f->st->patches_trimmed : &f->st->patches_untrimmed) += 1;
}

/* §7.1 between nodes of one face: a fat border along the item's rectangle (counter-clockwise),
 * trimmed by the texture of draw `share` over st_box when given. */
static sw_result item_border(hl_face *hf, const hl_choice *c, const double cell[2],
                             const double *st_box, size_t share, sw_status *status)
{
    return sw__fr_rect_border(hf->f, hf->o, c->rect, cell, st_box, share, status);
}

/* Per-item trim textures (a face whose one texture would be too large): the item's own draw,
 * trimmed over its rectangle when a loop crosses it, untrimmed when inside, nothing when outside.
 */
static sw_result draw_item_own(hl_face *hf, hl_choice *c, const sw__gpu_patch *pt, int64_t loops,
                               double sign, int on_gpu, sw_status *status)
{
    sw__fr_tess *f = hf->f;
    int cls = item_class(&f->geo->loops[loops], c->rect);
    if (cls < 0)
        return SW_OK;
    int trimmed = cls == 0;
    double cell[2];
    item_cell(pt, cell);
    size_t draw = f->geo->n_draws, first = f->geo->mesh.n_idx;
    sw_result r;
    if (on_gpu) {
        r = sw__fr_add_draw(f, hf->o, first, trimmed, &c->need, cell, status);
        if (r == SW_OK)
            r = sw__fr_gpu_patch(f, hf->o, pt, c->rect, sign, (int32_t)draw, trimmed, status);
    } else {
        r = sw__gpu_tessellate_face(pt, 1, 1, sign, c->rect, &f->geo->mesh, status);
        if (r == SW_OK)
            r = sw__fr_add_draw(f, hf->o, first, trimmed, &c->need, cell, status);
    }
    if (r == SW_OK && trimmed) {
        pending_trim *t = &f->geo->trims[f->geo->n_trims - 1];
        t->loops = loops;
        t->clip = 1;
        memcpy(t->rect, c->rect, sizeof t->rect);
    }
    count_item(hf, pt, on_gpu, trimmed);
    if (r == SW_OK && hf->n_chosen > 1 && !f->env->ctx->crack_fill_off)
        r = item_border(hf, c, cell, trimmed ? c->rect : NULL, draw, status);
    return r;
}

/* The loops' flattening tolerance: the finest of the chosen items' (sw__fr_trim_flat_tol). Slivers
 * (sw__fr_sliver) are skipped, as in the border's cell: a span of 7e-16 flattened a loop into
 * 748k vertices. */
static double loop_tolerance(const hl_face *hf)
{
    int32_t max_entry = sw__gpu_atlas_max_entry(hf->f->env->ctx);
    const double *ub = hf->f->env->sv->faces[hf->o->face].uv_box;
    double tol = INFINITY, all = INFINITY;
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        const hl_choice *c = &hf->chosen[i];
        const double w[2] = {c->rect[1] - c->rect[0], c->rect[3] - c->rect[2]};
        const int exact = sw__fr_exact_edges(hf->f->env, c->need.u, c->need.v, max_entry);
        const double flat[2] = {
            sw__fr_trim_flat_tol(hf->f->env, w[0], c->need.u, exact, max_entry),
            sw__fr_trim_flat_tol(hf->f->env, w[1], c->need.v, exact, max_entry)};
        for (int d = 0; d < 2; ++d) {
            all = fmin(all, flat[d]);
            if (!sw__fr_sliver(w[d], ub[2 * d + 1] - ub[2 * d]))
                tol = fmin(tol, flat[d]);
        }
    }
    return tol < INFINITY ? tol : all;
}

static sw_result draw_own_textures(hl_face *hf, sw__gpu_patch *pts, double sign, int on_gpu,
                                   const double cell_min[2], sw_status *status)
{
    sw__fr_tess *f = hf->f;
    int64_t loops = -1;
    sw_result r = sw__fr_face_loops(f, hf->o->face, loop_tolerance(hf), &loops, status);
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK; ++i)
        if (pts[i].visible)
            r = draw_item_own(hf, &hf->chosen[i], &pts[i], loops, sign, on_gpu, status);
    if (r == SW_OK)
        r = sw__fr_loop_borders(f, hf->o, loops, cell_min, status);
    return r;
}

/* One draw for the whole face (one trim texture over its trim box, as the direct path). */
static sw_result draw_one_texture(hl_face *hf, sw__gpu_patch *pts, double sign, int on_gpu,
                                  const trim_need *need, const double cell_min[2],
                                  sw_status *status)
{
    sw__fr_tess *f = hf->f;
    const double *ub = f->env->sv->faces[hf->o->face].uv_box;
    size_t draw = f->geo->n_draws, first = f->geo->mesh.n_idx;
    sw_result r =
        on_gpu ? sw__fr_add_draw(f, hf->o, first, hf->trimmed, need, cell_min, status) : SW_OK;
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK; ++i) {
        if (!pts[i].visible)
            continue;
        r = on_gpu
                ? sw__fr_gpu_patch(f, hf->o, &pts[i], ub, sign, (int32_t)draw, hf->trimmed, status)
                : sw__gpu_tessellate_face(&pts[i], 1, 1, sign, ub, &f->geo->mesh, status);
        count_item(hf, &pts[i], on_gpu, hf->trimmed);
    }
    if (r == SW_OK && !on_gpu)
        r = sw__fr_add_draw(f, hf->o, first, hf->trimmed, need, cell_min, status);
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK && hf->n_chosen > 1; ++i) {
        double cell[2];
        item_cell(&pts[i], cell);
        if (pts[i].visible && !f->env->ctx->crack_fill_off)
            r = item_border(hf, &hf->chosen[i], cell, hf->trimmed ? ub : NULL, draw, status);
    }
    if (r == SW_OK && !hf->trimmed && !f->env->ctx->crack_fill_off) {
        /* a trimmed face's loops get theirs with its trim texture (the trim plan, stage_trim.c) */
        r = sw__fr_box_border(f, hf->o, cell_min, status);
    }
    return r;
}

/* Texels of one texture over the face's trim box that serve every chosen item. */
static trim_need face_need(const hl_face *hf, const sw__gpu_patch *pts)
{
    const double *ub = hf->f->env->sv->faces[hf->o->face].uv_box;
    trim_need n = {1.0, 1.0};
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        const hl_choice *c = &hf->chosen[i];
        if (!pts[i].visible)
            continue;
        const double wu = c->rect[1] - c->rect[0], wv = c->rect[3] - c->rect[2];
        if (!sw__fr_sliver(wu, ub[1] - ub[0])) /* a sliver's texel would ask 1e8 over the box */
            n.u = fmax(n.u, c->need.u * (ub[1] - ub[0]) / wu);
        if (!sw__fr_sliver(wv, ub[3] - ub[2]))
            n.v = fmax(n.v, c->need.v * (ub[3] - ub[2]) / wv);
    }
    return n;
}

static sw_result draw_chosen(hl_face *hf, sw_status *status)
{
    sw__fr_tess *f = hf->f;
    const occurrence *o = hf->o;
    const double sign = sw__fr_normal_sign(f->env, o);
    int on_gpu = f->env->ctx->eval_mode == SW__GPU_EVAL_AUTO;
    sw__gpu_patch *pts = NULL;
    size_t cap_pts = 0;
    sw_result r = item_patches(hf, &pts, &cap_pts, &hf->cap_chosen, status);
    if (r != SW_OK) {
        sw__free(pts);
        return r;
    }
    double cell[2];
    if (sw__fr_grid_cell(pts, hf->n_chosen, f->env->sv->faces[o->face].uv_box, cell) > 0) {
        trim_need need = face_need(hf, pts);
        r = hf->trimmed && (need.u > k_tile_texels || need.v > k_tile_texels)
                ? draw_own_textures(hf, pts, sign, on_gpu, cell, status)
                : draw_one_texture(hf, pts, sign, on_gpu, &need, cell, status);
        f->st->faces_drawn++;
    } else {
        f->st->faces_culled++;
    }
    sw__free(pts);
    return r;
}

sw_result sw__fr_tess_hierarchy(sw__fr_tess *f, const occurrence *o, const hl_choice *items,
                                size_t n, sw_status *status)
{
    hl_face hf = {f, o,         sw__malloc((n ? n : 1) * sizeof *items),
                  n, n ? n : 1, sw__fr_face_trimmed(f->env, o->face)};
    if (!hf.chosen)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    memcpy(hf.chosen, items, n * sizeof *items);
    sw_result r = draw_chosen(&hf, status);
    sw__free(hf.chosen);
    return r;
}

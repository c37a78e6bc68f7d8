/* SPDX-License-Identifier: MIT */
/* The tessellate stage's direct path: a face occurrence by its own rational Bézier patches
 * (Guthe et al. 2005 §4.2, without the bicubic hierarchy): each patch culled by its control-net
 * box, its grid density chosen so that its triangles stay within ε_img on screen (§5.2 and §7 in
 * one rigorous bound, lod/bezier/sampling.c's sw_lod_screen_segments, over the grid classes'
 * segment counts), densities unified per patch column and row so that grids meet vertex to vertex;
 * drawn as vertex-shader records (degree <= 3 x 3), as CPU grids (higher degrees), or, with
 * eval_exact, evaluated from the face's knot vectors. A trimmed face whose trim texture would be
 * too large has its trim box cut into tiles, each with its own texture. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_TILES_PER_DIR = 4096,   /* trim tiles of a face per direction */
    MAX_TILES_PER_FACE = 16384, /* visible trim tiles of one face occurrence (else coarser) */
};

static sw_result face_bezier(sw__fr_tess *f, uint32_t face, const sw_sg_bezier_set **out,
                             sw_status *status)
{
    sw_sg_bezier_set *have = atomic_load_explicit(&f->bez[face], memory_order_acquire);
    if (!have) {
        sw_sg_bezier_set *set = sw__calloc(1, sizeof *set);
        if (!set)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", face);
        const double *b = f->env->sv->faces[face].uv_box;
        sw_sg_surface s;
        sw_sg_scene_face_surface(f->env->scene, face, &s);
        sw_result r = sw_sg_surface_extract_bezier_in(&s, b[0], b[1], b[2], b[3], set, status);
        if (r != SW_OK) {
            sw__free(set);
            return r;
        }
        /* another chunk may have extracted the same face meanwhile: the first one stays */
        if (atomic_compare_exchange_strong_explicit(&f->bez[face], &have, set,
                                                    memory_order_acq_rel, memory_order_acquire)) {
            have = set;
        } else {
            sw_sg_bezier_set_free(set);
            sw__free(set);
        }
    }
    *out = have;
    return SW_OK;
}

/* Sets up one patch: eye-relative control points, clipping to the uv box, culling, density. */
static void patch_setup(sw__fr_tess *f, const occurrence *o, const sw_sg_bezier_patch *bp,
                        const double ub[4], int class_grids, const double f_centre[3], double *cpw,
                        sw__gpu_patch *pt, trim_need *need)
{
    size_t n = (size_t)(bp->deg_u + 1) * (size_t)(bp->deg_v + 1);
    double box[6];
    sw__fr_box_empty(box);
    for (size_t i = 0; i < n; ++i) {
        sw__fr_xform_h(o->world, f->env->view.eye, bp->cpw + 4 * i, cpw + 4 * i);
        sw__fr_box_add(box, cpw + 4 * i);
    }
    memset(pt, 0, sizeof *pt);
    pt->deg_u = bp->deg_u;
    pt->deg_v = bp->deg_v;
    pt->cpw = cpw;
    pt->cpo = bp->cpw;
    memcpy(pt->centre, f_centre, sizeof pt->centre);
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
    if (!(pt->s1 > pt->s0) || !(pt->t1 > pt->t0) || !sw__gpu_view_box_visible(&f->env->view, box))
        return;
    pt->visible = 1;
    const double range[4] = {pt->s0, pt->s1, pt->t0, pt->t1};
    const segment_set *set = class_grids ? &f->env->gpu_segments : &f->env->cpu_segments;
    sw_lod_screen_view scr;
    sw__fr_screen_less(f, sw__fr_float_error_px(f->env, cpw, n, box), &scr);
    sw_lod_screen_density d;
    if (!sw_lod_screen_segments(bp->deg_u, bp->deg_v, cpw, range, &scr, set->n, set->count,
                                MAX_BOUND_SUBDIVISION, &d))
        f->st->bound_exceeded++; /* capped at the largest grid: the bound is not kept */
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

/* GPU evaluation of a face's patches: one draw record for its colour and trim texture, one
 * patch record per visible patch (or piece). */
static sw_result gpu_face(sw__fr_tess *f, const occurrence *o, const sw__gpu_patch *pt, size_t n,
                          double sign, int trimmed, const trim_need *need, const double cell[2],
                          sw_status *status)
{
    int32_t d = (int32_t)f->geo->n_draws;
    sw_result r = sw__fr_add_draw(f, o, f->geo->mesh.n_idx, trimmed, need, cell, status);
    const double *ub = f->env->sv->faces[o->face].uv_box;
    for (size_t p = 0; p < n && r == SW_OK; ++p)
        if (pt[p].visible)
            r = sw__fr_gpu_patch(f, o, &pt[p], ub, sign, d, trimmed, status);
    return r;
}

/* Which path draws a face: the vertex shader takes rational Bézier patches of degree <= 3 x 3
 * (§4.2); higher degrees stay CPU grids (patch_grid.c) until the bicubic hierarchy feeds them. */
static int face_gpu_eligible(const sw_sg_bezier_set *set)
{
    if (set->n_u * set->n_v == 0)
        return 0;
    return set->patches[0].deg_u <= 3 && set->patches[0].deg_v <= 3;
}

static int face_on_gpu(const sw__fr_tess *f, const sw_sg_bezier_set *set)
{
    if (f->env->exact)
        return 1;
    return f->env->ctx->eval_mode == SW__GPU_EVAL_AUTO && face_gpu_eligible(set);
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
    sw__fr_tess *f;
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
    c->visible = sw__gpu_view_box_visible(&t->f->env->view, box);
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
        !sw__grow((void **)&t->tiles, &t->cap_tiles, t->n_tiles + 1, sizeof *t->tiles))
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
    sw__fr_tess *f = t->f;
    patch_span(t->set, 0, tl->rect[0], tl->rect[1], &tl->a0, &tl->a1);
    patch_span(t->set, 1, tl->rect[2], tl->rect[3], &tl->b0, &tl->b1);
    size_t n = (size_t)(tl->a1 - tl->a0 + 1) * (size_t)(tl->b1 - tl->b0 + 1);
    if (!sw__grow((void **)&t->cells, &t->cap_cells, t->n_cells + n, sizeof *t->cells))
        return 0;
    tl->first_cell = t->n_cells;
    tl->need = (trim_need){1.0, 1.0};
    const segment_set *set = t->class_grids ? &f->env->gpu_segments : &f->env->cpu_segments;
    for (int32_t b = tl->b0; b <= tl->b1; ++b)
        for (int32_t a = tl->a0; a <= tl->a1; ++a) {
            sw__gpu_patch *c = &t->cells[t->n_cells++];
            make_cell(t, (size_t)b * (size_t)t->set->n_u + (size_t)a, tl->rect, c);
            c->col = a;
            c->row = b;
            if (!c->visible)
                continue;
            const double range[4] = {c->s0, c->s1, c->t0, c->t1};
            const size_t n_cp = (size_t)(c->deg_u + 1) * (size_t)(c->deg_v + 1);
            double box[6];
            sw__fr_box_empty(box);
            for (size_t i = 0; i < n_cp; ++i)
                sw__fr_box_add(box, c->cpw + 4 * i);
            sw_lod_screen_view scr;
            sw__fr_screen_less(f, sw__fr_float_error_px(f->env, c->cpw, n_cp, box), &scr);
            sw_lod_screen_density d;
            if (!sw_lod_screen_segments(c->deg_u, c->deg_v, c->cpw, range, &scr, set->n, set->count,
                                        MAX_BOUND_SUBDIVISION, &d))
                f->st->bound_exceeded++; /* capped: the bound is not kept */
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

static sw_result tile_loops(tiling *t, int64_t *index, sw_status *status)
{
    sw__fr_tess *f = t->f;
    int32_t max_entry = sw__gpu_atlas_max_entry(f->env->ctx);
    double tol = INFINITY;
    for (size_t i = 0; i < t->n_tiles; ++i) {
        const tile *tl = &t->tiles[i];
        const int exact = sw__fr_exact_edges(f->env, tl->need.u, tl->need.v, max_entry);
        tol = fmin(tol, sw__fr_trim_flat_tol(f->env, tl->rect[1] - tl->rect[0], tl->need.u, exact,
                                             max_entry));
        tol = fmin(tol, sw__fr_trim_flat_tol(f->env, tl->rect[3] - tl->rect[2], tl->need.v, exact,
                                             max_entry));
    }
    sw_result r = sw__fr_face_loops(f, t->o->face, tol, index, status);
    const face_loops *fl = r == SW_OK ? &f->geo->loops[*index] : NULL;
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
    sw__fr_tess *f = t->f;
    int trimmed = tl->cls == 0;
    int32_t n_cols = tl->a1 - tl->a0 + 1, n_rows = tl->b1 - tl->b0 + 1;
    size_t n = (size_t)n_cols * (size_t)n_rows, first = f->geo->mesh.n_idx;
    const sw__gpu_patch *c = t->cells + tl->first_cell;
    int32_t d = (int32_t)f->geo->n_draws;
    sw_result r = SW_OK;
    if (on_gpu) {
        r = sw__fr_add_draw(f, t->o, first, trimmed, &tl->need, cell, status);
        for (size_t p = 0; p < n && r == SW_OK; ++p)
            if (c[p].visible)
                r = sw__fr_gpu_patch(f, t->o, &c[p], tl->rect, sign, d, trimmed, status);
    } else {
        r = sw__gpu_tessellate_face(c, n_cols, n_rows, sign, tl->rect, &f->geo->mesh, status);
        for (size_t p = 0; p < n && f->env->ctx->patch_hook; ++p)
            if (c[p].visible)
                sw__fr_report_patch(f, t->o, &c[p], c[p].s0, c[p].s1, c[p].t0, c[p].t1, c[p].nu,
                                    c[p].nv, 0, trimmed);
        if (r == SW_OK)
            r = sw__fr_add_draw(f, t->o, first, trimmed, &tl->need, cell, status);
    }
    if (r == SW_OK && trimmed) {
        pending_trim *pt = &f->geo->trims[f->geo->n_trims - 1];
        pt->loops = loops;
        pt->clip = 1;
        memcpy(pt->rect, tl->rect, sizeof pt->rect);
    }
    return r;
}

static sw_result tiled_draws(tiling *t, double sign, int on_gpu, sw_status *status)
{
    sw__fr_tess *f = t->f;
    int64_t loops = -1;
    sw_result r = tile_loops(t, &loops, status);
    double cell[2];
    sw__fr_grid_cell(t->cells, t->n_cells, f->env->sv->faces[t->o->face].uv_box, cell);
    for (size_t i = 0; i < t->n_tiles && r == SW_OK; ++i)
        if (t->tiles[i].cls >= 0)
            r = tile_draw(t, &t->tiles[i], loops, sign, on_gpu, cell, status);
    if (r == SW_OK)
        r = sw__fr_loop_borders(f, t->o, loops, cell, status);
    return r;
}

static int32_t tiles_for(double need)
{
    int32_t k = 1;
    while (k < MAX_TILES_PER_DIR && need / k > k_tile_texels)
        k *= 2;
    return k;
}

static sw_result tiled_face(sw__fr_tess *f, const occurrence *o, const sw_sg_bezier_set *set,
                            const sw__gpu_patch *pt, const trim_need *need, double sign, int on_gpu,
                            int class_grids, sw_status *status)
{
    tiling t = {f,
                o,
                set,
                pt,
                f->env->sv->faces[o->face].uv_box,
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

sw_result sw__fr_tess_direct(sw__fr_tess *f, const occurrence *o, sw_status *status)
{
    const sw_sg_face_rec *rec = &f->env->sv->faces[o->face];
    const sw_sg_bezier_set *set = NULL;
    sw_result r = face_bezier(f, o->face, &set, status);
    if (r != SW_OK)
        return r;
    if (f->env->exact) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(f->env->scene, o->face, &s);
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
    int on_gpu = face_on_gpu(f, set);
    /* one centre for the face's kept grids: patches sharing an edge keep bit-identical vertices
     * along it (eval.vert.glsl), as eye-relative ones do */
    double centre[3] = {0.0, 0.0, 0.0};
    if (n > 0)
        for (int k = 0; k < 3; ++k)
            centre[k] = set->patches[0].cpw[k] / set->patches[0].cpw[3];
    /* CPU_GRIDS mode draws the grids the vertex shader would (the reference of §4.2's path). */
    int class_grids = f->env->exact || face_gpu_eligible(set);
    for (size_t p = 0; p < n; ++p) {
        const sw_sg_bezier_patch *bp = &set->patches[p];
        patch_setup(f, o, bp, rec->uv_box, class_grids, centre, cpw + at, &pt[p], &need);
        pt[p].col = (int32_t)(p % (size_t)n_cols);
        pt[p].row = (int32_t)(p / (size_t)n_cols);
        at += (size_t)(bp->deg_u + 1) * (size_t)(bp->deg_v + 1) * 4;
        drawn += (size_t)pt[p].visible;
    }
    f->st->patches_culled += n - drawn;
    const int trimmed = sw__fr_face_trimmed(f->env, o->face);
    if (drawn > 0) {
        unify_densities(pt, n_cols, n_rows);
        const double sign = sw__fr_normal_sign(f->env, o);
        size_t first = f->geo->mesh.n_idx;
        double cell[2];
        sw__fr_grid_cell(pt, n, rec->uv_box, cell);
        if (trimmed && (need.u > k_tile_texels || need.v > k_tile_texels)) {
            r = tiled_face(f, o, set, pt, &need, sign, on_gpu, class_grids, status);
            if (on_gpu)
                f->st->patches_gpu_evaluated += drawn;
        } else if (on_gpu) {
            r = gpu_face(f, o, pt, n, sign, trimmed, &need, cell, status);
            f->st->patches_gpu_evaluated += drawn;
        } else {
            r = sw__gpu_tessellate_face(pt, n_cols, n_rows, sign, rec->uv_box, &f->geo->mesh,
                                        status);
            for (size_t p = 0; p < n && f->env->ctx->patch_hook; ++p)
                if (pt[p].visible)
                    sw__fr_report_patch(f, o, &pt[p], pt[p].s0, pt[p].s1, pt[p].t0, pt[p].t1,
                                        pt[p].nu, pt[p].nv, 0, trimmed);
            if (r == SW_OK)
                r = sw__fr_add_draw(f, o, first, trimmed, &need, cell, status);
        }
        if (f->env->exact)
            f->st->patches_exact += drawn;
        if (r == SW_OK && !trimmed && !f->env->ctx->crack_fill_off)
            r = sw__fr_box_border(f, o, cell, status); /* counter-clockwise */
        f->st->faces_drawn++;
        if (trimmed)
            f->st->patches_trimmed += drawn;
        else
            f->st->patches_untrimmed += drawn;
    } else {
        f->st->faces_culled++;
    }
    sw__free(pt);
    sw__free(cpw);
    return r;
}

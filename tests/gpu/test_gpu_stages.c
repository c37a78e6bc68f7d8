/* SPDX-License-Identifier: MIT */
/* The frame's stages (gpu/frame_stages.h), driven one by one, each checked against a property a
 * broken version of it would violate:
 *  - cull: without cones the visible face occurrences are exactly the BVH items whose boxes are
 *    not outside the frustum, classified one by one (a BVH walk that dropped a partly visible
 *    node's items, or kept an outside one, differs); with cones every occurrence dropped is
 *    back-facing at every sample of its exact surface (normals from the NURBS derivatives, not
 *    from the cones: a wrong cone or orientation rule culls a face that shows);
 *  - select: every sample of a picked face whose exact point lies inside the frustum falls in a
 *    chosen hierarchy item's rectangle (a cut that drops or misplaces an item leaves a hole), and
 *    the items over their error budget are exactly the ones counted;
 *  - tessellate: every draw's index range lies in the mesh, every vertex-shader record names an
 *    existing draw and control points, each trimmed draw has one pending trim, and the triangle
 *    count is the records' grids plus the borders (a bookkeeping slip shows);
 *  - trim: each texture's class holds its wanted texels (or the atlas maximum), its loops exist
 *    and lie in the face's trim box; after the atlas every trimmed draw has an entry of the
 *    planned size; the side of a loop its fat border covers is the face's for thin bands, holes
 *    and islands in either orientation (a probe a fixed fraction of the longest edge off the loop
 *    lands beyond a band 2π long and 0.002 wide: the ribbon then covers the outside); with
 *    exact trim edges every trim has a grid set on its draw (cells and segments inside the
 *    frame's arrays, as many as counted) or a texture class, never both, and the chained stages
 *    equal sw_gpu_render_scene's image (planted: the grid not set on its draw → fails);
 *  - chunks: the tessellation split among the pool's workers is the one thread's byte for byte,
 *    for per-frame faces and, with static LODs, for units at a static level with their borders;
 *  - submit: the stages chained by hand give the image sw_gpu_render_scene gives, byte for byte;
 *    and a hand-made geometry (one flat bilinear patch record) covers exactly the pixels its
 *    analytic projection covers.
 * Usage: test_gpu_stages MODEL... */
#include <splinewalk/sw_lod_build.h>
#include "frame_stages.h"
#include "gpu_test_compare.h"
#include "sw_hooks.h"
#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_sg_import.h"
#ifdef SW_TEST_STATIC
#include "sw_lod_static_set.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

enum { W = 320, H = 240 };
static sw_th_pool *g_pool;
static int g_bound_counted;  /* narrow views with pieces counted over the bound */
static int g_partial_views;  /* views that cut a model: the cull check is not vacuous */
static int g_parallel_split; /* frames tessellated in chunks: the parallel check is not vacuous */
static int g_static_split;   /* the same with static picks among the chunks */

/* One frame's stage outputs, as sw_gpu_frame_prepare keeps them. */
typedef struct stages {
    sw_gpu_frame_desc desc;
    sw__fr_env env;
    sw__fr_hierarchy hy;
    sw__fr_visible vis;
    sw__fr_selection sel;
    sw__fr_geometry geo;
    sw_gpu_frame_stats st;
} stages;

static void stages_free(stages *s)
{
    if (s->hy.cache && s->hy.reader >= 0) {
        sw_lod_cache_reader_leave(s->hy.cache, s->hy.reader);
        sw_lod_cache_reader_remove(s->hy.cache, s->hy.reader);
    }
    sw__fr_visible_free(&s->vis);
    sw__fr_selection_free(&s->sel);
    sw__fr_geometry_free(&s->geo);
}

/* cull -> select -> tessellate -> trim plan, as frame.c chains them. */
static sw_result run_prepare(stages *s, sw_gpu_context *ctx, const sw_sg_scene *scene,
                             const sw_gpu_frame_desc *desc, sw_status *st)
{
    memset(s, 0, sizeof *s);
    s->hy.reader = -1;
    sw__gpu_desc_defaults(desc, &s->desc);
    double scene_box[6];
    sw_result r = sw__fr_env_init(&s->env, ctx, scene, &s->desc, st);
    if (r == SW_OK && s->desc.hierarchies) {
        s->hy.cache = s->desc.hierarchies;
        s->hy.reader = sw_lod_cache_reader_add(s->hy.cache);
        sw_lod_cache_reader_enter(s->hy.cache, s->hy.reader);
    }
    if (r == SW_OK)
        r = sw__fr_cull_scene_box(&s->env, &s->desc, &s->vis, scene_box, st);
    if (r == SW_OK)
        r = sw__fr_env_view(&s->env, &s->desc, scene_box, st);
    if (r == SW_OK)
        r = sw__fr_cull(&s->env, &s->desc, &s->vis, &s->st, st);
    if (r == SW_OK)
        r = sw__fr_select(&s->env, &s->hy, &s->vis, &s->sel, &s->st, st);
    if (r == SW_OK)
        r = sw__fr_tessellate(&s->env, &s->vis, &s->sel, &s->geo, &s->st, st);
    if (r == SW_OK)
        r = sw__fr_trim_plan(&s->env, &s->geo, &s->st, st);
    return r;
}

static int same_occurrence(const occurrence *o, uint32_t face, const double world[12])
{
    return o->face == face && memcmp(o->world, world, sizeof o->world) == 0;
}

static int faces_hold(const sw__fr_faces *l, uint32_t face, const double world[12])
{
    for (size_t i = 0; i < l->n; ++i)
        if (same_occurrence(&l->occ[i], face, world))
            return 1;
    return 0;
}

static void view_frustum(const sw__gpu_view *v, sw_sg_frustum *fr)
{
    memcpy(fr->origin, v->eye, sizeof fr->origin);
    memcpy(fr->planes, v->planes, sizeof v->planes);
    fr->n_planes = 5;
}

/* ---- cull ------------------------------------------------------------------------------------ */
static void check_cull_exact(const stages *s, const sw_sg_bvh *bvh, const char *name)
{
    sw_sg_frustum fr;
    view_frustum(&s->env.view, &fr);
    size_t expected = 0, missing = 0;
    for (uint32_t i = 0; i < bvh->n_items; ++i) {
        sw_sg_bvh_item_view it_view;
        sw_sg_bvh_item_at(bvh, i, &it_view);
        const sw_sg_bvh_item_view *it = &it_view;
        if (sw_sg_frustum_classify(&fr, it->box) == SW_SG_CULL_OUTSIDE)
            continue;
        expected++;
        missing += !faces_hold(&s->vis.faces, it->face, it->world);
    }
    CHECK(missing == 0 && expected == s->vis.faces.n,
          "%s: cull kept %zu occurrences, brute force %zu (%zu of those missing)", name,
          s->vis.faces.n, expected, missing);
    CHECK(expected > 0, "%s: nothing in view", name);
    g_partial_views += expected < bvh->n_items;
}

/* Whether the occurrence shows its back at every sample of its exact surface: outward normals
 * (the derivatives' cross product, flipped for a reversed face and a mirroring transform) point
 * away from the eye. Degenerate samples (poles) say nothing. */
static int back_facing_everywhere(const sw_sg_scene *scene, const occurrence *o,
                                  const double eye[3])
{
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(scene)->faces[o->face];
    sw_sg_surface srf;
    sw_sg_scene_face_surface(scene, o->face, &srf);
    const double *m = o->world, *ub = rec->uv_box;
    const double cof[9] = {
        m[5] * m[10] - m[6] * m[9], m[6] * m[8] - m[4] * m[10], m[4] * m[9] - m[5] * m[8],
        m[2] * m[9] - m[1] * m[10], m[0] * m[10] - m[2] * m[8], m[1] * m[8] - m[0] * m[9],
        m[1] * m[6] - m[2] * m[5],  m[2] * m[4] - m[0] * m[6],  m[0] * m[5] - m[1] * m[4]};
    const double det = m[0] * cof[0] + m[1] * cof[1] + m[2] * cof[2];
    const double flip =
        ((rec->flags & SW_SG_FACE_REVERSED) ? -1.0 : 1.0) * (det < 0.0 ? -1.0 : 1.0);
    enum { N = 9 };
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const double u = ub[0] + (ub[1] - ub[0]) * i / (N - 1);
            const double v = ub[2] + (ub[3] - ub[2]) * j / (N - 1);
            sw_sg_surface_d2 d;
            sw_sg_surface_eval_d2(&srf, u, v, &d);
            const double n[3] = {d.du[1] * d.dv[2] - d.du[2] * d.dv[1],
                                 d.du[2] * d.dv[0] - d.du[0] * d.dv[2],
                                 d.du[0] * d.dv[1] - d.du[1] * d.dv[0]};
            double nw[3], pw[3], dot = 0.0, nn = 0.0, dd = 0.0;
            for (int a = 0; a < 3; ++a) {
                nw[a] = flip * (cof[a] * n[0] + cof[3 + a] * n[1] + cof[6 + a] * n[2]);
                pw[a] = m[4 * a] * d.p[0] + m[4 * a + 1] * d.p[1] + m[4 * a + 2] * d.p[2] +
                        m[4 * a + 3] - eye[a];
                dot += nw[a] * pw[a];
                nn += nw[a] * nw[a];
                dd += pw[a] * pw[a];
            }
            if (nn > 0.0 && dot < -1e-9 * sqrt(nn * dd))
                return 0;
        }
    return 1;
}

static void check_cull_backfaces(const stages *with, const stages *without, const char *name)
{
    size_t culled = 0, wrong = 0;
    for (size_t i = 0; i < without->vis.faces.n; ++i) {
        const occurrence *o = &without->vis.faces.occ[i];
        if (faces_hold(&with->vis.faces, o->face, o->world))
            continue;
        culled++;
        if (!back_facing_everywhere(with->env.scene, o, with->env.view.eye)) {
            wrong++;
            if (wrong <= 3)
                printf("  face %u culled, but some of it faces the eye\n", o->face);
        }
    }
    printf("%s: %zu of %zu visible occurrences back-culled\n", name, culled, without->vis.faces.n);
    CHECK(wrong == 0, "%s: %zu back-culled occurrences face the eye somewhere", name, wrong);
    CHECK(with->vis.faces.n + culled == without->vis.faces.n,
          "%s: culling with cones added occurrences", name);
}

/* ---- select ---------------------------------------------------------------------------------- */
static int inside_frustum(const sw__gpu_view *v, const double x[3])
{
    const double r = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int k = 0; k < 5; ++k)
        if (!(v->planes[k][0] * x[0] + v->planes[k][1] * x[1] + v->planes[k][2] * x[2] +
                  v->planes[k][3] >
              1e-7 * r))
            return 0;
    return 1;
}

/* Whether (u, v) lies in r, up to a rounding of the box's extent (node rectangles and the face's
 * trim box are computed apart, and may differ in their last bits). */
static int in_rect(const double r[4], const double ub[4], double u, double v)
{
    const double eu = 1e-9 * (ub[1] - ub[0]), ev = 1e-9 * (ub[3] - ub[2]);
    return u >= r[0] - eu && u <= r[1] + eu && v >= r[2] - ev && v <= r[3] + ev;
}

static void check_select(const stages *s, const char *name)
{
    size_t samples = 0, holes = 0, faces = 0, over = 0;
    for (size_t f = 0; f < s->sel.n_faces; ++f) {
        const sw__fr_face_pick *p = &s->sel.faces[f];
        if (!p->hierarchy)
            continue;
        faces++;
        const hl_choice *items = s->sel.items + p->first_item;
        for (size_t k = 0; k < p->n_items; ++k)
            over += !(items[k].err_w <= 0.5 * items[k].eps_obj);
        sw_sg_surface srf;
        sw_sg_scene_face_surface(s->env.scene, p->occ.face, &srf);
        const double *ub = s->env.sv->faces[p->occ.face].uv_box, *m = p->occ.world;
        enum { N = 9 };
        for (int j = 0; j < N; ++j)
            for (int i = 0; i < N; ++i) {
                const double u = i == N - 1 ? ub[1] : ub[0] + (ub[1] - ub[0]) * i / (N - 1);
                const double v = j == N - 1 ? ub[3] : ub[2] + (ub[3] - ub[2]) * j / (N - 1);
                double x[3], e[3];
                sw_sg_surface_eval(&srf, u, v, x);
                for (int a = 0; a < 3; ++a)
                    e[a] = m[4 * a] * x[0] + m[4 * a + 1] * x[1] + m[4 * a + 2] * x[2] +
                           m[4 * a + 3] - s->env.view.eye[a];
                if (!inside_frustum(&s->env.view, e))
                    continue;
                samples++;
                int found = 0;
                for (size_t k = 0; k < p->n_items && !found; ++k)
                    found = in_rect(items[k].rect, ub, u, v);
                holes += !found;
                if (!found && holes <= 5 && getenv("SW_TEST_DEBUG")) {
                    printf("  hole: face %u (%zu items) at (%g, %g), box %g %g %g %g\n",
                           p->occ.face, p->n_items, u, v, ub[0], ub[1], ub[2], ub[3]);
                    for (size_t k = 0; k < p->n_items; ++k)
                        printf("    item %d/%d: %g %g %g %g\n", items[k].it.node,
                               items[k].it.part_depth, items[k].rect[0], items[k].rect[1],
                               items[k].rect[2], items[k].rect[3]);
                }
            }
    }
    printf("%s: %zu faces by their hierarchy cut, %zu items, %zu samples in view\n", name, faces,
           s->sel.n_items, samples);
    CHECK(faces > 0 && samples > 0, "%s: no hierarchy cut to check", name);
    CHECK(holes == 0, "%s: %zu of %zu samples in view lie in no chosen item", name, holes, samples);
    CHECK(over == s->st.hlod_over_budget, "%s: %zu items over budget, %llu counted", name, over,
          (unsigned long long)s->st.hlod_over_budget);
}

/* ---- tessellate ------------------------------------------------------------------------------ */
static void check_tessellate(const stages *s, const char *name)
{
    const sw__fr_geometry *g = &s->geo;
    size_t bad_draws = 0, bad_recs = 0, bad_trims = 0;
    uint64_t tri = 0;
    for (size_t i = 0; i < g->n_draws; ++i)
        bad_draws += g->draws[i].first_idx + g->draws[i].n_idx > g->mesh.n_idx;
    for (size_t i = 0; i < g->n_recs; ++i) {
        const sw__gpu_patch_rec *r = &g->recs[i];
        const size_t n_cp = (size_t)(r->deg_u + 1) * (size_t)(r->deg_v + 1);
        bad_recs += r->draw < 0 || (size_t)r->draw >= g->n_draws ||
                    (!s->env.exact && (size_t)r->cp + n_cp > g->n_cps);
        tri += 2u * (uint64_t)sw__gpu_grid_segments[r->level_u] *
               (uint64_t)sw__gpu_grid_segments[r->level_v];
    }
    for (size_t i = 0; i < g->n_trims; ++i) {
        size_t same = 0;
        for (size_t k = 0; k < g->n_trims; ++k)
            same += g->trims[k].draw == g->trims[i].draw;
        bad_trims += g->trims[i].draw >= g->n_draws || same != 1;
    }
    for (size_t i = 0; i < g->mesh.n_idx; ++i)
        bad_draws += g->mesh.idx[i] >= g->mesh.n_v;
    CHECK(g->n_draws > 0 && g->n_recs > 0, "%s: nothing tessellated", name);
    CHECK(bad_draws == 0, "%s: %zu draws or indices outside the mesh", name, bad_draws);
    CHECK(bad_recs == 0, "%s: %zu records name no draw or no control points", name, bad_recs);
    CHECK(bad_trims == 0, "%s: %zu pending trims without their own draw", name, bad_trims);
    CHECK(s->st.triangles == tri + g->border_triangles,
          "%s: %llu triangles counted, records and borders make %llu", name,
          (unsigned long long)s->st.triangles, (unsigned long long)(tri + g->border_triangles));
}

/* ---- trim --------------------------------------------------------------------------------------
 */
static void check_trim_plan(const stages *s, const char *name)
{
    const sw__fr_geometry *g = &s->geo;
    const int32_t max_entry = sw__gpu_atlas_max_entry(s->env.ctx);
    size_t small = 0, no_loops = 0, stray = 0;
    double worst = 0.0;
    for (size_t i = 0; i < g->n_trims; ++i) {
        const pending_trim *p = &g->trims[i];
        small += p->w < fmin(ceil(p->width), max_entry) || p->h < fmin(ceil(p->height), max_entry);
        if (p->loops < 0 || (size_t)p->loops >= g->n_loops) {
            no_loops++;
            continue;
        }
        /* the texture's texels over the trim box (the loops' flattening tolerance is half of
         * one): a vertex may stray from the box by a rounding, not by a texel */
        const double *ub = s->env.sv->faces[p->occ.face].uv_box;
        const double *r = p->clip ? p->rect : ub;
        const double tu = (r[1] - r[0]) / p->w, tv = (r[3] - r[2]) / p->h;
        const face_loops *fl = &g->loops[p->loops];
        for (uint32_t k = 0; k < fl->n; ++k)
            for (uint32_t j = 0; j < fl->loops[k].count; ++j) {
                const double *q = fl->loops[k].uv + 2 * j;
                const double out = fmax(fmax((ub[0] - q[0]) / tu, (q[0] - ub[1]) / tu),
                                        fmax((ub[2] - q[1]) / tv, (q[1] - ub[3]) / tv));
                worst = fmax(worst, out);
                stray += out > 1e-3;
            }
    }
    if (stray)
        printf("%s: loops stray up to %.3g texels outside their trim box\n", name, worst);
    CHECK(g->n_trims > 0, "%s: no trimmed draw", name);
    CHECK(small == 0, "%s: %zu trim classes below their wanted texels", name, small);
    CHECK(no_loops == 0, "%s: %zu trims without flattened loops", name, no_loops);
    CHECK(stray == 0, "%s: %zu loop vertices outside their face's trim box", name, stray);
}

/* With exact trim edges (desc.trim_edges): every trim either has a grid, set on its draw, whose
 * cells and segments lie in the frame's arrays, or (too coarse a texel would not show) a texture
 * class; at least one has a grid, and the grids take no atlas footprint. */
static void check_exact_plan(const stages *s, const char *name)
{
    const sw__fr_geometry *g = &s->geo;
    const sw__gpu_edge_grids *e = &g->edges;
    size_t exact = 0, bad = 0;
    for (size_t i = 0; i < g->n_trims; ++i) {
        const pending_trim *p = &g->trims[i];
        if (p->grid < 0) {
            bad += p->w <= 0 || p->h <= 0 || g->draws[p->draw].edge_grid >= 0;
            continue;
        }
        ++exact;
        const sw__gpu_edge_grid *h = (size_t)p->grid < e->n_grids ? &e->grids[p->grid] : NULL;
        bad += !h || g->draws[p->draw].edge_grid != p->grid;
        if (!h)
            continue;
        const size_t n_cells = (size_t)h->n[0] * h->n[1];
        bad += h->first_cell + n_cells > e->n_cells;
        for (size_t c = 0; c < n_cells && h->first_cell + n_cells <= e->n_cells; ++c) {
            const uint32_t *cell = &e->cells[2 * (h->first_cell + c)];
            bad += (size_t)cell[0] + (cell[1] >> 4) > e->n_segs ||
                   ((cell[1] >> 1) & 7u) >= SW__GPU_EDGE_REFS;
        }
    }
    CHECK(exact > 0 && exact == s->st.trim_exact, "%s: %zu exact trims, %llu counted", name, exact,
          (unsigned long long)s->st.trim_exact);
    CHECK(bad == 0, "%s: %zu trims with a grid out of its arrays, or neither grid nor class", name,
          bad);
}

static void check_atlas(sw_gpu_context *ctx, const stages *s, const char *name)
{
    const sw__fr_geometry *g = &s->geo;
    size_t bad = 0;
    for (size_t i = 0; i < g->n_trims; ++i) {
        const int32_t id = g->draws[g->trims[i].draw].trim_entry;
        sw__gpu_trim_rect tr = {0, 0, 0, 0, 0};
        if (id >= 0)
            sw__gpu_atlas_rect(ctx, id, &tr);
        if (g->trims[i].grid >= 0) /* exact edges: no texture */
            bad += id >= 0;
        else
            bad += id < 0 || tr.w != g->trims[i].w || tr.h != g->trims[i].h;
    }
    for (size_t i = 0; i < g->n_shares; ++i) {
        const sw__gpu_draw *d = &g->draws[g->shares[2 * i]], *src = &g->draws[g->shares[2 * i + 1]];
        bad += d->trim_entry != src->trim_entry || d->edge_grid != src->edge_grid;
    }
    CHECK(bad == 0,
          "%s: %zu trimmed draws without an atlas entry of the planned size (or with one "
          "beside exact edges)",
          name, bad);
}

/* ---- submit ------------------------------------------------------------------------------------
 */
/* The same frame tessellated in chunks with the pool's workers (desc.pool) must be the one
 * thread's geometry item for item: every chunk appended in order with its vertex, index, draw,
 * loop and control-point numbers rebased. Planted fault seen failing: the records' draw index not
 * rebased in append_geometry (stage_tessellate_parallel.c). */
/* memcmp of n bytes, which wants real pointers even for n = 0 */
static int same_bytes(const void *a, const void *b, size_t n)
{
    return n == 0 || memcmp(a, b, n) == 0;
}

static int same_draw(const sw__gpu_draw *a, const sw__gpu_draw *b)
{
    return a->first_idx == b->first_idx && a->n_idx == b->n_idx &&
           memcmp(a->color, b->color, sizeof a->color) == 0 && a->trim_entry == b->trim_entry &&
           memcmp(a->uv_map, b->uv_map, sizeof a->uv_map) == 0;
}

static int same_trim(const pending_trim *a, const pending_trim *b)
{
    return a->draw == b->draw && same_occurrence(&a->occ, b->occ.face, b->occ.world) &&
           a->width == b->width && a->height == b->height && a->cell[0] == b->cell[0] &&
           a->cell[1] == b->cell[1] && a->loops == b->loops && a->clip == b->clip &&
           memcmp(a->rect, b->rect, sizeof a->rect) == 0 && a->w == b->w && a->h == b->h;
}

static int same_loops(const face_loops *a, const face_loops *b)
{
    if (a->n != b->n)
        return 0;
    for (uint32_t k = 0; k < a->n; ++k)
        if (a->loops[k].count != b->loops[k].count ||
            !same_bytes(a->loops[k].uv, b->loops[k].uv, 2 * a->loops[k].count * sizeof(double)))
            return 0;
    return 1;
}

static size_t first_mismatch(const sw__fr_geometry *a, const sw__fr_geometry *b)
{
    const sw__gpu_mesh *m = &a->mesh, *n = &b->mesh;
    if (m->n_v != n->n_v || !same_bytes(m->v, n->v, m->n_v * sizeof *m->v))
        return 1;
    if (m->n_idx != n->n_idx || !same_bytes(m->idx, n->idx, m->n_idx * sizeof *m->idx))
        return 2;
    if (a->n_draws != b->n_draws)
        return 3;
    for (size_t i = 0; i < a->n_draws; ++i)
        if (!same_draw(&a->draws[i], &b->draws[i]))
            return 3;
    if (a->n_trims != b->n_trims)
        return 4;
    for (size_t i = 0; i < a->n_trims; ++i)
        if (!same_trim(&a->trims[i], &b->trims[i]))
            return 4;
    if (a->n_shares != b->n_shares ||
        !same_bytes(a->shares, b->shares, 2 * a->n_shares * sizeof *a->shares))
        return 5;
    if (a->n_loops != b->n_loops)
        return 6;
    for (size_t i = 0; i < a->n_loops; ++i)
        if (!same_loops(&a->loops[i], &b->loops[i]))
            return 6;
    if (a->n_recs != b->n_recs || !same_bytes(a->recs, b->recs, a->n_recs * sizeof *a->recs))
        return 7;
    if (a->n_cps != b->n_cps || !same_bytes(a->cps, b->cps, 4 * a->n_cps * sizeof *a->cps))
        return 8;
    if (a->gpu_vertices != b->gpu_vertices || a->border_triangles != b->border_triangles)
        return 9;
    if (a->n_resident != b->n_resident || a->resident_triangles != b->resident_triangles ||
        !same_bytes(a->resident, b->resident, a->n_resident * sizeof *a->resident))
        return 10;
    return 0;
}

static void check_parallel(sw_gpu_context *ctx, const sw_sg_scene *scene,
                           const sw_gpu_frame_desc *desc, const stages *one, const char *name)
{
    static const char *const what[] = {
        "",      "vertices", "indices",        "draws",         "trims",         "shares",
        "loops", "records",  "control points", "vertex counts", "resident draws"};
    sw_gpu_frame_desc d = *desc;
    d.pool = g_pool;
    stages par;
    sw_status st = {0};
    if (run_prepare(&par, ctx, scene, &d, &st) != SW_OK) {
        CHECK(0, "%s: stages with the pool: %s", name, st.message);
        stages_free(&par);
        return;
    }
    size_t bad = first_mismatch(&par.geo, &one->geo);
    printf("%s: tessellation in %llu chunks (%llu by workers, join %.2f ms): %s\n", name,
           (unsigned long long)par.st.tess_chunks, (unsigned long long)par.st.tess_chunks_by_pool,
           par.st.ms_join, bad ? what[bad] : "the one thread's geometry");
    /* below 32 faces a split is not worth it (MIN_FACES_PER_CHUNK) */
    CHECK(par.st.tess_chunks > 1 || one->sel.n_faces < 32, "%s: %zu faces not split (%llu chunks)",
          name, one->sel.n_faces, (unsigned long long)par.st.tess_chunks);
    g_parallel_split += par.st.tess_chunks > 1;
    CHECK(bad == 0, "%s: chunked tessellation differs from one thread's in its %s", name,
          what[bad]);
    CHECK(par.st.triangles == one->st.triangles && par.st.faces_drawn == one->st.faces_drawn &&
              par.st.patches_culled == one->st.patches_culled &&
              par.st.bound_exceeded == one->st.bound_exceeded,
          "%s: chunked stats differ (triangles %llu vs %llu)", name,
          (unsigned long long)par.st.triangles, (unsigned long long)one->st.triangles);
    stages_free(&par);
}

#ifdef SW_TEST_STATIC
/* Static picks are chunked too (the first model only): with the scene's static LODs (built
 * converged) and the view 3x farther, so that most units are drawn at a level, the chunked geometry
 * and the static counters equal the one thread's (a chunk that lost a static pick's borders, or a
 * counter not merged, differs). */
static void check_parallel_static(sw_gpu_context *ctx, const sw_sg_scene *scene,
                                  const sw_gpu_frame_desc *base, const char *name)
{
    sw_lod_static_set *set = NULL;
    sw_status st = {0};
    if (sw_lod_static_set_create(scene, g_pool, NULL, &set, &st) != SW_OK) {
        CHECK(0, "%s: static set: %s", name, st.message);
        return;
    }
    sw_gpu_frame_desc d = *base;
    d.static_lods = set;
    for (int k = 0; k < 3; ++k)
        d.camera.eye[k] = d.camera.target[k] + 3.0 * (d.camera.eye[k] - d.camera.target[k]);
    stages one;
    if (run_prepare(&one, ctx, scene, &d, &st) != SW_OK) {
        CHECK(0, "%s: stages with static LODs: %s", name, st.message);
    } else {
        char what[256];
        snprintf(what, sizeof what, "%s (static LODs: %zu static picks, %zu faces)", name,
                 one.sel.n_statics, one.sel.n_faces);
        const size_t picks = one.sel.n_statics + one.sel.n_faces;
        stages par;
        d.pool = g_pool;
        if (run_prepare(&par, ctx, scene, &d, &st) != SW_OK) {
            CHECK(0, "%s: with the pool: %s", what, st.message);
        } else {
            const size_t bad = first_mismatch(&par.geo, &one.geo);
            printf("%s: %llu chunks: %s\n", what, (unsigned long long)par.st.tess_chunks,
                   bad ? "DIFFERENT" : "the one thread's geometry");
            CHECK(par.st.tess_chunks > 1 || picks < 32, "%s: not split", what);
            g_static_split += par.st.tess_chunks > 1 && one.sel.n_statics > 0;
            CHECK(bad == 0, "%s: chunked tessellation differs from one thread's (%zu)", what, bad);
            /* every static pick a draw of the context's GPU copy of its level (gpu/resident.c) */
            CHECK(one.geo.n_resident == one.sel.n_statics &&
                      one.geo.resident_triangles == one.st.static_triangles,
                  "%s: %zu resident draws (%llu triangles) for %zu static picks (%llu)", what,
                  one.geo.n_resident, (unsigned long long)one.geo.resident_triangles,
                  one.sel.n_statics, (unsigned long long)one.st.static_triangles);
            CHECK(par.st.static_units_drawn == one.st.static_units_drawn &&
                      par.st.static_faces == one.st.static_faces &&
                      par.st.static_triangles == one.st.static_triangles &&
                      par.st.static_levels_used == one.st.static_levels_used &&
                      par.st.border_triangles == one.st.border_triangles,
                  "%s: chunked static counters differ (units %llu vs %llu, faces %llu vs %llu)",
                  what, (unsigned long long)par.st.static_units_drawn,
                  (unsigned long long)one.st.static_units_drawn,
                  (unsigned long long)par.st.static_faces, (unsigned long long)one.st.static_faces);
        }
        stages_free(&par);
    }
    stages_free(&one);
    sw_lod_static_set_destroy(set);
}
#endif

/* The stages chained by hand against sw_gpu_render_scene on the same context. From a model's
 * second view on, the reference frame starts from the plan of the frame before, recycled into
 * the context with its arrays (frame_stash.c): an item or count kept from that frame shows here
 * as pixels or triangles that the fresh stages do not have. */
static void check_chain(sw_gpu_context *ctx, const sw_sg_scene *scene,
                        const sw_gpu_frame_desc *desc, stages *s, const char *name)
{
    sw_status st = {0};
    sw_gpu_image by_hand = {0}, whole = {0};
    sw_gpu_frame_stats whole_st = {0};
    sw_result r = sw__fr_trim_atlas(ctx, scene, &s->geo, &s->st, &st);
    if (r == SW_OK)
        check_atlas(ctx, s, name);
    if (r == SW_OK)
        r = sw__fr_submit(ctx, &s->env.view, &s->desc, &s->geo, &st);
    if (r == SW_OK)
        r = sw__gpu_readback(ctx, &s->env.view, 0, &by_hand, &st);
    if (r == SW_OK)
        r = sw_gpu_render_scene(ctx, scene, desc, &whole, &whole_st, &st);
    CHECK(r == SW_OK, "%s: atlas, submit or reference frame: %s", name, st.message);
    if (r == SW_OK) {
        const sw_test_image_diff d = sw_test_compare_images(&by_hand, &whole, 0);
        CHECK(d.any == 0 && d.covered > 0,
              "%s: the stages by hand differ from sw_gpu_render_scene in %ld pixels (%ld covered)",
              name, d.any, d.covered);
        /* submit adds the mesh's own triangles to the stages' count (frame.c) */
        const uint64_t triangles =
            s->st.triangles + s->geo.mesh.n_idx / 3 - s->geo.border_triangles;
        CHECK(whole_st.triangles == triangles &&
                  whole_st.border_triangles == s->geo.border_triangles,
              "%s: sw_gpu_render_scene counts %llu triangles (%llu of borders), the stages %llu "
              "(%llu)",
              name, (unsigned long long)whole_st.triangles,
              (unsigned long long)whole_st.border_triangles, (unsigned long long)triangles,
              (unsigned long long)s->geo.border_triangles);
    }
    sw_gpu_image_free(&by_hand);
    sw_gpu_image_free(&whole);
}

/* A flat square [-0.5, 0.5]^2 at z = -1 before an eye at the origin looking down -z, fovy 90°, as
 * one bilinear patch record: it must cover exactly the pixels whose centres project inside it
 * (focal H/2 px), up to one pixel along its edges. */
static void check_submit_analytic(sw_gpu_context *ctx)
{
    sw_gpu_frame_desc desc = {0};
    desc.width = W;
    desc.height = H;
    desc.background[3] = 0.0f;
    desc.camera = (sw_gpu_camera){{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90.0};
    sw__gpu_view view;
    sw_status st = {0};
    sw__fr_geometry g;
    memset(&g, 0, sizeof g);
    float cps[16] = {-0.5f, -0.5f, -1, 1, 0.5f, -0.5f, -1, 1,
                     -0.5f, 0.5f,  -1, 1, 0.5f, 0.5f,  -1, 1};
    sw__gpu_patch_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.st[1] = rec.st[3] = 1.0f;
    rec.trim_map[1] = rec.trim_map[3] = 1.0f;
    rec.color[0] = rec.color[1] = rec.color[2] = rec.color[3] = 1.0f;
    rec.deg_u = rec.deg_v = 1;
    rec.normal_sign = 1.0f;
    rec.uv_map[2] = rec.uv_map[3] = 1.0f;
    sw__gpu_draw d;
    memset(&d, 0, sizeof d);
    d.trim_entry = -1;
    d.edge_grid = -1;
    memcpy(d.color, rec.color, sizeof d.color);
    g.recs = &rec;
    g.n_recs = 1;
    g.cps = cps;
    g.n_cps = 4;
    g.draws = &d;
    g.n_draws = 1;
    sw_gpu_image img = {0};
    sw_result r = sw__gpu_view_init(&view, &desc.camera, W, H, 0.1, &st);
    if (r == SW_OK)
        r = sw__fr_submit(ctx, &view, &desc, &g, &st);
    if (r == SW_OK)
        r = sw__gpu_readback(ctx, &view, 0, &img, &st);
    CHECK(r == SW_OK, "analytic submit: %s", st.message);
    long wrong = 0, covered = 0;
    const double focal = 0.5 * H; /* tan 45° = 1 */
    for (int32_t y = 0; y < H && r == SW_OK; ++y)
        for (int32_t x = 0; x < W; ++x) {
            /* pixel centre to the plane z = -1 (top row first) */
            const double px = (x + 0.5 - 0.5 * W) / focal, py = (0.5 * H - (y + 0.5)) / focal;
            const int want = fabs(px) < 0.5 && fabs(py) < 0.5;
            const int edge =
                fabs(fabs(px) - 0.5) < 1.0 / focal || fabs(fabs(py) - 0.5) < 1.0 / focal;
            const int got = img.rgba[4 * ((size_t)y * W + (size_t)x) + 3] != 0;
            covered += got;
            wrong += got != want && !edge;
        }
    printf("analytic submit: %ld pixels covered, %ld wrong away from the edges\n", covered, wrong);
    CHECK(r != SW_OK || (wrong == 0 && covered > 0), "analytic submit: %ld pixels wrong", wrong);
    sw_gpu_image_free(&img);
}

/* The counter of pieces over the bound counts: a view of the model at the floor of the field of
 * view (0.01°)'s middle, drawn by the faces' own Bézier patches, asks grids finer than the segment
 * limit (a counter that never counts would pass the check above). */
static void check_bound_counted(sw_gpu_context *ctx, const sw_sg_scene *scene,
                                const sw_gpu_frame_desc *base, const char *name)
{
    sw_gpu_frame_desc desc = *base;
    desc.camera.fovy_deg = SW_FOVY_MIN_DEG;
    desc.hierarchies = NULL;
    stages s;
    sw_status st = {0};
    if (run_prepare(&s, ctx, scene, &desc, &st) != SW_OK)
        CHECK(0, "%s: narrow view: %s", name, st.message);
    else
        printf("%s: 0.01 deg view: %llu pieces over the bound\n", name,
               (unsigned long long)s.st.bound_exceeded);
    g_bound_counted += s.st.bound_exceeded > 0;
    stages_free(&s);
}

/* ---- driver ------------------------------------------------------------------------------------
 */
static void run_model(sw_gpu_context *ctx, const char *path, int first_model)
{
    sw_sg_import_desc id = {path, NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL;
    sw_sg_bvh *bvh = NULL;
    sw_lod_face_cones *fc = NULL;
    sw_lod_cache *cache = NULL;
    sw_status st = {0};
    if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK ||
        sw_sg_bvh_build(scene, &bvh, &st) != SW_OK ||
        sw_lod_face_cones_build(scene, &fc, &st) != SW_OK ||
        sw_lod_cache_create(scene, g_pool, NULL, &cache, &st) != SW_OK || bvh->n_nodes == 0) {
        CHECK(0, "%s: import, BVH, cones or cache: %s", path, st.message);
        goto done;
    }
    /* the iso preset narrowed to 15° and aimed off centre: some occurrences outside the view,
     * some back-facing */
    sw_gpu_frame_desc desc = {0};
    desc.width = W;
    desc.height = H;
    desc.camera = sw_test_view_camera(bvh->box, 1);
    desc.camera.fovy_deg = 15.0;
    for (int k = 0; k < 3; ++k) {
        const double shift = 0.2 * (bvh->box[k] - desc.camera.target[k]);
        desc.camera.target[k] += shift;
        desc.camera.eye[k] += shift;
    }
    desc.bvh = bvh;
    stages plain, coned;
    if (run_prepare(&plain, ctx, scene, &desc, &st) != SW_OK)
        CHECK(0, "%s: stages without cones: %s", path, st.message);
    else
        check_cull_exact(&plain, bvh, path);
    desc.face_cones = fc;
    desc.hierarchies = cache;
    if (run_prepare(&coned, ctx, scene, &desc, &st) != SW_OK) {
        CHECK(0, "%s: stages: %s", path, st.message);
    } else {
        check_cull_backfaces(&coned, &plain, path);
        check_select(&coned, path);
        check_tessellate(&coned, path);
        check_trim_plan(&coned, path);
        check_parallel(ctx, scene, &desc, &coned, path);
#ifdef SW_TEST_STATIC
        if (first_model) /* building the static levels is the slow part under the sanitizers */
            check_parallel_static(ctx, scene, &desc, path);
#endif
        check_chain(ctx, scene, &desc, &coned, path);
        CHECK(coned.st.bound_exceeded == 0, "%s: %llu pieces over the error bound", path,
              (unsigned long long)coned.st.bound_exceeded);
    }
    desc.trim_edges = 1; /* the same stages with exact trim edges */
    stages exact;
    if (run_prepare(&exact, ctx, scene, &desc, &st) != SW_OK) {
        CHECK(0, "%s: stages with exact edges: %s", path, st.message);
    } else {
        check_exact_plan(&exact, path);
        check_chain(ctx, scene, &desc, &exact, path);
    }
    stages_free(&exact);
    desc.trim_edges = 0;
    check_bound_counted(ctx, scene, &desc, path);
    stages_free(&plain);
    stages_free(&coned);
done:
    sw_lod_cache_destroy(cache);
    sw_lod_face_cones_free(fc);
    sw_sg_bvh_free(bvh);
    sw_sg_scene_free(scene);
}

/* sw__fr_left_is_inside on hand-made loops whose answer is known: a band 2π x 0.002 (a cone's
 * face around its seam in a small unit), with a thin slot in it and an island in the slot, each
 * loop in both orientations. */
static void check_left_is_inside(void)
{
    enum { N_CASES = 8 };
    const double two_pi = 6.283185307179586, w = 0.002;
    double band[8] = {0, 0, two_pi, 0, two_pi, w, 0, w};
    double slot[8] = {1, 0.25 * w, 1, 0.75 * w, 4, 0.75 * w, 4, 0.25 * w};
    double island[8] = {2, 0.4 * w, 3, 0.4 * w, 3, 0.6 * w, 2, 0.6 * w};
    size_t wrong = 0;
    for (int c = 0; c < N_CASES; ++c) {
        double *pts[3] = {band, slot, island};
        double rev[3][8];
        sw_sg_polyline loops[3];
        for (int k = 0; k < 3; ++k) {
            const int flip = (c >> k) & 1; /* loop k reversed */
            for (int i = 0; i < 4; ++i) {
                rev[k][2 * i] = pts[k][2 * (flip ? 3 - i : i)];
                rev[k][2 * i + 1] = pts[k][2 * (flip ? 3 - i : i) + 1];
            }
            loops[k] = (sw_sg_polyline){.uv = rev[k], .count = 4};
        }
        for (uint32_t k = 0; k < 3; ++k) {
            /* as written the band and the island run counter-clockwise, the slot clockwise:
             * each has the face on its left */
            const int want = !((c >> k) & 1);
            wrong += sw__fr_left_is_inside(loops, 3, k) != want;
        }
    }
    CHECK(wrong == 0, "%zu of %d loops: the fat border's side is not the face's", wrong,
          3 * N_CASES);
}

int main(int argc, char **argv)
{
    (void)sw_lod_build_install(); /* static LODs are built by the LOD-building module */
    if (argc < 2) {
        fprintf(stderr, "usage: %s MODEL...\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    sw_th_pool_desc pd = {0};
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK ||
        sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: pool or context: %s\n", st.message);
        return 1;
    }
    check_submit_analytic(ctx);
    check_left_is_inside();
    for (int a = 1; a < argc; ++a)
        run_model(ctx, argv[a], a == 1);
    CHECK(g_partial_views > 0, "no view left an occurrence outside: the cull check is vacuous");
    CHECK(g_bound_counted > 0, "no narrow view counted a piece over the bound");
    CHECK(g_parallel_split > 0,
          "no frame was tessellated in chunks: the parallel check is vacuous");
#ifdef SW_TEST_STATIC
    CHECK(g_static_split > 0,
          "no frame with static picks was tessellated in chunks: the static check is vacuous");
#endif
    sw_gpu_context_free(ctx);
    sw_th_pool_destroy(g_pool);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}

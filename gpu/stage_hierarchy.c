/* SPDX-License-Identifier: MIT */
/* The select stage's traversal of the faces' bicubic hierarchies (Guthe et al. 2005 §7 over the
 * §6 hierarchies of lod/hierarchy/hierarchy_cache.c): the cut of each per-frame face occurrence.
 *
 * Per face occurrence, from the root down: a node whose box (grown by its error) misses the
 * frustum is culled; a node is chosen when its approximation error, in world units, is at most
 * half the object-space tolerance ε_obj that ε_img allows at the nearest depth of its box (§7
 * splits ε equally between approximation and sampling), and — on a trimmed face — when its own
 * trim texture needs at most k_tile_texels per direction; otherwise its children are visited, or,
 * when it is fine enough and its texture needs at most k_node_texels, it is cut into parts. A
 * leaf that is still too coarse is refined below itself in the pool (sw_lod_cache_refine;
 * converged mode waits for it, sw__fr_hierarchy_prepare); a leaf whose trim texture would be too
 * large is cut into parts of its own bicubic (same error bound, smaller box and texture), which is
 * also what keeps a close-up at 1/10,000 of a model within the maximum texture size (§7: "the
 * hierarchy splits"). The chosen items are drawn by stage_tessellate_hierarchy.c. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_ITEMS_PER_FACE = 16384, /* nodes (or parts) drawn for one face occurrence */
    MAX_PART_DEPTH = 48, /* halvings of a leaf's domain for its trim texture (2^-24 per dir.) */
    MAX_REFINE_ROUNDS = 8,
};

typedef struct hl_face {
    const sw__fr_env *env;
    sw__fr_hierarchy *hy;
    sw_gpu_frame_stats *st;
    sw__fr_selection *sel; /* NULL while planning: nothing is chosen */
    const occurrence *o;
    const sw_lod_hierarchy *h;
    double scale; /* bounds the occurrence transform's stretch (sw_sg_stretch_bound) */
    int trimmed;
    hl_item *stack;
    size_t n_stack, cap_stack;
    size_t n_chosen;
    int32_t *refine_nodes; /* leaves to refine below (planning and walkthrough) */
    double *refine_tol;
    size_t n_refine, cap_refine, cap_refine_tol;
    int oom;
} hl_face;

/* The hierarchies hold their share of the memory budget (memory_budget.c): no more refinement. */
static int hierarchy_budget_spent(const hl_face *hf)
{
    return sw_lod_cache_memory(hf->hy->cache) >= hf->env->ctx->hierarchy_bytes;
}

static void item_rect(const sw_lod_hnode *n, const double range[4], double out[4])
{
    double du = n->rect[1] - n->rect[0], dv = n->rect[3] - n->rect[2];
    out[0] = n->rect[0] + du * range[0];
    out[1] = range[1] >= 1.0 ? n->rect[1] : n->rect[0] + du * range[1];
    out[2] = n->rect[2] + dv * range[2];
    out[3] = range[3] >= 1.0 ? n->rect[3] : n->rect[2] + dv * range[3];
}

static int full_range(const double r[4])
{
    return r[0] == 0.0 && r[1] == 1.0 && r[2] == 0.0 && r[3] == 1.0;
}

/* The item's bicubic in eye-relative world space, and its box. */
static void item_net(const hl_face *hf, const sw_lod_hnode *n, const double range[4],
                     double cpw[64], double box[6])
{
    double part[64];
    const double *src = n->cpw;
    if (!full_range(range)) {
        sw_lod_bez_restrict(3, 3, 4, n->cpw, range, part);
        src = part;
    }
    sw__fr_box_empty(box);
    for (int i = 0; i < 16; ++i) {
        sw__fr_xform_h(hf->o->world, hf->env->view.eye, src + 4 * i, cpw + 4 * i);
        sw__fr_box_add(box, cpw + 4 * i);
    }
}

static int push(hl_face *hf, int32_t node, const double range[4], int32_t part_depth)
{
    if (!sw__grow((void **)&hf->stack, &hf->cap_stack, hf->n_stack + 1, sizeof *hf->stack)) {
        hf->oom = 1;
        return 0;
    }
    hl_item *it = &hf->stack[hf->n_stack++];
    it->node = node;
    it->part_depth = part_depth;
    memcpy(it->range, range, sizeof it->range);
    return 1;
}

static void push_children(hl_face *hf, const sw_lod_hnode *n)
{
    static const double k_full[4] = {0.0, 1.0, 0.0, 1.0};
    push(hf, n->child[0], k_full, 0);
    push(hf, n->child[1], k_full, 0);
}

/* Halves the item's range along the direction whose trim texture is the larger. */
static void split_part(hl_face *hf, const hl_item *it, const trim_need *need)
{
    double a[4], b[4];
    memcpy(a, it->range, sizeof a);
    memcpy(b, it->range, sizeof b);
    int dir = need->v > need->u;
    double mid = 0.5 * (it->range[2 * dir] + it->range[2 * dir + 1]);
    a[2 * dir + 1] = mid;
    b[2 * dir] = mid;
    if (push(hf, it->node, a, it->part_depth + 1))
        push(hf, it->node, b, it->part_depth + 1);
}

static void choose(hl_face *hf, const hl_item *it, const double cpw[64], double err_w,
                   double eps_obj, const trim_need *need)
{
    sw__fr_selection *sel = hf->sel;
    if (!sel)
        return;
    if (hf->n_chosen >= MAX_ITEMS_PER_FACE ||
        !sw__grow((void **)&sel->items, &sel->cap_items, sel->n_items + 1, sizeof *sel->items)) {
        hf->oom = 1;
        return;
    }
    hl_choice *c = &sel->items[sel->n_items++];
    hf->n_chosen++;
    c->it = *it;
    memcpy(c->cpw, cpw, sizeof c->cpw);
    const sw_lod_hnode *n = &hf->h->nodes[it->node];
    if (full_range(it->range))
        memcpy(c->cpo, n->cpw, sizeof c->cpo);
    else
        sw_lod_bez_restrict(3, 3, 4, n->cpw, it->range, c->cpo);
    item_rect(&hf->h->nodes[it->node], it->range, c->rect);
    c->err_w = err_w;
    c->eps_obj = eps_obj;
    c->need = *need;
    c->grid_splits = 0;
    if (!(err_w <= 0.5 * eps_obj)) {
        hf->st->hlod_over_budget++;
        if (hierarchy_budget_spent(hf)) { /* left unrefined for the budget's sake */
            hf->st->budget_coarsened++;
            hf->st->bound_exceeded++;
        }
    }
}

/* In planning rounds and walkthrough frames: a leaf to refine below, to a tolerance in the
 * surface's units (asked for together after the traversal, submit_refines); none once the
 * hierarchies hold their share of the memory budget: the leaf is drawn as it is. */
static void ask_refine(hl_face *hf, int32_t node, double eps_obj)
{
    if (hierarchy_budget_spent(hf))
        return;
    double tol = 0.5 * eps_obj / hf->scale;
    if (!(tol > 0.0) || !isfinite(tol))
        return;
    if (!sw__grow((void **)&hf->refine_nodes, &hf->cap_refine, hf->n_refine + 1,
                  sizeof *hf->refine_nodes) ||
        !sw__grow((void **)&hf->refine_tol, &hf->cap_refine_tol, hf->n_refine + 1,
                  sizeof *hf->refine_tol)) {
        hf->oom = 1;
        return;
    }
    hf->refine_nodes[hf->n_refine] = node;
    hf->refine_tol[hf->n_refine++] = tol;
}

/* All of the face's leaves in one refinement task (one new version of its hierarchy). */
static void submit_refines(hl_face *hf)
{
    sw__fr_hierarchy *hy = hf->hy;
    const int walk = hf->env->walkthrough;
    if (hf->n_refine == 0)
        return;
    sw_lod_refine_outcome out = SW_LOD_REFINE_DONE;
    if (sw_lod_cache_refine_leaves(hy->cache, hf->o->face, hf->refine_nodes, hf->refine_tol,
                                   (uint32_t)hf->n_refine, walk ? &hy->req : NULL,
                                   walk ? NULL : &hy->group, &out) == SW_OK &&
        (out == SW_LOD_REFINE_SUBMITTED || out == SW_LOD_REFINE_BUSY)) {
        hy->refine_asked++;
        hf->st->hlod_refine_requests += (uint64_t)walk;
    }
}

/* Visits one item: culls it, chooses it, or goes below it. */
static void visit(hl_face *hf, const hl_item *it)
{
    const sw__fr_env *env = hf->env;
    const int planning = hf->hy->planning;
    const sw_lod_hnode *n = &hf->h->nodes[it->node];
    const int representable = (n->flags & SW_LOD_HNODE_REPRESENTABLE) != 0;
    const int has_children = n->child[0] >= 0 && it->part_depth == 0;
    double cpw[64], box[6];
    if (!representable) { /* its surface bound is the children's: never culled here */
        if (has_children)
            push_children(hf, n);
        return;
    }
    item_net(hf, n, it->range, cpw, box);
    double err_w = n->error * hf->scale;
    for (int k = 0; k < 3; ++k) {
        box[k] -= err_w;
        box[3 + k] += err_w;
    }
    if (!sw__gpu_view_box_visible(&env->view, box)) {
        if (!planning)
            hf->st->patches_culled++;
        return;
    }
    double z = sw__gpu_view_box_depth(&env->view, box);
    double eps_obj = sw_lod_object_tolerance(env->eps_px, z, env->view.focal_px, env->view.tan_x,
                                             env->view.tan_y);
    trim_need need = {1.0, 1.0};
    if (hf->trimmed) {
        need.u = fmax(1.0, n->tex_c[0] * hf->scale * (it->range[1] - it->range[0]) / eps_obj);
        need.v = fmax(1.0, n->tex_c[1] * hf->scale * (it->range[3] - it->range[2]) / eps_obj);
    }
    int approx_ok = err_w <= 0.5 * eps_obj;
    int texture_ok = need.u <= k_tile_texels && need.v <= k_tile_texels;
    /* a node fine enough whose texture is too large for a tile but not for a node is cut into
     * parts of itself (same approximation, smaller textures) rather than refined */
    if (approx_ok && !texture_ok && need.u <= k_node_texels && need.v <= k_node_texels &&
        it->part_depth < MAX_PART_DEPTH) {
        split_part(hf, it, &need);
        return;
    }
    if (approx_ok && texture_ok) {
        if (!planning)
            choose(hf, it, cpw, err_w, eps_obj, &need);
        return;
    }
    if (has_children) {
        push_children(hf, n);
        return;
    }
    if (!approx_ok && (planning || env->walkthrough) && it->part_depth == 0)
        ask_refine(hf, it->node, eps_obj);
    if (!texture_ok && it->part_depth < MAX_PART_DEPTH) {
        split_part(hf, it, &need);
        return;
    }
    if (!planning)
        choose(hf, it, cpw, err_w, eps_obj, &need);
}

static void traverse(hl_face *hf)
{
    static const double k_full[4] = {0.0, 1.0, 0.0, 1.0};
    hf->n_stack = hf->n_chosen = 0;
    hf->n_refine = 0;
    push(hf, hf->h->root, k_full, 0);
    while (hf->n_stack > 0 && !hf->oom) {
        hl_item it = hf->stack[--hf->n_stack];
        visit(hf, &it);
    }
    if (!hf->oom)
        submit_refines(hf);
}

static void hl_face_init(hl_face *hf, const sw__fr_env *env, sw__fr_hierarchy *hy,
                         sw_gpu_frame_stats *st, sw__fr_selection *sel, const occurrence *o,
                         const sw_lod_hierarchy *h)
{
    memset(hf, 0, sizeof *hf);
    hf->env = env;
    hf->hy = hy;
    hf->st = st;
    hf->sel = sel;
    hf->o = o;
    hf->h = h;
    hf->scale = sw_sg_stretch_bound(o->world);
    hf->trimmed = sw__fr_face_trimmed(env, o->face);
}

static void hl_face_free(hl_face *hf)
{
    sw__free(hf->stack);
    sw__free(hf->refine_nodes);
    sw__free(hf->refine_tol);
}

sw_result sw__fr_hierarchy_cut(const sw__fr_env *env, sw__fr_hierarchy *hy, const occurrence *o,
                               const sw_lod_hierarchy *h, sw__fr_selection *sel,
                               sw_gpu_frame_stats *st, sw_status *status)
{
    hl_face hf;
    hl_face_init(&hf, env, hy, st, sel, o, h);
    traverse(&hf);
    const int oom = hf.oom;
    hl_face_free(&hf);
    if (oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY,
                        "face %u: hierarchy traversal out of memory (or over %d nodes)", o->face,
                        MAX_ITEMS_PER_FACE);
    return SW_OK;
}

/* ---- converged mode: build and refine before the cut ------------------------------------------
 */
/* Whether face's hierarchy is to be asked for: once the hierarchies hold their share of the memory
 * budget, only those already built are used; the others are drawn by their Bézier patches (the
 * bound kept, the work done every frame, nothing kept). */
static int may_build(const sw__fr_env *env, const sw__fr_hierarchy *hy, uint32_t face)
{
    return sw_lod_cache_memory(hy->cache) < env->ctx->hierarchy_bytes ||
           sw_lod_cache_state_get(hy->cache, face) != SW_LOD_CACHE_EMPTY;
}

/* Whether requesting `n` more builds could take the hierarchies past their share: at a bound of
 * what a face's hierarchy takes (~2.4 KiB measured, docs/memory.md; 4 KiB with margin). */
static int share_tight(const sw__fr_env *env, const sw__fr_hierarchy *hy, size_t n)
{
    return (double)sw_lod_cache_memory(hy->cache) + 4096.0 * (double)n >=
           (double)env->ctx->hierarchy_bytes;
}

static void wait_group(sw__fr_hierarchy *hy, sw_th_pool *pool, sw_gpu_frame_stats *st);

/* The faces' builds, waited for. Where the hierarchies' share of the memory budget could be spent
 * by them, in batches, looking at the memory between batches (may_build). */
static sw_result request_builds(const sw__fr_env *env, sw__fr_hierarchy *hy,
                                const sw__fr_faces *faces, sw_gpu_frame_stats *st)
{
    enum { BATCH = 32 };
    sw_th_pool *pool = sw_lod_cache_pool(hy->cache);
    for (size_t i = 0; i < faces->n;) {
        const size_t end =
            share_tight(env, hy, faces->n - i) && faces->n - i > BATCH ? i + BATCH : faces->n;
        for (; i < end; ++i) {
            if (!may_build(env, hy, faces->occ[i].face))
                continue;
            sw_result r =
                sw_lod_cache_request_group(hy->cache, faces->occ[i].face, NULL, &hy->group);
            if (r == SW_ERR_OUT_OF_MEMORY)
                return r; /* a FAILED face is drawn by its Bézier patches */
        }
        wait_group(hy, pool, st);
    }
    return SW_OK;
}

/* One planning pass over the faces; returns 0 on out of memory. */
static int plan_round(const sw__fr_env *env, sw__fr_hierarchy *hy, const sw__fr_faces *faces,
                      sw_gpu_frame_stats *st)
{
    int ok = 1;
    for (size_t i = 0; i < faces->n && ok; ++i) {
        const sw_lod_hierarchy *h = sw_lod_cache_get(hy->cache, faces->occ[i].face);
        if (!h)
            continue;
        hl_face hf;
        hl_face_init(&hf, env, hy, st, NULL, &faces->occ[i], h);
        traverse(&hf);
        ok = !hf.oom;
        hl_face_free(&hf);
    }
    return ok;
}

/* Walkthrough: asks for the faces' hierarchies and returns at once. */
static sw_result request_walkthrough(const sw__fr_env *env, sw__fr_hierarchy *hy,
                                     const sw__fr_faces *faces, sw_status *status)
{
    hy->req.priority = SW_TH_PRIORITY_FRAME;
    hy->req.token = env->ctx->walk_token;
    hy->req.generation = sw_th_token_cancel(env->ctx->walk_token);
    for (size_t i = 0; i < faces->n; ++i)
        if (may_build(env, hy, faces->occ[i].face) &&
            sw_lod_cache_request(hy->cache, faces->occ[i].face, &hy->req) == SW_ERR_OUT_OF_MEMORY)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy requests: out of memory");
    return SW_OK;
}

static void wait_group(sw__fr_hierarchy *hy, sw_th_pool *pool, sw_gpu_frame_stats *st)
{
    sw_th_group_wait(pool, &hy->group);
    st->hlod_waits++;
}

static sw_result converge(const sw__fr_env *env, sw__fr_hierarchy *hy, const sw__fr_faces *faces,
                          sw_gpu_frame_stats *st, sw_status *status)
{
    sw_th_pool *pool = sw_lod_cache_pool(hy->cache);
    sw_th_group_init(&hy->group);
    if (request_builds(env, hy, faces, st) != SW_OK) {
        wait_group(hy, pool, st);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy builds: out of memory");
    }
    hy->planning = 1;
    sw_result r = SW_OK;
    for (int round = 0; round < MAX_REFINE_ROUNDS; ++round) {
        hy->refine_asked = 0;
        sw_lod_cache_stats before, after;
        sw_lod_cache_stats_get(hy->cache, &before);
        int ok = plan_round(env, hy, faces, st);
        wait_group(hy, pool, st);
        if (!ok) {
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy traversal: out of memory");
            break;
        }
        if (hy->refine_asked == 0)
            break;
        st->hlod_refine_rounds++;
        sw_lod_cache_stats_get(hy->cache, &after);
        if (after.refinements == before.refinements)
            break; /* nothing could be refined further (depth limits): drawn over budget */
    }
    hy->planning = 0;
    return r;
}

/* ms_hierarchy: the time this stage's thread blocked on the pool, in both modes (not the stage's
 * wall time: its planning traversals are work, not waiting). */
sw_result sw__fr_hierarchy_prepare(const sw__fr_env *env, sw__fr_hierarchy *hy,
                                   const sw__fr_faces *faces, sw_gpu_frame_stats *st,
                                   sw_status *status)
{
    const sw_th_wait_count w0 = sw_th_thread_waits();
    sw_result r = env->walkthrough ? request_walkthrough(env, hy, faces, status)
                                   : converge(env, hy, faces, st, status);
    st->ms_hierarchy += 1e-6 * (double)(sw_th_thread_waits().ns - w0.ns);
    return r;
}

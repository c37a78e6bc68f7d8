/* The frame's traversal of the faces' bicubic hierarchies (Guthe et al. 2005 §7 over the §6
 * hierarchies of lod/hierarchy_cache.c).
 *
 * Per face occurrence, from the root down: a node whose box (grown by its error) misses the
 * frustum is culled; a node is drawn when its approximation error, in world units, is at most half
 * the object-space tolerance ε_obj that ε_img allows at the nearest depth of its box (§7 splits ε
 * equally between approximation and sampling), and — on a trimmed face — when its own trim texture
 * needs at most k_tile_texels per direction; otherwise its children are visited. A leaf that is
 * still too coarse is refined below itself in the pool (sw_lod_cache_refine; converged mode waits
 * for it, sw__fr_hlod_prepare); a leaf whose trim texture would be too large is cut into parts of
 * its own bicubic (same error bound, smaller box and texture), which is also what keeps a close-up
 * at 1/10,000 of a model within the maximum texture size (§7: "the hierarchy splits").
 *
 * The error budget of a drawn node is rigorous, not the paper's 50/50 guess: the node's bound e
 * (distance between the exact surface and the bicubic at the same parameters, lod/error_bound.c)
 * projects to at most e_px = ε_img e / ε_obj(z_min) pixels, and the grid density is chosen for the
 * rest, ε_img - e_px (sw_lod_screen_segments, which bounds the grid against the bicubic on
 * screen). Each drawn node gets its own trim texture over its rectangle (nodes wholly inside the
 * trimmed region need none; nodes outside it are not drawn) and, when the face is drawn as more
 * than one node, a fat border along its rectangle, since neighbouring nodes are different bicubics
 * sampled at different densities (§7.1); the border carries the node's trim lookup, so that it does
 * not show in trimmed-away parts.
 */
#include "frame_internal.h"
#include "sw_hooks.h"
#include "sw_lod_bezier.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_ITEMS_PER_FACE = 16384, /* nodes (or parts) drawn for one face occurrence */
    MAX_PART_DEPTH =
        48, /* halvings of a leaf's domain for its trim texture (2^-24 per direction) */
    MAX_REFINE_ROUNDS = 8,
};

/* A node, or a part [s0,s1] x [t0,t1] of its local domain (part_depth > 0). */
typedef struct hl_item {
    int32_t node, part_depth;
    double range[4];
} hl_item;

typedef struct hl_choice {
    hl_item it;
    double cpw[64]; /* the item's bicubic, eye-relative world, homogeneous */
    double rect[4]; /* its rectangle in face parameters */
    double err_w;   /* its error bound in world units */
    double eps_obj; /* ε_obj at its nearest depth */
    trim_need need; /* trim texels over rect */
} hl_choice;

typedef struct hl_face {
    frame *f;
    const occurrence *o;
    const sw_lod_hierarchy *h;
    double scale; /* bounds the occurrence transform's stretch (sw__fr_stretch_bound) */
    int trimmed;
    hl_item *stack;
    size_t n_stack, cap_stack;
    hl_choice *chosen;
    size_t n_chosen, cap_chosen;
    int32_t *refine_nodes; /* leaves to refine below (planning and walkthrough) */
    double *refine_tol;
    size_t n_refine, cap_refine, cap_refine_tol;
    int oom;
} hl_face;

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
        sw__fr_xform_h(hf->o->world, hf->f->view.eye, src + 4 * i, cpw + 4 * i);
        sw__fr_box_add(box, cpw + 4 * i);
    }
}

/* Eye-relative box of a node that holds no bicubic (from its children's boxes). */
static void node_box(const hl_face *hf, const sw_lod_hnode *n, double box[6])
{
    sw__fr_box_empty(box);
    for (int c = 0; c < 8; ++c) {
        double p[4] = {n->box[(c & 1) ? 3 : 0], n->box[(c & 2) ? 4 : 1], n->box[(c & 4) ? 5 : 2],
                       1.0},
               q[4];
        sw__fr_xform_h(hf->o->world, hf->f->view.eye, p, q);
        sw__fr_box_add(box, q);
    }
}

static int push(hl_face *hf, int32_t node, const double range[4], int32_t part_depth)
{
    if (!sw__gpu_grow((void **)&hf->stack, &hf->cap_stack, hf->n_stack + 1, sizeof *hf->stack)) {
        hf->oom = 1;
        return 0;
    }
    hl_item *it = &hf->stack[hf->n_stack++];
    it->node = node;
    it->part_depth = part_depth;
    memcpy(it->range, range, sizeof it->range);
    return 1;
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
    if (hf->n_chosen >= MAX_ITEMS_PER_FACE || !sw__gpu_grow((void **)&hf->chosen, &hf->cap_chosen,
                                                            hf->n_chosen + 1, sizeof *hf->chosen)) {
        hf->oom = 1;
        return;
    }
    hl_choice *c = &hf->chosen[hf->n_chosen++];
    c->it = *it;
    memcpy(c->cpw, cpw, sizeof c->cpw);
    item_rect(&hf->h->nodes[it->node], it->range, c->rect);
    c->err_w = err_w;
    c->eps_obj = eps_obj;
    c->need = *need;
    if (!(err_w <= 0.5 * eps_obj))
        hf->f->st.hlod_over_budget++;
}

/* In planning rounds and walkthrough frames: a leaf to refine below, to a tolerance in the
 * surface's units (asked for together after the traversal, submit_refines). */
static void ask_refine(hl_face *hf, int32_t node, double eps_obj)
{
    double tol = 0.5 * eps_obj / hf->scale;
    if (!(tol > 0.0) || !isfinite(tol))
        return;
    if (!sw__gpu_grow((void **)&hf->refine_nodes, &hf->cap_refine, hf->n_refine + 1,
                      sizeof *hf->refine_nodes) ||
        !sw__gpu_grow((void **)&hf->refine_tol, &hf->cap_refine_tol, hf->n_refine + 1,
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
    frame *f = hf->f;
    if (hf->n_refine == 0)
        return;
    sw_lod_refine_outcome out = SW_LOD_REFINE_DONE;
    if (sw_lod_cache_refine_leaves(f->cache, hf->o->face, hf->refine_nodes, hf->refine_tol,
                                   (uint32_t)hf->n_refine, f->walkthrough ? &f->req : NULL,
                                   f->walkthrough ? NULL : &f->group, &out) == SW_OK &&
        (out == SW_LOD_REFINE_SUBMITTED || out == SW_LOD_REFINE_BUSY)) {
        f->refine_asked++;
        f->st.hlod_refine_requests += (uint64_t)f->walkthrough;
    }
}

/* Visits one item: culls it, draws it, or goes below it. */
static void visit(hl_face *hf, const hl_item *it)
{
    frame *f = hf->f;
    const sw_lod_hnode *n = &hf->h->nodes[it->node];
    const int representable = (n->flags & SW_LOD_HNODE_REPRESENTABLE) != 0;
    const int has_children = n->child[0] >= 0 && it->part_depth == 0;
    double cpw[64], box[6];
    if (!representable) {
        node_box(hf, n, box); /* its surface bound is the children's: never culled here */
        if (has_children) {
            static const double k_full[4] = {0.0, 1.0, 0.0, 1.0};
            push(hf, n->child[0], k_full, 0);
            push(hf, n->child[1], k_full, 0);
        }
        return;
    }
    item_net(hf, n, it->range, cpw, box);
    double err_w = n->error * hf->scale;
    for (int k = 0; k < 3; ++k) {
        box[k] -= err_w;
        box[3 + k] += err_w;
    }
    if (!sw__gpu_view_box_visible(&f->view, box)) {
        if (!f->planning)
            f->st.patches_culled++;
        return;
    }
    double z = sw__gpu_view_box_depth(&f->view, box);
    double eps_obj =
        sw_lod_object_tolerance(f->eps_px, z, f->view.focal_px, f->view.tan_x, f->view.tan_y);
    trim_need need = {1.0, 1.0};
    if (hf->trimmed) {
        need.u = fmax(1.0, n->tex_c[0] * hf->scale * (it->range[1] - it->range[0]) / eps_obj);
        need.v = fmax(1.0, n->tex_c[1] * hf->scale * (it->range[3] - it->range[2]) / eps_obj);
    }
    int approx_ok = err_w <= 0.5 * eps_obj;
    int texture_ok = need.u <= k_tile_texels && need.v <= k_tile_texels;
    if (approx_ok && texture_ok) {
        if (!f->planning)
            choose(hf, it, cpw, err_w, eps_obj, &need);
        return;
    }
    if (has_children) {
        static const double k_full[4] = {0.0, 1.0, 0.0, 1.0};
        push(hf, n->child[0], k_full, 0);
        push(hf, n->child[1], k_full, 0);
        return;
    }
    if (!approx_ok && (f->planning || f->walkthrough) && it->part_depth == 0)
        ask_refine(hf, it->node, eps_obj);
    if (!texture_ok && it->part_depth < MAX_PART_DEPTH) {
        split_part(hf, it, &need);
        return;
    }
    if (!f->planning)
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

static void hl_face_init(hl_face *hf, frame *f, const occurrence *o, const sw_lod_hierarchy *h)
{
    memset(hf, 0, sizeof *hf);
    hf->f = f;
    hf->o = o;
    hf->h = h;
    hf->scale = sw__fr_stretch_bound(o->world);
    const sw_sg_face_rec *rec = &f->sv->faces[o->face];
    hf->trimmed = (rec->flags & SW_SG_FACE_TRIMMED) && rec->n_loops > 0;
}

static void hl_face_free(hl_face *hf)
{
    sw__free(hf->stack);
    sw__free(hf->chosen);
    sw__free(hf->refine_nodes);
    sw__free(hf->refine_tol);
}

/* ---- converged mode: build and refine before drawing ------------------------------------------
 */
static sw_result request_builds(frame *f, const double *boxes)
{
    for (size_t i = 0; i < f->n_occ; ++i) {
        if (!sw__gpu_view_box_visible(&f->view, boxes + 6 * i))
            continue;
        sw_result r = sw_lod_cache_request_group(f->cache, f->occ[i].face, NULL, &f->group);
        if (r == SW_ERR_OUT_OF_MEMORY)
            return r; /* a FAILED face is drawn by its Bézier patches */
    }
    return SW_OK;
}

/* One planning pass over the visible occurrences; returns 0 on out of memory. */
static int plan_round(frame *f, const double *boxes)
{
    int ok = 1;
    for (size_t i = 0; i < f->n_occ && ok; ++i) {
        if (!sw__gpu_view_box_visible(&f->view, boxes + 6 * i))
            continue;
        const sw_lod_hierarchy *h = sw_lod_cache_get(f->cache, f->occ[i].face);
        if (!h)
            continue;
        hl_face hf;
        hl_face_init(&hf, f, &f->occ[i], h);
        traverse(&hf);
        ok = !hf.oom;
        hl_face_free(&hf);
    }
    return ok;
}

/* Walkthrough: asks for the visible faces' hierarchies and returns at once. */
static sw_result request_walkthrough(frame *f, const double *boxes, sw_status *status)
{
    f->walkthrough = 1;
    f->req.priority = SW_TH_PRIORITY_FRAME;
    f->req.token = f->ctx->walk_token;
    f->req.generation = sw_th_token_cancel(f->ctx->walk_token);
    for (size_t i = 0; i < f->n_occ; ++i)
        if (sw__gpu_view_box_visible(&f->view, boxes + 6 * i) &&
            sw_lod_cache_request(f->cache, f->occ[i].face, &f->req) == SW_ERR_OUT_OF_MEMORY)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy requests: out of memory");
    return SW_OK;
}

static void wait_group(frame *f, sw_th_pool *pool)
{
    sw_th_group_wait(pool, &f->group);
    f->st.hlod_waits++;
}

sw_result sw__fr_hlod_prepare(frame *f, const double *boxes, int walkthrough, sw_status *status)
{
    if (walkthrough)
        return request_walkthrough(f, boxes, status);
    double t0 = sw__gpu_now_ms();
    sw_th_pool *pool = sw_lod_cache_pool(f->cache);
    sw_th_group_init(&f->group);
    if (request_builds(f, boxes) != SW_OK) {
        wait_group(f, pool);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy builds: out of memory");
    }
    wait_group(f, pool);
    f->planning = 1;
    for (int round = 0; round < MAX_REFINE_ROUNDS; ++round) {
        f->refine_asked = 0;
        sw_lod_cache_stats before, after;
        sw_lod_cache_stats_get(f->cache, &before);
        int ok = plan_round(f, boxes);
        wait_group(f, pool);
        if (!ok) {
            f->planning = 0;
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy traversal: out of memory");
        }
        if (f->refine_asked == 0)
            break;
        f->st.hlod_refine_rounds++;
        sw_lod_cache_stats_get(f->cache, &after);
        if (after.refinements == before.refinements)
            break; /* nothing could be refined further (depth limits): drawn over budget */
    }
    f->planning = 0;
    f->st.ms_hierarchy = sw__gpu_now_ms() - t0;
    return SW_OK;
}

/* ---- exact degree of a node's bicubic ----------------------------------------------------------
 * Planes, cylinders and cones reach the hierarchy as degree-elevated bicubics. Their derivative
 * bounds (lod/sampling.c, products of degree 3p x 3q) cost ~6x more at degree 3 than at the true
 * degree, and the bound is the same surface's: so the density is computed at the lowest degree
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

/* ---- drawing the chosen items ------------------------------------------------------------------
 */
/* The item as a patch of the direct path: clipped to the face's trim box, density for what its
 * approximation error leaves of ε_img. */
static void item_patch(const hl_face *hf, hl_choice *c, sw__gpu_patch *pt)
{
    frame *f = hf->f;
    const double *ub = f->sv->faces[hf->o->face].uv_box;
    memset(pt, 0, sizeof *pt);
    pt->deg_u = pt->deg_v = 3;
    pt->cpw = c->cpw;
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
        return;
    pt->visible = 1;
    sw_lod_screen_view scr = f->screen;
    double approx_px = f->eps_px * c->err_w / c->eps_obj;
    scr.eps_px = fmax(f->eps_px - approx_px, 0.25 * f->eps_px);
    const double range[4] = {pt->s0, pt->s1, pt->t0, pt->t1};
    double low[64];
    int32_t deg_u, deg_v;
    lowest_degree(c->cpw, low, &deg_u, &deg_v);
    sw_lod_screen_density d;
    sw_lod_screen_segments(deg_u, deg_v, low, range, &scr, f->gpu_segments.n, f->gpu_segments.count,
                           MAX_BOUND_SUBDIVISION, &d);
    pt->eps = d.eps_obj;
    pt->nu = d.nu;
    pt->nv = d.nv;
    if (hf->trimmed) { /* tighter than the node's constants: bounds of this range, at full ε_img */
        double eps_t = d.eps_obj * f->eps_px / scr.eps_px;
        c->need.u = sw_lod_trim_texels(1.0, d.d1[0], 1.0, eps_t); /* over the item */
        c->need.v = sw_lod_trim_texels(1.0, d.d1[1], 1.0, eps_t);
    }
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
    frame *f = hf->f;
    if (!on_gpu && f->ctx->patch_hook)
        sw__fr_report_patch(f, hf->o, pt, pt->s0, pt->s1, pt->t0, pt->t1, pt->nu, pt->nv, 0,
                            trimmed);
    f->st.hlod_nodes++;
    f->st.patches_gpu_evaluated += (uint64_t)on_gpu;
    *(trimmed ? &f->st.patches_trimmed : &f->st.patches_untrimmed) += 1;
}

/* §7.1 between nodes of one face: a fat border along the item's rectangle (counter-clockwise),
 * trimmed by the texture of draw `share` over st_box when given. */
static sw_result item_border(hl_face *hf, const hl_choice *c, const double cell[2],
                             const double *st_box, size_t share, sw_status *status)
{
    const double *b = c->rect;
    const double loop[8] = {b[0], b[2], b[1], b[2], b[1], b[3], b[0], b[3]};
    return sw__fr_fat_border(hf->f, hf->o, loop, 4, 1, cell, st_box, share, status);
}

/* Per-item trim textures (a face whose one texture would be too large): the item's own draw,
 * trimmed over its rectangle when a loop crosses it, untrimmed when inside, nothing when outside.
 */
static sw_result draw_item_own(hl_face *hf, hl_choice *c, const sw__gpu_patch *pt, int64_t loops,
                               double sign, int on_gpu, sw_status *status)
{
    frame *f = hf->f;
    int cls = item_class(&f->loops[loops], c->rect);
    if (cls < 0)
        return SW_OK;
    int trimmed = cls == 0;
    double cell[2];
    item_cell(pt, cell);
    size_t draw = f->n_draws, first = f->mesh.n_idx;
    sw_result r;
    if (on_gpu) {
        r = sw__fr_add_draw(f, hf->o, first, trimmed, &c->need, cell, status);
        if (r == SW_OK)
            r = sw__fr_gpu_patch(f, hf->o, pt, c->rect, sign, (int32_t)draw, trimmed, status);
    } else {
        r = sw__gpu_tessellate_face(pt, 1, 1, sign, c->rect, &f->mesh, status);
        if (r == SW_OK)
            r = sw__fr_add_draw(f, hf->o, first, trimmed, &c->need, cell, status);
    }
    if (r == SW_OK && trimmed) {
        pending_trim *t = &f->trims[f->n_trims - 1];
        t->loops = loops;
        memcpy(t->rect, c->rect, sizeof t->rect);
    }
    count_item(hf, pt, on_gpu, trimmed);
    if (r == SW_OK && hf->n_chosen > 1 && !f->ctx->crack_fill_off)
        r = item_border(hf, c, cell, trimmed ? c->rect : NULL, draw, status);
    return r;
}

/* The finest trim texel of the chosen items, halved: the loops' flattening tolerance. */
static double loop_tolerance(const hl_face *hf)
{
    int32_t max_entry = sw__gpu_atlas_max_entry(hf->f->ctx);
    double tol = INFINITY;
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        const hl_choice *c = &hf->chosen[i];
        tol =
            fmin(tol, 0.5 * (c->rect[1] - c->rect[0]) / sw__fr_class_texels(c->need.u, max_entry));
        tol =
            fmin(tol, 0.5 * (c->rect[3] - c->rect[2]) / sw__fr_class_texels(c->need.v, max_entry));
    }
    return tol;
}

static sw_result draw_own_textures(hl_face *hf, sw__gpu_patch *pts, double sign, int on_gpu,
                                   const double cell_min[2], sw_status *status)
{
    frame *f = hf->f;
    int64_t loops = -1;
    sw_result r = sw__fr_face_loops(f, hf->o->face, loop_tolerance(hf), &loops, status);
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK; ++i)
        if (pts[i].visible)
            r = draw_item_own(hf, &hf->chosen[i], &pts[i], loops, sign, on_gpu, status);
    const face_loops *fl = r == SW_OK ? &f->loops[loops] : NULL;
    for (uint32_t k = 0; fl && !f->ctx->crack_fill_off && k < fl->n && r == SW_OK; ++k)
        r = sw__fr_fat_border(f, hf->o, fl->loops[k].uv, fl->loops[k].count,
                              sw__fr_left_is_inside(fl->loops, fl->n, k), cell_min, NULL, 0,
                              status);
    return r;
}

/* One draw for the whole face (one trim texture over its trim box, as the direct path). */
static sw_result draw_one_texture(hl_face *hf, sw__gpu_patch *pts, double sign, int on_gpu,
                                  const trim_need *need, const double cell_min[2],
                                  sw_status *status)
{
    frame *f = hf->f;
    const double *ub = f->sv->faces[hf->o->face].uv_box;
    size_t draw = f->n_draws, first = f->mesh.n_idx;
    sw_result r =
        on_gpu ? sw__fr_add_draw(f, hf->o, first, hf->trimmed, need, cell_min, status) : SW_OK;
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK; ++i) {
        if (!pts[i].visible)
            continue;
        r = on_gpu
                ? sw__fr_gpu_patch(f, hf->o, &pts[i], ub, sign, (int32_t)draw, hf->trimmed, status)
                : sw__gpu_tessellate_face(&pts[i], 1, 1, sign, ub, &f->mesh, status);
        count_item(hf, &pts[i], on_gpu, hf->trimmed);
    }
    if (r == SW_OK && !on_gpu)
        r = sw__fr_add_draw(f, hf->o, first, hf->trimmed, need, cell_min, status);
    for (size_t i = 0; i < hf->n_chosen && r == SW_OK && hf->n_chosen > 1; ++i) {
        double cell[2];
        item_cell(&pts[i], cell);
        if (pts[i].visible && !f->ctx->crack_fill_off)
            r = item_border(hf, &hf->chosen[i], cell, hf->trimmed ? ub : NULL, draw, status);
    }
    if (r == SW_OK && !hf->trimmed && !f->ctx->crack_fill_off) {
        /* a trimmed face's loops get theirs with its trim texture (frame.c make_trim) */
        const double box_loop[8] = {ub[0], ub[2], ub[1], ub[2], ub[1], ub[3], ub[0], ub[3]};
        r = sw__fr_fat_border(f, hf->o, box_loop, 4, 1, cell_min, NULL, 0, status);
    }
    return r;
}

/* Texels of one texture over the face's trim box that serve every chosen item. */
static trim_need face_need(const hl_face *hf, const sw__gpu_patch *pts)
{
    const double *ub = hf->f->sv->faces[hf->o->face].uv_box;
    trim_need n = {1.0, 1.0};
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        const hl_choice *c = &hf->chosen[i];
        if (!pts[i].visible)
            continue;
        n.u = fmax(n.u, c->need.u * (ub[1] - ub[0]) / (c->rect[1] - c->rect[0]));
        n.v = fmax(n.v, c->need.v * (ub[3] - ub[2]) / (c->rect[3] - c->rect[2]));
    }
    return n;
}

static sw_result draw_chosen(hl_face *hf, sw_status *status)
{
    frame *f = hf->f;
    const occurrence *o = hf->o;
    const sw_sg_face_rec *rec = &f->sv->faces[o->face];
    double sign = (rec->flags & SW_SG_FACE_REVERSED) ? -1.0 : 1.0;
    if (sw__fr_det3(o->world) < 0.0)
        sign = -sign;
    int on_gpu = f->ctx->eval_mode == SW__GPU_EVAL_AUTO;
    sw__gpu_patch *pts = sw__malloc((hf->n_chosen ? hf->n_chosen : 1) * sizeof *pts);
    if (!pts)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u: out of memory", o->face);
    double cell[2] = {INFINITY, INFINITY};
    for (size_t i = 0; i < hf->n_chosen; ++i) {
        item_patch(hf, &hf->chosen[i], &pts[i]);
        double c[2];
        item_cell(&pts[i], c);
        if (pts[i].visible) {
            cell[0] = fmin(cell[0], c[0]);
            cell[1] = fmin(cell[1], c[1]);
        }
    }
    sw_result r = SW_OK;
    if (cell[0] < INFINITY) {
        trim_need need = face_need(hf, pts);
        r = hf->trimmed && (need.u > k_tile_texels || need.v > k_tile_texels)
                ? draw_own_textures(hf, pts, sign, on_gpu, cell, status)
                : draw_one_texture(hf, pts, sign, on_gpu, &need, cell, status);
        f->st.faces_drawn++;
    } else {
        f->st.faces_culled++;
    }
    sw__free(pts);
    return r;
}

sw_result sw__fr_hlod_draw_face(frame *f, const occurrence *o, sw_status *status)
{
    const sw_lod_hierarchy *h = sw_lod_cache_get(f->cache, o->face);
    if (!h) {
        f->st.hlod_fallback_faces++;
        return sw__fr_draw_face(f, o, status);
    }
    hl_face hf;
    hl_face_init(&hf, f, o, h);
    traverse(&hf);
    sw_result r = hf.oom ? sw__fail(status, SW_ERR_OUT_OF_MEMORY,
                                    "face %u: hierarchy traversal out of memory (or over %d "
                                    "nodes)",
                                    o->face, MAX_ITEMS_PER_FACE)
                         : draw_chosen(&hf, status);
    hl_face_free(&hf);
    return r;
}

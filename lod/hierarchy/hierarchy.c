/* SPDX-License-Identifier: MIT */
/* The per-surface bicubic hierarchy of Guthe et al. 2005 §6 (Fig. 7): Bézier extraction (§6),
 * the box cut of §4.4, a subdivision tree per Bézier patch from degree_reduce.c (blue), a median
 * cut over the patch grid along the longer parameter direction whose pairs are simplified bottom-up
 * by simplify.c (green), and per node the derivative constants of sw_lod_hierarchy.h.
 *
 * Error bookkeeping. A blue node's error is the direct bound of error_bound.c between the exact
 * patch piece and its bicubic, raised to its children's (so a coarser node never claims less). A
 * green node N joining children C_0, C_1 has, on child k's part, |S - N| <= |S - C_k| + |C_k - N|
 * <= e_k + s_k (triangle inequality; s_k the simplification bound on that part), so its error is
 * max_k (e_k + s_k) — the paper's "children's error + simplification error", taken per part.
 * Pairs meeting at a crease (tangent discontinuity), or with a child that is not representable,
 * are not joined: the node keeps only its rectangle and children, and the renderer descends.
 */
#include "sw_lod_hierarchy.h"
#include "sw_hooks.h"

#include "sw_lod_bezier.h"
#include "sw_lod_reduce.h"
#include "sw_lod_sampling.h"
#include "sw_status_util.h"

#include <stdlib.h>
#include <string.h>

typedef struct builder {
    sw_lod_hierarchy *h;
    int32_t cap;
    const sw_lod_hierarchy_desc *desc;
    const sw_sg_bezier_set *set;
    double (*rects)[4];   /* per patch: its rectangle in surface parameters (box-cut) */
    double **nets;        /* per patch: control points over that rectangle */
    double patch_rect[4]; /* the patch whose subtree is being built */
    sw_status *status;
} builder;

static int32_t new_node(builder *b)
{
    sw_lod_hierarchy *h = b->h;
    if (h->n_nodes == b->cap) {
        int32_t cap = b->cap ? 2 * b->cap : 64;
        sw_lod_hnode *grown = sw__realloc(h->nodes, (size_t)cap * sizeof *grown);
        if (!grown)
            return -1;
        h->nodes = grown;
        b->cap = cap;
    }
    sw_lod_hnode *n = &h->nodes[h->n_nodes];
    memset(n, 0, sizeof *n);
    n->child[0] = n->child[1] = n->parent = -1;
    return h->n_nodes++;
}

/* Box of the control points, derivative constants, representable flag. */
static void finish_bicubic(sw_lod_hnode *n)
{
    for (int a = 0; a < 3; ++a) {
        n->box[a] = INFINITY;
        n->box[3 + a] = -INFINITY;
    }
    for (int k = 0; k < 16; ++k)
        for (int a = 0; a < 3; ++a) {
            const double x = n->cpw[k * 4 + a] / n->cpw[k * 4 + 3];
            n->box[a] = fmin(n->box[a], x);
            n->box[3 + a] = fmax(n->box[3 + a], x);
        }
    sw_lod_patch_bounds pb;
    sw_lod_rational_bezier_bounds(3, 3, n->cpw, &pb);
    n->seg_c[0] = 0.5 * sqrt(pb.d2[0] + pb.d2[1]);
    n->seg_c[1] = 0.5 * sqrt(pb.d2[2] + pb.d2[1]);
    n->tex_c[0] = pb.d1[0];
    n->tex_c[1] = pb.d1[1];
    n->flags |= SW_LOD_HNODE_REPRESENTABLE;
}

static void link_child(sw_lod_hierarchy *h, int32_t parent, int32_t child)
{
    sw_lod_hnode *p = &h->nodes[parent];
    p->child[p->child[0] < 0 ? 0 : 1] = child;
    h->nodes[child].parent = parent;
}

/* ---- blue: one Bézier patch's subdivision tree ------------------------------------------------
 */
static int32_t visit_patch_node(void *ctx, const sw_lod_reduce_node *rn)
{
    builder *b = ctx;
    const int32_t id = new_node(b);
    if (id < 0)
        return -1;
    sw_lod_hnode *n = &b->h->nodes[id];
    const double *pr = b->patch_rect;
    n->rect[0] = pr[0] + rn->rect[0] * (pr[1] - pr[0]);
    n->rect[1] = pr[0] + rn->rect[1] * (pr[1] - pr[0]);
    n->rect[2] = pr[2] + rn->rect[2] * (pr[3] - pr[2]);
    n->rect[3] = pr[2] + rn->rect[3] * (pr[3] - pr[2]);
    memcpy(n->cpw, rn->cpw, sizeof n->cpw);
    n->error = rn->error;
    n->split_dir = rn->split_dir;
    n->flags = SW_LOD_HNODE_IN_PATCH;
    finish_bicubic(n);
    if (rn->parent >= 0)
        link_child(b->h, rn->parent, id);
    if (rn->leaf) {
        ++b->h->n_leaves;
        if (rn->error > b->h->leaf_tolerance)
            ++b->h->leaves_over_tolerance;
    }
    return id;
}

static sw_result build_patch(builder *b, int32_t k, int32_t *root)
{
    const sw_sg_bezier_patch *p = &b->set->patches[k];
    const int32_t first = b->h->n_nodes;
    memcpy(b->patch_rect, b->rects[k], sizeof b->patch_rect);
    const sw_lod_reduce_desc rd = {b->h->leaf_tolerance,
                                   b->desc->max_depth > 0 ? b->desc->max_depth : 8, b->desc->error};
    sw_result res =
        sw_lod_reduce_tree(p->deg_u, p->deg_v, b->nets[k], &rd, visit_patch_node, b, b->status);
    if (res != SW_OK)
        return res;
    /* pre-order: children come after their parent, so one backward pass makes errors monotone */
    for (int32_t i = b->h->n_nodes - 1; i > first; --i) {
        sw_lod_hnode *n = &b->h->nodes[i], *par = &b->h->nodes[n->parent];
        par->error = fmax(par->error, n->error);
    }
    *root = first;
    return SW_OK;
}

/* ---- green: median cut and pairwise simplification --------------------------------------------
 */
/* Whether the exact surface has a crease along the edge between the two halves of a block: the
 * Bézier patches on both sides of it, compared before any approximation. */
static int block_crease(const builder *b, int32_t a0, int32_t a1, int32_t b0, int32_t b1, int dir,
                        int32_t am, int32_t bm)
{
    const double limit = b->desc->crease_angle > 0.0 ? b->desc->crease_angle : 0.35;
    const int32_t nu = b->set->n_u, count = dir ? a1 - a0 : b1 - b0;
    for (int32_t k = 0; k < count; ++k) {
        const int32_t lo = dir ? (bm - 1) * nu + a0 + k : (b0 + k) * nu + am - 1;
        const int32_t hi = dir ? bm * nu + a0 + k : (b0 + k) * nu + am;
        const sw_sg_bezier_patch *pl = &b->set->patches[lo], *ph = &b->set->patches[hi];
        if (sw_lod_crease_angle(pl->deg_u, pl->deg_v, b->nets[lo], ph->deg_u, ph->deg_v,
                                b->nets[hi], dir) > limit)
            return 1;
    }
    return 0;
}

static void join(builder *b, int32_t id, double s, int creased)
{
    sw_lod_hierarchy *h = b->h;
    sw_lod_hnode *n = &h->nodes[id];
    const sw_lod_hnode *c0 = &h->nodes[n->child[0]], *c1 = &h->nodes[n->child[1]];
    for (int a = 0; a < 3; ++a) {
        n->box[a] = fmin(c0->box[a], c1->box[a]);
        n->box[3 + a] = fmax(c0->box[3 + a], c1->box[3 + a]);
    }
    n->error = INFINITY;
    if (creased || !(c0->flags & c1->flags & SW_LOD_HNODE_REPRESENTABLE))
        return;
    sw_lod_simplify_result sr;
    if (sw_lod_simplify_pair(c0->cpw, c1->cpw, n->split_dir, s, &b->desc->error, &sr, NULL) !=
        SW_OK)
        return; /* out of scratch memory: leave the pair unjoined, still correct */
    const double e = fmax(c0->error + sr.error[0], c1->error + sr.error[1]);
    if (!isfinite(e))
        return;
    memcpy(n->cpw, sr.cpw, sizeof n->cpw);
    n->error = e;
    finish_bicubic(n);
}

static double block_extent(const builder *b, int32_t a0, int32_t a1, int32_t b0, int32_t b1,
                           int dir)
{
    const int32_t nu = b->set->n_u;
    const double *lo = b->rects[b0 * nu + a0], *hi = b->rects[(b1 - 1) * nu + (a1 - 1)];
    return dir ? hi[3] - lo[2] : hi[1] - lo[0];
}

static sw_result build_block(builder *b, int32_t a0, int32_t a1, int32_t b0, int32_t b1,
                             int32_t *out)
{
    if (a1 - a0 == 1 && b1 - b0 == 1)
        return build_patch(b, b0 * b->set->n_u + a0, out);
    int dir = block_extent(b, a0, a1, b0, b1, 1) > block_extent(b, a0, a1, b0, b1, 0);
    if ((dir ? b1 - b0 : a1 - a0) < 2)
        dir = !dir;
    const int32_t am = dir ? a1 : (a0 + a1) / 2, bm = dir ? (b0 + b1) / 2 : b1;
    int32_t lo, hi;
    sw_result res = build_block(b, a0, am, b0, bm, &lo);
    if (res == SW_OK)
        res = build_block(b, dir ? a0 : am, a1, dir ? bm : b0, b1, &hi);
    if (res != SW_OK)
        return res;
    const int32_t id = new_node(b);
    if (id < 0)
        return sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "hierarchy: %d nodes", (int)b->cap);
    sw_lod_hnode *n = &b->h->nodes[id];
    const sw_lod_hnode *l = &b->h->nodes[lo], *r = &b->h->nodes[hi];
    n->rect[0] = l->rect[0];
    n->rect[1] = r->rect[1];
    n->rect[2] = l->rect[2];
    n->rect[3] = r->rect[3];
    n->split_dir = dir;
    link_child(b->h, id, lo);
    link_child(b->h, id, hi);
    const int k = 2 * dir;
    const double s = (l->rect[k + 1] - l->rect[k]) / (r->rect[k + 1] - l->rect[k]);
    join(b, id, s, block_crease(b, a0, a1, b0, b1, dir, am, bm));
    *out = id;
    return SW_OK;
}

/* ---- setup ----------------------------------------------------------------------------------- */
static double net_diagonal(const sw_sg_surface *s)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const size_t n = (size_t)s->n_u * (size_t)s->n_v;
    for (size_t k = 0; k < n; ++k)
        for (int a = 0; a < 3; ++a) {
            const double x = s->cpw[k * 4 + a] / s->cpw[k * 4 + 3];
            lo[a] = fmin(lo[a], x);
            hi[a] = fmax(hi[a], x);
        }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

sw_result sw_lod_bezier_set_cut(sw_sg_bezier_set *set, const double uv_box[4], sw_status *status)
{
    const double *box = uv_box;
    for (int32_t k = 0; k < set->n_u * set->n_v; ++k) {
        sw_sg_bezier_patch *p = &set->patches[k];
        const double r[4] = {fmax(p->u0, box[0]), fmin(p->u1, box[1]), fmax(p->v0, box[2]),
                             fmin(p->v1, box[3])};
        if (!(r[0] < r[1] && r[2] < r[3]))
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "uv box misses patch %d", (int)k);
        const double local[4] = {(r[0] - p->u0) / (p->u1 - p->u0), (r[1] - p->u0) / (p->u1 - p->u0),
                                 (r[2] - p->v0) / (p->v1 - p->v0),
                                 (r[3] - p->v0) / (p->v1 - p->v0)};
        /* the extraction owns p->cpw: cut in place */
        sw_lod_bez_restrict(p->deg_u, p->deg_v, 4, p->cpw, local, p->cpw);
        p->u0 = r[0], p->u1 = r[1], p->v0 = r[2], p->v1 = r[3];
    }
    return SW_OK;
}

/* Each patch's rectangle (after the box cut, §4.4) and its control points over it. */
static sw_result cut_patches(builder *b)
{
    const sw_sg_bezier_set *set = b->set;
    const int32_t np = set->n_u * set->n_v;
    b->rects = sw__malloc((size_t)np * sizeof *b->rects);
    b->nets = sw__calloc((size_t)np, sizeof *b->nets);
    if (!b->rects || !b->nets)
        return sw__fail(b->status, SW_ERR_OUT_OF_MEMORY, "hierarchy: %d patches", (int)np);
    for (int32_t k = 0; k < np; ++k) {
        const sw_sg_bezier_patch *p = &set->patches[k];
        double *r = b->rects[k];
        r[0] = p->u0, r[1] = p->u1, r[2] = p->v0, r[3] = p->v1;
        b->nets[k] = p->cpw;
    }
    return SW_OK;
}

sw_result sw_lod_hierarchy_build(const sw_sg_surface *s, const sw_lod_hierarchy_desc *desc,
                                 sw_lod_hierarchy **out, sw_status *status)
{
    const sw_lod_hierarchy_desc d = desc ? *desc : (sw_lod_hierarchy_desc){0};
    *out = NULL;
    sw_sg_bezier_set set;
    sw_result res = d.use_box
                        ? sw_sg_surface_extract_bezier_in(s, d.uv_box[0], d.uv_box[1], d.uv_box[2],
                                                          d.uv_box[3], &set, status)
                        : sw_sg_surface_extract_bezier(s, &set, status);
    if (res != SW_OK)
        return res;
    if (set.n_u * set.n_v == 0) {
        sw_sg_bezier_set_free(&set);
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "hierarchy: uv box misses the domain");
    }
    if (d.use_box && (res = sw_lod_bezier_set_cut(&set, d.uv_box, status)) != SW_OK) {
        sw_sg_bezier_set_free(&set);
        return res;
    }
    sw_lod_hierarchy *h = sw__calloc(1, sizeof *h);
    builder b = {h, 0, &d, &set, NULL, NULL, {0.0, 1.0, 0.0, 1.0}, status};
    if (!h)
        res = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "hierarchy");
    else {
        h->leaf_tolerance = d.leaf_tolerance > 0.0 ? d.leaf_tolerance : 1e-3 * net_diagonal(s);
        if (!(h->leaf_tolerance > 0.0))
            h->leaf_tolerance = 1e-12; /* a surface collapsed to a point */
        h->n_patches = set.n_u * set.n_v;
        res = cut_patches(&b);
    }
    if (res == SW_OK)
        res = build_block(&b, 0, set.n_u, 0, set.n_v, &h->root);
    sw__free(b.rects);
    sw__free(b.nets);
    sw_sg_bezier_set_free(&set);
    if (res != SW_OK) {
        sw_lod_hierarchy_free(h);
        return res;
    }
    *out = h;
    sw__status_ok(status);
    return SW_OK;
}

void sw_lod_hierarchy_free(sw_lod_hierarchy *h)
{
    if (!h)
        return;
    sw__free(h->nodes);
    sw__free(h);
}

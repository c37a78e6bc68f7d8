/* SPDX-License-Identifier: MIT */
/* The cull stage: which face occurrences, unit instances and meshes may show in the view.
 *
 * Input: the scene (its traversal, or the caller's occurrences for immediate draws), its BVH
 * (sw_sg_bvh_cull: a node outside the frustum is culled with its subtree, a node inside takes its
 * subtree untested, Kumar §4.4), or with static LODs the set's BVH of unit instances; the view;
 * the faces' normal cones. Output (sw__fr_visible): the visible face occurrences with their
 * eye-relative boxes; with static LODs the visible unit instances with their shown faces; the
 * mesh occurrences inside the frustum.
 *
 * Back-patch culling (Kumar §4.4): an occurrence of a closed-shell face whose outward cone, in the
 * world, faces away from every view direction into its box is dropped before anything is asked
 * of the pool, so culled faces cost nothing further. Sound only for an eye outside the solids:
 * from inside a solid's material its back faces are what one sees, so a frame whose eye is found
 * inside one (sw__fr_eye_shells, with a face BVH) culls none.
 *
 * The unit-instance BVH. With static LODs the frame culls the set's BVH whose leaves are unit
 * instances (lod/static/sw_lod_static_set.h: the face occurrences grouped by (unit, transform)
 * once, when the set was made), not the faces' BVH: an instance is what gets a level, so its
 * classification and back-patch test are decided once, at its leaf. Partly visible, each of its
 * faces is classified against the frustum by its own box (the box and test of the faces' BVH, so
 * the per-frame path gets the faces it got from that BVH and asks no hierarchy for the others).
 * Wholly inside, none is tested: each face's drawn surface lies in the unit's box, so inside the
 * frustum, and the face's control-net box holds that surface, so no plane can have the box wholly
 * behind it — the test could only answer "not outside". An instance none of whose faces is shown
 * is culled whole: no level is chosen, asked for or drawn. */
#include "frame_stages.h"
#include "occlusion.h"
#include "sw_sg_pick.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int sw__fr_faces_push(sw__fr_faces *l, const occurrence *o, const double eye_box[6])
{
    if (!sw__grow((void **)&l->occ, &l->cap_occ, l->n + 1, sizeof *l->occ) ||
        !sw__grow((void **)&l->boxes, &l->cap_boxes, 6 * (l->n + 1), sizeof *l->boxes))
        return 0;
    l->occ[l->n] = *o;
    memcpy(l->boxes + 6 * l->n, eye_box, 6 * sizeof *l->boxes);
    l->n++;
    return 1;
}

void sw__fr_faces_free(sw__fr_faces *l)
{
    sw__free(l->occ);
    sw__free(l->boxes);
    memset(l, 0, sizeof *l);
}

void sw__fr_visible_free(sw__fr_visible *vis)
{
    sw__fr_faces_free(&vis->faces);
    sw__fr_faces_free(&vis->unit_faces);
    sw__free(vis->instances);
    sw__free(vis->proxies);
    sw__free(vis->meshes);
    sw__free(vis->shapes);
    memset(vis, 0, sizeof *vis);
}

/* The static set's instances when static LODs cull this frame (env resolves when they do). */
static const sw_lod_static_instances *static_instances(const sw__fr_env *env)
{
    return env->statics ? sw_lod_static_set_instances(env->statics) : NULL;
}

static const sw_sg_bvh *face_bvh(const sw_gpu_frame_desc *desc)
{
    return desc->occurrences ? NULL : desc->bvh; /* immediate draws: no BVH culls them */
}

/* ---- every occurrence, boxed by its transformed control net (the path without a BVH) ------- */
typedef struct all_taker {
    const sw__fr_env *env;
    sw__fr_faces *faces;
    int oom;
} all_taker;

static void occurrence_box(const sw__fr_env *env, const occurrence *o, double box[6])
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(env->scene, o->face, &s);
    sw__fr_box_empty(box);
    size_t n = (size_t)s.n_u * (size_t)s.n_v;
    for (size_t i = 0; i < n; ++i) {
        double h[4];
        sw__fr_xform_h(o->world, env->view.eye, s.cpw + 4 * i, h);
        sw__fr_box_add(box, h);
    }
}

static int take_any(void *user, uint32_t face, const double world[12], const float color[4])
{
    all_taker *t = user;
    occurrence o;
    double box[6];
    sw__fr_occurrence_init(&o, face, world, color);
    occurrence_box(t->env, &o, box);
    if (!sw__fr_faces_push(t->faces, &o, box)) {
        t->oom = 1;
        return 1;
    }
    return 0;
}

static sw_result collect_all(const sw__fr_env *env, const sw_gpu_frame_desc *desc,
                             sw__fr_faces *faces, double scene_box[6], sw_status *status)
{
    all_taker t = {env, faces, 0};
    for (size_t i = 0; desc->occurrences && i < desc->n_occurrences && !t.oom; ++i) {
        const sw_gpu_occurrence *o = &desc->occurrences[i];
        if (o->face >= env->sv->n_faces)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "frame: occurrence %zu names face %u of %u", i, o->face,
                            env->sv->n_faces);
        take_any(&t, o->face, o->world, o->color);
    }
    if ((!desc->occurrences && sw_sg_scene_traverse(env->scene, take_any, &t) != SW_OK) || t.oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "scene traversal: out of memory");
    sw__fr_box_empty(scene_box);
    for (size_t i = 0; i < faces->n; ++i)
        for (int k = 0; k < 3; ++k) {
            scene_box[k] = fmin(scene_box[k], faces->boxes[6 * i + k]);
            scene_box[3 + k] = fmax(scene_box[3 + k], faces->boxes[6 * i + 3 + k]);
        }
    return SW_OK;
}

/* ---- meshes ------------------------------------------------------------------------------- */
typedef struct mesh_taker {
    const sw__fr_env *env;
    sw__fr_mesh_occ **list; /* the visible set's meshes or shapes */
    size_t *n, *cap;
    int shapes;
    double *scene_box;
    int oom;
} mesh_taker;

/* A mesh's box, or a shape's plane box (in its plane z = 0); a label on screen's: its anchor
 * (its extent in the world depends on the view). */
static void local_box(const sw__fr_env *env, int shapes, uint32_t i, double box[6])
{
    if (!shapes) {
        memcpy(box, env->sv->meshes[i].box, 6 * sizeof *box);
        return;
    }
    const sw_sg_shape_rec *s = &env->sv->shapes[i];
    const double *b = s->box;
    const int screen = (s->flags & SW_SG_SHAPE_SCREEN) != 0;
    const double q[6] = {screen ? 0.0 : b[0], screen ? 0.0 : b[1], 0.0,
                         screen ? 0.0 : b[2], screen ? 0.0 : b[3], 0.0};
    memcpy(box, q, sizeof q);
}

static int take_mesh(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                     const float color[4])
{
    (void)node;
    mesh_taker *c = ctx;
    if (!sw__grow((void **)c->list, c->cap, *c->n + 1, sizeof **c->list)) {
        c->oom = 1;
        return 1;
    }
    sw__fr_mesh_occ *o = &(*c->list)[(*c->n)++];
    o->mesh = mesh;
    memcpy(o->world, world, sizeof o->world);
    memcpy(o->color, color, sizeof o->color);
    /* the world box as the BVH boxes occurrences, then eye-relative like the view's planes */
    double lb[6], wb[6];
    local_box(c->env, c->shapes, mesh, lb);
    sw_sg_box_transform(world, lb, wb);
    sw__fr_eye_box(c->env->view.eye, wb, o->box);
    for (int k = 0; k < 3; ++k) {
        c->scene_box[k] = fmin(c->scene_box[k], o->box[k]);
        c->scene_box[3 + k] = fmax(c->scene_box[3 + k], o->box[3 + k]);
    }
    return 0;
}

/* Mesh and shape occurrences join the scene box, so the near plane leaves one close to the eye
 * in front of it. */
static sw_result collect_meshes(const sw__fr_env *env, sw__fr_visible *vis, double scene_box[6],
                                sw_status *status)
{
    mesh_taker m = {env, &vis->meshes, &vis->n_meshes, &vis->cap_meshes, 0, scene_box, 0};
    mesh_taker s = {env, &vis->shapes, &vis->n_shapes, &vis->cap_shapes, 1, scene_box, 0};
    if ((env->sv->n_meshes &&
         (sw_sg_scene_traverse_meshes(env->scene, take_mesh, &m) != SW_OK || m.oom)) ||
        (env->sv->n_shapes &&
         (sw_sg_scene_traverse_shapes(env->scene, take_mesh, &s) != SW_OK || s.oom)))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh occurrences: out of memory");
    return SW_OK;
}

/* Keeps the occurrences whose box meets the frustum (a label on screen: always, its text may show
 * where its anchor does not; the outline stage culls it behind the near plane); returns how many
 * were dropped. */
static uint64_t cull_boxes(const sw__fr_env *env, sw__fr_mesh_occ *list, size_t *n, int shapes)
{
    size_t k = 0;
    for (size_t i = 0; i < *n; ++i)
        if ((shapes && (env->sv->shapes[list[i].mesh].flags & SW_SG_SHAPE_SCREEN)) ||
            sw__gpu_view_box_visible(&env->view, list[i].box))
            list[k++] = list[i];
    uint64_t dropped = *n - k;
    *n = k;
    return dropped;
}

static void cull_meshes(const sw__fr_env *env, sw__fr_visible *vis, sw_gpu_frame_stats *st)
{
    st->meshes_culled += cull_boxes(env, vis->meshes, &vis->n_meshes, 0);
    st->shapes_culled += cull_boxes(env, vis->shapes, &vis->n_shapes, 1);
}

void sw__fr_visible_empty(sw__fr_visible *vis)
{
    vis->faces.n = vis->unit_faces.n = 0;
    vis->n_instances = vis->n_meshes = vis->n_shapes = vis->n_proxies = 0;
}

sw_result sw__fr_cull_scene_box(const sw__fr_env *env, const sw_gpu_frame_desc *desc,
                                sw__fr_visible *vis, double scene_box[6], sw_status *status)
{
    sw__fr_visible_empty(vis);
    const sw_sg_bvh *bvh = face_bvh(desc);
    const sw_lod_static_instances *units = static_instances(env);
    sw_result r = SW_OK;
    if (bvh || units) {
        /* the unit-instance BVH's scene box is the face BVH's root box: the same near plane */
        sw__fr_box_empty(scene_box);
        if (bvh && bvh->n_nodes)
            sw__fr_eye_box(env->view.eye, bvh->box, scene_box);
        else if (!bvh && units->n_occs)
            sw__fr_eye_box(env->view.eye, units->scene_box, scene_box);
    } else {
        r = collect_all(env, desc, &vis->faces, scene_box, status);
    }
    return r == SW_OK ? collect_meshes(env, vis, scene_box, status) : r;
}

/* ---- the faces' BVH ----------------------------------------------------------------------- */
static void add_bvh_stats(sw_gpu_frame_stats *st, const sw_sg_bvh_cull_stats *cs)
{
    st->bvh_nodes_visited += cs->nodes_visited;
    st->bvh_nodes_inside += cs->nodes_inside;
    st->bvh_nodes_partly += cs->nodes_partly;
    st->bvh_nodes_outside += cs->nodes_outside;
    st->bvh_items_tested += cs->items_tested;
    st->bvh_items_visible += cs->items_visible;
    st->bvh_items_inside += cs->items_inside;
}

static void view_frustum(const sw__fr_env *env, sw_sg_frustum *fr)
{
    memcpy(fr->origin, env->view.eye, sizeof fr->origin);
    memcpy(fr->planes, env->view.planes, sizeof env->view.planes);
    fr->n_planes = (int32_t)(sizeof env->view.planes / sizeof env->view.planes[0]);
}

typedef struct bvh_taker {
    const sw__fr_env *env;
    const sw_sg_bvh *bvh;
    sw__fr_faces *faces;
} bvh_taker;

static int take_bvh_item(void *ctx, uint32_t item, sw_sg_cull_class cls)
{
    (void)cls;
    bvh_taker *t = ctx;
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(t->bvh, item, &view);
    const sw_sg_bvh_item_view *it = &view;
    occurrence o;
    double box[6];
    sw__fr_occurrence_init(&o, it->face, it->world, it->color);
    sw__fr_eye_box(t->env->view.eye, it->box, box);
    return !sw__fr_faces_push(t->faces, &o, box);
}

static sw_result collect_bvh(const sw__fr_env *env, const sw_sg_bvh *bvh, sw__fr_faces *faces,
                             sw_gpu_frame_stats *st, sw_status *status)
{
    sw_sg_frustum fr;
    view_frustum(env, &fr);
    bvh_taker t = {env, bvh, faces};
    sw_sg_bvh_cull_stats cs;
    const int stopped = sw_sg_bvh_cull(bvh, &fr, take_bvh_item, &t, &cs);
    st->faces_culled += bvh->n_items - cs.items_visible;
    add_bvh_stats(st, &cs);
    if (stopped)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    return SW_OK;
}

/* Takes the unit instances of the static set's BVH into the frame's visible set (the
 * unit-instance BVH section below). */
typedef struct instance_taker {
    const sw__fr_env *env;
    const sw_lod_static_instances *in;
    const sw_lod_face_cones *fc; /* NULL: no back-patch culling */
    sw_sg_frustum fr;
    sw__fr_visible *vis;
    sw_gpu_frame_stats *st;
    uint64_t occs_seen; /* face occurrences of the instances reported */
    int oom;
} instance_taker;

/* ---- the faces' BVH with occlusion culling (gpu/occlusion.h) -------------------------------
 * The BVH is walked near to far (the nearer child first), so that the planes found visible first
 * hide what lies behind them: a node hidden by the occlusion map is culled with its subtree, a
 * face occurrence hidden by it is culled, and a visible planar one is drawn into the map. Back
 * faces are culled on the way (not drawn into the map: they are not drawn). The visible items are
 * then taken in increasing index order, as sw_sg_bvh_cull reports them, so that the frame draws
 * the faces it keeps in the order it draws them without occlusion culling. Not for wireframe
 * frames (sw__fr_cull). */
enum { OCC_STACK = 128 };

typedef struct occ_walk occ_walk;
struct occ_walk {
    const sw__fr_env *env;
    const sw_sg_bvh *bvh; /* the faces' BVH, or the static set's of unit instances */
    const sw_gpu_occluders *oc; /* NULL: no occlusion culling (a walk for proxies alone) */
    const sw_lod_face_cones *fc;
    sw_sg_frustum fr;
    sw__occ_map map; /* unused without oc */
    /* a leaf's item not outside the frustum (inside: its node is wholly inside) */
    void (*item)(occ_walk *w, uint32_t item, int inside);
    uint32_t *kept; /* visible items */
    size_t n_kept, cap_kept;
    sw_sg_bvh_cull_stats cs;
    uint64_t back, nodes_occluded, faces_occluded;
    /* the unit-instance BVH: its taker (instances, frustum, cones, output) */
    struct instance_taker *taker; /* NULL: the faces' BVH */
    uint64_t faces_taken;
    int oom;
};

/* The map's test and drawing; without occluders nothing is hidden. */
static int occ_hidden(occ_walk *w, const double eb[6])
{
    return w->oc && sw__occ_map_box_hidden(&w->map, eb);
}

static int occ_add_face(occ_walk *w, uint32_t face, const double world[12])
{
    return w->oc ? sw__occ_map_add_face(&w->map, w->oc, face, world, w->env->view.eye) : 0;
}

/* One item of a leaf: frustum (unless its node is inside), occlusion, back face; kept ones are
 * drawn into the map. */
static void occ_item(occ_walk *w, uint32_t item, int inside)
{
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(w->bvh, item, &view);
    const sw_sg_bvh_item_view *it = &view;
    if (!inside) {
        w->cs.items_tested++;
        if (sw_sg_frustum_classify(&w->fr, it->box) == SW_SG_CULL_OUTSIDE)
            return;
    }
    w->cs.items_visible++;
    double eb[6];
    sw__fr_eye_box(w->env->view.eye, it->box, eb);
    if (occ_hidden(w, eb)) {
        w->faces_occluded++;
        return;
    }
    if (w->fc) {
        occurrence o;
        sw__fr_occurrence_init(&o, it->face, it->world, it->color);
        if (sw__fr_face_back_facing(w->fc, &o, eb)) {
            w->back++;
            return;
        }
    }
    if (!sw__grow((void **)&w->kept, &w->cap_kept, w->n_kept + 1, sizeof *w->kept) ||
        occ_add_face(w, it->face, it->world) < 0) {
        w->oom = 1;
        return;
    }
    w->kept[w->n_kept++] = item;
}

/* Face occurrences under a BVH node: its items, or its instances' occurrences. */
static uint64_t node_occurrences(const occ_walk *w, const sw_sg_bvh_node *node)
{
    if (!w->taker)
        return node->count;
    uint64_t n = 0;
    for (uint32_t i = node->first; i < node->first + node->count; ++i)
        n += w->taker->in->instances[w->bvh->items[i].face].n_occ;
    return n;
}

static double node_distance(const occ_walk *w, int32_t node)
{
    double box[6], eb[6];
    sw_sg_bvh_node_box(w->bvh, (uint32_t)node, box);
    sw__fr_eye_box(w->env->view.eye, box, eb);
    return sw__gpu_box_distance(eb);
}

/* The cut of the unit-instance BVH stops at a node whose proxy is within the view's tolerance at
 * the nearest depth of the node's box (the select stage's rule, stage_select.c, in world units:
 * the proxy is placed in the world); the node's instances count as taken. */
static int take_proxy(occ_walk *w, uint32_t node, const double eb[6])
{
    const sw_lod_proxy *p = sw_lod_static_set_proxy(w->env->statics, node);
    if (!p)
        return 0;
    const sw__gpu_view *v = &w->env->view;
    const double z = sw__gpu_view_box_depth(v, eb);
    if (p->err > sw_lod_object_tolerance(w->env->eps_px, z, v->focal_px, v->tan_x, v->tan_y))
        return 0;
    sw__fr_visible *vis = w->taker->vis;
    if (!sw__grow((void **)&vis->proxies, &vis->cap_proxies, vis->n_proxies + 1,
                  sizeof *vis->proxies)) {
        w->oom = 1;
        return 1;
    }
    vis->proxies[vis->n_proxies++] = node;
    w->faces_taken += p->faces;
    return 1;
}

static void occ_walk_bvh(occ_walk *w)
{
    uint32_t stack[OCC_STACK];
    uint8_t inside_of[OCC_STACK];
    uint32_t n = w->bvh->n_nodes ? 1 : 0;
    stack[0] = 0;
    inside_of[0] = 0;
    while (n > 0 && !w->oom) {
        --n;
        const uint32_t id = stack[n];
        const sw_sg_bvh_node *node = &w->bvh->nodes[id];
        int inside = inside_of[n];
        w->cs.nodes_visited++;
        double box[6];
        sw_sg_bvh_node_box(w->bvh, id, box);
        if (!inside) {
            const sw_sg_cull_class k = sw_sg_frustum_classify(&w->fr, box);
            if (k == SW_SG_CULL_OUTSIDE) {
                w->cs.nodes_outside++;
                continue;
            }
            inside = k == SW_SG_CULL_INSIDE;
        }
        *(inside ? &w->cs.nodes_inside : &w->cs.nodes_partly) += 1;
        double eb[6];
        sw__fr_eye_box(w->env->view.eye, box, eb);
        if (occ_hidden(w, eb)) {
            w->nodes_occluded++;
            w->faces_occluded += node_occurrences(w, node);
            continue;
        }
        if (w->taker && w->env->proxies && take_proxy(w, id, eb))
            continue;
        if (node->second < 0 || n + 2 > OCC_STACK) {
            for (uint32_t i = node->first; i < node->first + node->count && !w->oom; ++i)
                w->item(w, i, inside);
            continue;
        }
        /* the nearer child on top of the stack */
        const int32_t child[2] = {(int32_t)id + 1, node->second};
        const int near1 = node_distance(w, child[1]) < node_distance(w, child[0]);
        stack[n] = (uint32_t)child[near1 ? 0 : 1];
        inside_of[n++] = (uint8_t)inside;
        stack[n] = (uint32_t)child[near1 ? 1 : 0];
        inside_of[n++] = (uint8_t)inside;
    }
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* A walk of `bvh` near to far with a fresh map, item by item; occ_walk_finish closes it. */
static sw_result occ_walk_run(occ_walk *w, const sw__fr_env *env, const sw_sg_bvh *bvh,
                              const sw_gpu_occluders *oc, const sw_lod_face_cones *fc,
                              void (*item)(occ_walk *, uint32_t, int), struct instance_taker *taker,
                              sw_status *status)
{
    memset(w, 0, sizeof *w);
    w->env = env;
    w->bvh = bvh;
    w->oc = oc;
    w->fc = fc;
    w->item = item;
    w->taker = taker;
    view_frustum(env, &w->fr);
    if (oc && !sw__occ_map_init(&w->map, &env->view, env->eps_px))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "occlusion map: out of memory");
    occ_walk_bvh(w);
    return SW_OK;
}

/* The walk's counters into the frame's; its map freed. */
static sw_result occ_walk_finish(occ_walk *w, sw_gpu_frame_stats *st, sw_status *status)
{
    st->faces_backculled += w->back;
    st->occlusion_tests += w->map.tests;
    st->nodes_occluded += w->nodes_occluded;
    st->faces_occluded += w->faces_occluded;
    st->occluders_drawn += w->map.occluders_drawn;
    add_bvh_stats(st, &w->cs);
    sw__occ_map_free(&w->map);
    if (w->oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    return SW_OK;
}

static sw_result collect_bvh_occluded(const sw__fr_env *env, const sw_sg_bvh *bvh,
                                      const sw_gpu_occluders *oc, const sw_lod_face_cones *fc,
                                      sw__fr_faces *faces, sw_gpu_frame_stats *st,
                                      sw_status *status)
{
    occ_walk w;
    sw_result r = occ_walk_run(&w, env, bvh, oc, fc, occ_item, NULL, status);
    if (r != SW_OK)
        return r;
    if (w.n_kept > 1) /* kept may be NULL */
        qsort(w.kept, w.n_kept, sizeof *w.kept, cmp_u32);
    for (size_t i = 0; i < w.n_kept && !w.oom; ++i) {
        sw_sg_bvh_item_view view;
        sw_sg_bvh_item_at(bvh, w.kept[i], &view);
        const sw_sg_bvh_item_view *it = &view;
        occurrence o;
        double box[6];
        sw__fr_occurrence_init(&o, it->face, it->world, it->color);
        sw__fr_eye_box(env->view.eye, it->box, box);
        w.oom = !sw__fr_faces_push(faces, &o, box);
    }
    st->faces_culled += bvh->n_items - w.n_kept;
    sw__free(w.kept);
    return occ_walk_finish(&w, st, status);
}

/* ---- back-patch culling ------------------------------------------------------------------ */
/* 1 when the first face ray `dir` from the eye meets is a closed shell's, met from inside it
 * (its outward normal along the ray: the ray leaves the solid there). */
static int ray_leaves_shell(const sw__fr_env *env, const sw_sg_bvh *bvh, const double dir[3])
{
    sw_sg_pick_hit hit;
    sw_status st = {0};
    if (sw_sg_pick(env->scene, bvh, env->view.eye, dir, 0.0, &hit, &st) != SW_OK)
        return 1; /* unknown: taken as inside */
    if (hit.face == SW_SG_NONE)
        return 0;
    const uint32_t flags = env->sv->faces[hit.face].flags;
    if (!(flags & SW_SG_FACE_CLOSED_SHELL))
        return 0;
    sw_sg_surface srf;
    sw_sg_scene_face_surface(env->scene, hit.face, &srf);
    double h[12], du[3], dv[3], n[3], cof[9];
    sw_sg_surface_eval_h1(&srf, hit.uv[0], hit.uv[1], h);
    sw_sg_h1_tangents(h, du, dv, n); /* n: S_u x S_v times w^4 > 0 */
    const double *m = sw_sg_bvh_item_world(bvh, hit.item);
    sw__fr_cofactor3(m, cof); /* det(M) M^-T: the world normal, times the sign of det */
    double along = 0.0;
    for (int r = 0; r < 3; ++r)
        along += dir[r] * (cof[3 * r] * n[0] + cof[3 * r + 1] * n[1] + cof[3 * r + 2] * n[2]);
    along *= sw__fr_det3(m) < 0.0 ? -1.0 : 1.0;
    along *= flags & SW_SG_FACE_REVERSED ? -1.0 : 1.0;
    return along > 0.0;
}

int sw__fr_eye_shells(const sw__fr_env *env, const sw_gpu_frame_desc *desc)
{
    static const double k_dirs[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                        {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    const sw_sg_bvh *bvh = face_bvh(desc);
    if (!desc->face_cones || !bvh || !bvh->n_items)
        return SW__FR_EYE_UNKNOWN;
    for (int k = 0; k < 6; ++k)
        if (ray_leaves_shell(env, bvh, k_dirs[k]))
            return SW__FR_EYE_INSIDE;
    return SW__FR_EYE_OUTSIDE;
}

int sw__fr_face_back_facing(const sw_lod_face_cones *fc, const occurrence *o, const double box[6])
{
    sw_lod_cone w;
    return sw_lod_cone_to_world(&fc->cones[o->face], o->world, &w) &&
           sw_lod_cone_back_facing(&w, box);
}

static sw_result check_cones(const sw__fr_env *env, const sw_lod_face_cones *fc, sw_status *status)
{
    if (fc->n_faces != env->sv->n_faces)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: face cones of %u faces for a scene of %u", fc->n_faces,
                        env->sv->n_faces);
    return SW_OK;
}

/* Drops (compacting) the back-facing occurrences. */
static void cull_back_faces(const sw_lod_face_cones *fc, sw__fr_faces *faces,
                            sw_gpu_frame_stats *st)
{
    size_t k = 0;
    for (size_t i = 0; i < faces->n; ++i) {
        if (sw__fr_face_back_facing(fc, &faces->occ[i], faces->boxes + 6 * i)) {
            st->faces_backculled++;
            st->faces_culled++;
            continue;
        }
        if (k != i) {
            faces->occ[k] = faces->occ[i];
            memcpy(faces->boxes + 6 * k, faces->boxes + 6 * i, 6 * sizeof *faces->boxes);
        }
        k++;
    }
    faces->n = k;
}

/* ---- the unit-instance BVH (see the top of the file) --------------------------------------- */

/* Back-patch culling of a whole instance: the unit's outward cone in the world faces away from
 * every view direction into the instance's box (the cone is the full one unless the unit is part
 * of a closed shell). */
static int instance_back_facing(const instance_taker *t, const sw_lod_static_unit *un,
                                const sw_sg_bvh_item_view *it)
{
    sw_lod_cone w;
    if (!sw_lod_cone_to_world(&un->cone, it->world, &w))
        return 0;
    double eb[6];
    sw__fr_eye_box(t->env->view.eye, it->box, eb);
    return sw_lod_cone_back_facing(&w, eb);
}

enum { FACE_OUTSIDE = 0, FACE_BACK = 1, FACE_SHOWN = 2 };

/* Face occurrence k of an instance: outside the frustum (tested only when the instance is partly
 * visible), back-facing on its own (with cones), or shown; o and eb are set unless outside. */
static int face_shown(const instance_taker *t, const sw_lod_static_instance *in,
                      const sw_sg_bvh_item_view *it, uint32_t k, sw_sg_cull_class cls,
                      occurrence *o, double eb[6])
{
    const sw_lod_static_occ *oc = &t->in->occs[in->first_occ + k];
    double wb[6];
    sw_sg_box_transform(it->world, t->in->face_boxes + 6 * (size_t)oc->face, wb);
    if (cls != SW_SG_CULL_INSIDE && sw_sg_frustum_classify(&t->fr, wb) == SW_SG_CULL_OUTSIDE)
        return FACE_OUTSIDE;
    sw__fr_occurrence_init(o, oc->face, it->world, oc->color);
    sw__fr_eye_box(t->env->view.eye, wb, eb);
    return t->fc && sw__fr_face_back_facing(t->fc, o, eb) ? FACE_BACK : FACE_SHOWN;
}

/* Instance `item` with the unit faces from `first` on, unless it shows none (culled whole); 0
 * when out of memory. */
static int push_instance(sw__fr_visible *vis, uint32_t item, size_t first)
{
    const size_t n = vis->unit_faces.n - first;
    if (n == 0)
        return 1;
    if (!sw__grow((void **)&vis->instances, &vis->cap_instances, vis->n_instances + 1,
                  sizeof *vis->instances))
        return 0;
    vis->instances[vis->n_instances++] = (sw__fr_instance){item, first, n};
    return 1;
}

/* The instance's shown faces into vis->unit_faces; culled whole when none is. */
static void take_shown_faces(instance_taker *t, const sw_lod_static_instance *in,
                             const sw_sg_bvh_item_view *it, uint32_t item, sw_sg_cull_class cls)
{
    sw__fr_visible *vis = t->vis;
    const size_t first = vis->unit_faces.n;
    uint64_t back = 0;
    for (uint32_t k = 0; k < in->n_occ && !t->oom; ++k) {
        occurrence o;
        double eb[6];
        const int shown = face_shown(t, in, it, k, cls, &o, eb);
        back += shown == FACE_BACK;
        if (shown == FACE_SHOWN && !sw__fr_faces_push(&vis->unit_faces, &o, eb))
            t->oom = 1;
    }
    const size_t n = vis->unit_faces.n - first;
    t->st->faces_backculled += back;
    t->st->faces_culled += in->n_occ - n;
    if (!t->oom && !push_instance(vis, item, first))
        t->oom = 1;
}

static int take_instance(void *ctx, uint32_t item, sw_sg_cull_class cls)
{
    instance_taker *t = ctx;
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(t->in->bvh, item, &view);
    const sw_sg_bvh_item_view *it = &view;
    const sw_lod_static_instance *in = &t->in->instances[it->face];
    t->occs_seen += in->n_occ;
    if (in->unit != SW_LOD_STATIC_NO_UNIT && t->fc &&
        instance_back_facing(t, sw_lod_static_set_unit(t->env->statics, in->unit), it)) {
        t->st->faces_backculled += in->n_occ;
        t->st->faces_culled += in->n_occ;
        return 0;
    }
    take_shown_faces(t, in, it, item, cls);
    return t->oom;
}

static void instance_taker_init(instance_taker *t, const sw__fr_env *env,
                                const sw_lod_face_cones *fc, sw__fr_visible *vis,
                                sw_gpu_frame_stats *st)
{
    memset(t, 0, sizeof *t);
    t->env = env;
    t->in = sw_lod_static_set_instances(env->statics);
    t->fc = fc;
    t->vis = vis;
    t->st = st;
    view_frustum(env, &t->fr);
}

static sw_result collect_instances(const sw__fr_env *env, const sw_lod_face_cones *fc,
                                   sw__fr_visible *vis, sw_gpu_frame_stats *st, sw_status *status)
{
    instance_taker t;
    instance_taker_init(&t, env, fc, vis, st);
    sw_sg_bvh_cull_stats cs;
    sw_sg_bvh_cull(t.in->bvh, &t.fr, take_instance, &t, &cs);
    add_bvh_stats(st, &cs);
    if (t.oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visible occurrences: out of memory");
    st->faces_culled += t.in->n_occs - t.occs_seen; /* in instances outside the frustum */
    return SW_OK;
}

/* ---- the unit-instance BVH with occlusion culling --------------------------------------------
 * The walk of the faces' BVH with occlusion culling over the unit instances: near to far, a
 * hidden node or instance is culled whole, a visible instance's faces are classified one by one
 * (frustum when it is partly inside, back face, the map) and its shown planar faces are drawn
 * into the map. A face drawn from a static level is within ε_img of its exact surface on screen
 * (the level was chosen so), as a per-frame tessellation is, so the map's margins hold for it.
 * The instances are then put in increasing item order, as sw_sg_bvh_cull reports them. */
static void occ_instance_faces(occ_walk *w, const sw_lod_static_instance *in,
                               const sw_sg_bvh_item_view *it, uint32_t item, sw_sg_cull_class cls)
{
    sw__fr_visible *vis = w->taker->vis;
    const size_t first = vis->unit_faces.n;
    for (uint32_t k = 0; k < in->n_occ && !w->oom; ++k) {
        occurrence o;
        double eb[6];
        const int shown = face_shown(w->taker, in, it, k, cls, &o, eb);
        w->back += shown == FACE_BACK;
        if (shown != FACE_SHOWN)
            continue;
        if (occ_hidden(w, eb)) {
            w->faces_occluded++;
            continue;
        }
        if (!sw__fr_faces_push(&vis->unit_faces, &o, eb) || occ_add_face(w, o.face, it->world) < 0)
            w->oom = 1;
    }
    w->faces_taken += vis->unit_faces.n - first;
    if (!w->oom && !push_instance(vis, item, first))
        w->oom = 1;
}

static void occ_instance(occ_walk *w, uint32_t item, int inside)
{
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(w->bvh, item, &view);
    const sw_sg_bvh_item_view *it = &view;
    sw_sg_cull_class cls = SW_SG_CULL_INSIDE;
    if (!inside) {
        w->cs.items_tested++;
        cls = sw_sg_frustum_classify(&w->fr, it->box);
        if (cls == SW_SG_CULL_OUTSIDE)
            return;
    }
    w->cs.items_visible++;
    const sw_lod_static_instance *in = &w->taker->in->instances[it->face];
    double eb[6];
    sw__fr_eye_box(w->env->view.eye, it->box, eb);
    if (occ_hidden(w, eb)) {
        w->faces_occluded += in->n_occ;
        return;
    }
    if (in->unit != SW_LOD_STATIC_NO_UNIT && w->fc &&
        instance_back_facing(w->taker, sw_lod_static_set_unit(w->env->statics, in->unit), it)) {
        w->back += in->n_occ;
        return;
    }
    occ_instance_faces(w, in, it, item, cls);
}

static int cmp_instance(const void *a, const void *b)
{
    const uint32_t x = ((const sw__fr_instance *)a)->item, y = ((const sw__fr_instance *)b)->item;
    return (x > y) - (x < y);
}

static sw_result collect_instances_occluded(const sw__fr_env *env, const sw_gpu_occluders *oc,
                                            const sw_lod_face_cones *fc, sw__fr_visible *vis,
                                            sw_gpu_frame_stats *st, sw_status *status)
{
    instance_taker t;
    instance_taker_init(&t, env, fc, vis, st);
    occ_walk w;
    sw_result r = occ_walk_run(&w, env, t.in->bvh, oc, fc, occ_instance, &t, status);
    if (r != SW_OK)
        return r;
    if (vis->n_instances > 1)
        qsort(vis->instances, vis->n_instances, sizeof *vis->instances, cmp_instance);
    if (vis->n_proxies > 1)
        qsort(vis->proxies, vis->n_proxies, sizeof *vis->proxies, cmp_u32);
    st->faces_culled += t.in->n_occs - w.faces_taken;
    return occ_walk_finish(&w, st, status);
}

sw_result sw__fr_cull(const sw__fr_env *env, const sw_gpu_frame_desc *desc, sw__fr_visible *vis,
                      sw_gpu_frame_stats *st, sw_status *status)
{
    /* from inside a solid its faces are seen from behind: no back-patch culling then */
    const sw_lod_face_cones *fc = env->eye_shells == SW__FR_EYE_INSIDE ? NULL : desc->face_cones;
    sw_result r = fc ? check_cones(env, fc, status) : SW_OK;
    /* a wireframe frame shows what lies behind its faces' triangles: nothing occludes there */
    const int occlusion =
        desc->occluders && (face_bvh(desc) || static_instances(env)) && !desc->wireframe;
    if (r == SW_OK && desc->occluders &&
        desc->occluders->scene_serial != sw_sg_scene_serial(env->scene))
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT, "frame: occluders of another scene");
    /* the near-to-far walk also serves a cut that may stop at proxies, occluders or not */
    if (r == SW_OK && static_instances(env))
        r = occlusion || env->proxies
                ? collect_instances_occluded(env, occlusion ? desc->occluders : NULL, fc, vis, st,
                                             status)
                : collect_instances(env, fc, vis, st, status);
    else if (r == SW_OK && occlusion)
        r = collect_bvh_occluded(env, face_bvh(desc), desc->occluders, fc, &vis->faces, st, status);
    else if (r == SW_OK && face_bvh(desc))
        r = collect_bvh(env, face_bvh(desc), &vis->faces, st, status);
    if (r == SW_OK && fc && !occlusion)
        cull_back_faces(fc, &vis->faces, st);
    if (r == SW_OK)
        cull_meshes(env, vis, st);
    return r;
}

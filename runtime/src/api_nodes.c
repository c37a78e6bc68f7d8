/* SPDX-License-Identifier: MIT */
/* Public node-scene API (sw_nodes.h): the mutable node tree a host builds and edits. Each edit
 * asks api_nodes_compile.c for a new version; geometry descs are checked and turned into small
 * private scenes here, outside the edit lock, so a slow import never holds the scene up. */
#include "api_nodes_internal.h"
#include "sw_sg_text.h"
#include "sw_hooks.h"

#include "sw_lod_face_cones.h"
#include "sw_sg_tspline.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double k_identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

/* ---- the model's life --------------------------------------------------------------------------
 */

static void free_node(rt_node *n)
{
    while (n->first_child) {
        rt_node *c = n->first_child;
        n->first_child = c->next;
        free_node(c);
    }
    sw_sg_scene_free(n->geom);
    sw__free(n->name);
    sw__free(n);
}

static void free_children(rt_node *sentinel)
{
    while (sentinel->first_child) {
        rt_node *c = sentinel->first_child;
        sentinel->first_child = c->next;
        free_node(c);
    }
}

static void model_free(sw_rt_model *m)
{
    sw_th_pool_destroy(m->pool); /* runs a queued compilation to its end */
    sw_rt_scene *v = atomic_load_explicit(&m->published, memory_order_acquire);
    if (v)
        sw_rt_scene_release(v); /* frames still drawing it keep their references */
    free_children(&m->root);
    free_children(&m->detached);
    sw__free(m->name);
    sw__free(m->nodes.items);
    sw__free(m->nodes.generations);
    pthread_mutex_destroy(&m->nodes.lock);
    pthread_mutex_destroy(&m->edit_lock);
    pthread_mutex_destroy(&m->pub_lock);
    pthread_cond_destroy(&m->pub_cond);
    sw__free(m);
}

void sw_rt_nodes_scene_free(sw_rt_scene *scene)
{
    if (scene->model)
        model_free(scene->model);
    sw_lod_face_cones_free(scene->prebuilt_cones);
    sw__free(scene->face_nodes);
    sw__free(scene->mesh_nodes);
}

static void init_sentinel(rt_node *n, sw_node_kind kind)
{
    memset(n, 0, sizeof *n);
    n->kind = kind;
    memcpy(n->xform, k_identity, sizeof n->xform);
    n->color[3] = -1.0f;
}

static atomic_uint_fast64_t g_model_serial;

static sw_rt_model *model_create(const sw_scene_desc *desc, sw_status *status)
{
    sw_rt_model *m = sw__calloc(1, sizeof *m);
    if (!m || (desc && desc->name && !(m->name = sw__strdup(desc->name)))) {
        sw__free(m);
        sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_scene_create: out of memory");
        return NULL;
    }
    /* relaxed: only uniqueness matters */
    m->serial = atomic_fetch_add_explicit(&g_model_serial, 1u, memory_order_relaxed) + 1u;
    pthread_mutex_init(&m->edit_lock, NULL);
    pthread_mutex_init(&m->nodes.lock, NULL);
    pthread_mutex_init(&m->pub_lock, NULL);
    pthread_cond_init(&m->pub_cond, NULL);
    init_sentinel(&m->root, SW_NODE_GROUP);
    init_sentinel(&m->detached, SW_NODE_KIND_COUNT); /* not drawn itself (parent_index) */
    atomic_init(&m->published, NULL);
    sw_th_pool_desc pd = {.worker_count = 1};
    sw_rt_scene *v = NULL;
    uint64_t revision = 0;
    if (sw_th_pool_create(&pd, &m->pool) != SW_OK) {
        sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_scene_create: could not start its worker");
    } else if (sw__rt_model_compile(m, 0, &v, &revision, status) == SW_OK) {
        sw__rt_model_publish(m, v); /* the empty scene, revision 0 */
        atomic_store(&m->compiles, 1u);
        return m;
    }
    model_free(m);
    return NULL;
}

sw_result sw_scene_create(const sw_scene_desc *desc, sw_scene *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_create: NULL out");
    out->id = 0;
    sw_rt_model *m = model_create(desc, status);
    if (!m)
        return status ? status->result : SW_ERR_OUT_OF_MEMORY;
    sw_rt_scene *container = sw_rt_scene_alloc(NULL);
    if (!container) {
        model_free(m);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_scene_create: out of memory");
    }
    container->model = m;
    return sw_rt_scene_add_handle(container, out, status);
}

/* ---- looking things up ------------------------------------------------------------------------
 */

/* The scene's model with its edit lock held, and a reference on the container that end_edit
 * gives back. */
static sw_result begin_edit(sw_scene handle, const char *fn, sw_rt_scene **container,
                            sw_status *status)
{
    sw_result r = sw_rt_scene_lookup(handle, container, status);
    if (r != SW_OK)
        return r;
    if (!(*container)->model) {
        sw_rt_scene_release(*container);
        *container = NULL;
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "%s: scene %#x was loaded from a file; node calls need a scene made by "
                        "sw_scene_create",
                        fn, handle.id);
    }
    pthread_mutex_lock(&(*container)->model->edit_lock);
    return SW_OK;
}

static void end_edit(sw_rt_scene *container)
{
    pthread_mutex_unlock(&container->model->edit_lock);
    sw_rt_scene_release(container);
}

static sw_result accept_node(void *item, void *ctx)
{
    (void)item;
    (void)ctx;
    return SW_OK;
}

/* Under the edit lock (which is what keeps the node alive: only edits free nodes). */
static sw_result find_node(sw_rt_model *m, sw_node node, const char *fn, rt_node **out,
                           sw_status *status)
{
    void *item = NULL;
    if (sw_rt_pool_get_checked(&m->nodes, node.id, accept_node, NULL, &item) != SW_OK)
        return SW__MISUSE(status, SW_ERR_STALE_HANDLE, "%s: node handle %#x is stale or invalid",
                          fn, node.id);
    *out = item;
    return SW_OK;
}

/* ---- checking descs ----------------------------------------------------------------------------
 */

int sw__rt_all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(v[i]))
            return 0;
    }
    return 1;
}

static int all_zero(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (v[i] != 0.0)
            return 0;
    }
    return 1;
}

/* Zero means identity; otherwise finite with an invertible linear part. */
static sw_result read_transform(const double in[12], const char *fn, double out[12],
                                sw_status *status)
{
    if (all_zero(in, 12)) {
        memcpy(out, k_identity, 12 * sizeof *out);
        return SW_OK;
    }
    double det = in[0] * (in[5] * in[10] - in[6] * in[9]) -
                 in[1] * (in[4] * in[10] - in[6] * in[8]) + in[2] * (in[4] * in[9] - in[5] * in[8]);
    if (!sw__rt_all_finite(in, 12) || !(fabs(det) > 1e-300))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "%s: transform is not finite or its 3x3 part is singular", fn);
    for (int k = 0; k < 12; k++)
        if (!(fabs(in[k]) <= SW_SG_XFORM_MAX)) /* the rule: scenegraph/sw_sg_geom.h */
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "%s: transform entry %d is %g, beyond %g (products would overflow)", fn,
                            k, in[k], SW_SG_XFORM_MAX);
    memcpy(out, in, 12 * sizeof *out);
    return SW_OK;
}

static sw_result read_color(const float in[4], const char *fn, float out[4], sw_status *status)
{
    for (int k = 0; k < 4; k++) {
        if (!isfinite(in[k]) || in[k] < 0.0f)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "%s: colour component %d is %g (finite, >= 0)", fn, k, (double)in[k]);
    }
    memcpy(out, in, 4 * sizeof *out);
    if (in[3] == 0.0f)
        out[3] = -1.0f; /* inherit */
    return SW_OK;
}

/* A node camera is always given (no fitted default): the all-zero camera is refused too. */
static sw_result check_camera(const sw_camera *c, const char *fn, sw_status *status)
{
    sw_camera given = *c;
    if (given.fovy_deg == 0.0)
        given.fovy_deg = SW_DEFAULT_FOVY_DEG;
    const char *problem = sw_rt_camera_problem(&given);
    if (problem)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: camera: %s", fn, problem);
    return SW_OK;
}

/* ---- the tree ----------------------------------------------------------------------------------
 */

static void link_last(rt_node *parent, rt_node *n)
{
    n->parent = parent;
    n->prev = parent->last_child;
    if (parent->last_child)
        parent->last_child->next = n;
    else
        parent->first_child = n;
    parent->last_child = n;
    parent->n_children++;
}

static void unlink_node(rt_node *n)
{
    rt_node *p = n->parent;
    if (n->prev)
        n->prev->next = n->next;
    else
        p->first_child = n->next;
    if (n->next)
        n->next->prev = n->prev;
    else
        p->last_child = n->prev;
    p->n_children--;
    n->prev = n->next = NULL;
}

/* Does drawing `from` reach a node marked 2 (children and instance targets followed)? */
static int reaches_marked(const rt_node *from)
{
    if (from->mark == 2)
        return 1;
    if (from->target && reaches_marked(from->target))
        return 1;
    for (const rt_node *c = from->first_child; c; c = c->next) {
        if (reaches_marked(c))
            return 1;
    }
    return 0;
}

/* An instance of `target` under `parent` draws itself if target's drawing reaches the parent or
 * one of its ancestors. */
static int instance_cycles(rt_node *parent, const rt_node *target)
{
    for (rt_node *a = parent; a; a = a->parent)
        a->mark = 2;
    int cycle = reaches_marked(target);
    for (rt_node *a = parent; a; a = a->parent)
        a->mark = 0;
    return cycle;
}

static sw_result resolve_parent(sw_rt_model *m, const sw_node_desc *d, rt_node **out,
                                sw_status *status)
{
    if (d->detached) {
        *out = &m->detached;
        return SW_OK;
    }
    if (d->parent.id == 0) {
        *out = &m->root;
        return SW_OK;
    }
    sw_result r = find_node(m, d->parent, "sw_node_add (parent)", out, status);
    if (r == SW_OK && (*out)->kind != SW_NODE_GROUP && (*out)->kind != SW_NODE_TRANSFORM)
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                     "sw_node_add: parent %#x is not a GROUP or TRANSFORM node", d->parent.id);
    return r;
}

/* The parts of a desc that need no lock: kind, transform, colour, camera, name. */
static sw_result new_node(const sw_node_desc *d, rt_node **out, sw_status *status)
{
    const char *fn = "sw_node_add";
    *out = NULL;
    if ((unsigned)d->kind >= SW_NODE_KIND_COUNT)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: kind %d out of range", fn,
                        (int)d->kind);
    if (d->kind == SW_NODE_CAMERA && !d->camera)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: CAMERA without camera", fn);
    rt_node *n = sw__calloc(1, sizeof *n);
    if (!n)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    n->kind = d->kind;
    n->hidden = d->hidden != 0;
    sw_result r = read_color(d->color, fn, n->color, status);
    if (r == SW_OK && d->kind != SW_NODE_GROUP && d->kind != SW_NODE_CAMERA)
        r = read_transform(d->transform, fn, n->xform, status);
    else
        memcpy(n->xform, k_identity, sizeof n->xform);
    if (r == SW_OK && d->kind == SW_NODE_CAMERA &&
        (r = check_camera(d->camera, fn, status)) == SW_OK)
        n->camera = *d->camera;
    if (r == SW_OK && d->name && !(n->name = sw__strdup(d->name)))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    if (r == SW_OK)
        r = sw__rt_make_geom(d, &n->geom, status);
    if (r != SW_OK) {
        free_node(n);
        return r;
    }
    if (n->geom) {
        n->geom_faces = sw_sg_scene_view_ptr(n->geom)->n_faces;
        n->geom_triangles = sw__rt_geom_triangles(n->geom);
    }
    *out = n;
    return SW_OK;
}

/* Under the edit lock: places n in the tree and gives it a handle. */
static sw_result insert_node(sw_rt_model *m, const sw_node_desc *d, rt_node *n, sw_status *status)
{
    rt_node *parent = NULL;
    sw_result r = resolve_parent(m, d, &parent, status);
    if (r == SW_OK && n->kind == SW_NODE_INSTANCE) {
        r = find_node(m, d->instance_of, "sw_node_add (instance_of)", &n->target, status);
        if (r == SW_OK && instance_cycles(parent, n->target))
            r = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                         "sw_node_add: an instance of node %#x there would draw itself",
                         d->instance_of.id);
    }
    if (r != SW_OK)
        return r;
    n->id = sw_rt_pool_add(&m->nodes, n);
    if (!n->id)
        return sw__fail(status, SW_ERR_LIMIT, "sw_node_add: 65,535 nodes in the scene already");
    link_last(parent, n);
    if (n->target)
        n->target->instance_refs++;
    sw__rt_model_edited(m);
    return SW_OK;
}

sw_result sw_node_add(sw_scene scene, const sw_node_desc *desc, sw_node *out, sw_status *status)
{
    if (out)
        out->id = 0;
    if (!desc || !out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: NULL desc or out");
    rt_node *n = NULL;
    sw_result r = new_node(desc, &n, status); /* a slow import runs here, unlocked */
    if (r != SW_OK)
        return r;
    sw_rt_scene *c;
    r = begin_edit(scene, "sw_node_add", &c, status);
    if (r == SW_OK) {
        r = insert_node(c->model, desc, n, status);
        if (r == SW_OK)
            out->id = n->id;
        end_edit(c);
    }
    if (r != SW_OK)
        free_node(n);
    else
        sw__status_ok(status);
    return r;
}

sw_result sw_node_add_mesh(sw_scene scene, const sw_node_desc *node, const sw_mesh_desc *mesh,
                           sw_node *out, sw_status *status)
{
    if (out)
        out->id = 0;
    if (!mesh)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add_mesh: NULL mesh");
    sw_node_desc d;
    if (node)
        d = *node;
    else
        memset(&d, 0, sizeof d);
    d.kind = SW_NODE_MESH;
    d.mesh = mesh;
    return sw_node_add(scene, &d, out, status);
}

/* Counts, in each node's mark, the instances inside the subtree of `n` that draw it. */
static void count_inner_refs(rt_node *n, int add)
{
    if (n->target)
        n->target->mark += add ? 1u : (uint32_t)-1;
    for (rt_node *c = n->first_child; c; c = c->next)
        count_inner_refs(c, add);
}

static const rt_node *outer_referenced(const rt_node *n)
{
    if (n->instance_refs > n->mark)
        return n;
    for (const rt_node *c = n->first_child; c; c = c->next) {
        const rt_node *hit = outer_referenced(c);
        if (hit)
            return hit;
    }
    return NULL;
}

static void drop_handles(sw_rt_model *m, rt_node *n)
{
    if (n->target)
        n->target->instance_refs--;
    sw_rt_pool_remove(&m->nodes, n->id);
    for (rt_node *c = n->first_child; c; c = c->next)
        drop_handles(m, c);
}

sw_result sw_node_remove(sw_scene scene, sw_node node, sw_status *status)
{
    sw_rt_scene *c;
    sw_result r = begin_edit(scene, "sw_node_remove", &c, status);
    if (r != SW_OK)
        return r;
    sw_rt_model *m = c->model;
    rt_node *n = NULL;
    r = find_node(m, node, "sw_node_remove", &n, status);
    if (r == SW_OK) {
        count_inner_refs(n, 1);
        const rt_node *held = outer_referenced(n);
        count_inner_refs(n, 0);
        if (held)
            r = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                         "sw_node_remove: node %#x is drawn by an instance outside the subtree of "
                         "%#x; remove that instance first",
                         held->id, node.id);
    }
    if (r == SW_OK) {
        unlink_node(n);
        drop_handles(m, n);
        free_node(n); /* no compilation can be reading it: they copy under the edit lock */
        sw__rt_model_edited(m);
        sw__status_ok(status);
    }
    end_edit(c);
    return r;
}

/* ---- per-node edits ----------------------------------------------------------------------------
 */

typedef sw_result (*edit_fn)(rt_node *n, const void *arg, sw_status *status);

static sw_result edit_node(sw_scene scene, sw_node node, const char *fn, edit_fn edit,
                           const void *arg, sw_status *status)
{
    sw_rt_scene *c;
    sw_result r = begin_edit(scene, fn, &c, status);
    if (r != SW_OK)
        return r;
    rt_node *n = NULL;
    r = find_node(c->model, node, fn, &n, status);
    if (r == SW_OK)
        r = edit(n, arg, status);
    if (r == SW_OK) {
        sw__rt_model_edited(c->model);
        sw__status_ok(status);
    }
    end_edit(c);
    return r;
}

static sw_result edit_visible(rt_node *n, const void *arg, sw_status *status)
{
    (void)status;
    n->hidden = *(const int32_t *)arg == 0;
    return SW_OK;
}

static sw_result edit_color(rt_node *n, const void *arg, sw_status *status)
{
    static const float inherit[4] = {0, 0, 0, 0};
    return read_color(arg ? arg : inherit, "sw_node_set_color", n->color, status);
}

static sw_result edit_transform(rt_node *n, const void *arg, sw_status *status)
{
    if (n->kind == SW_NODE_GROUP || n->kind == SW_NODE_CAMERA)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "sw_node_set_transform: node %#x has no transform (GROUP or CAMERA)",
                        n->id);
    double xf[12];
    sw_result r = read_transform(arg, "sw_node_set_transform", xf, status);
    if (r == SW_OK)
        memcpy(n->xform, xf, sizeof xf);
    return r;
}

/* A node's new geometry, and the kind of node it is for. */
typedef struct geometry_swap {
    sw_sg_scene *geom; /* the new one in; the old one out */
    sw_node_kind kind;
    const char *fn;
} geometry_swap;

static sw_result edit_geometry(rt_node *n, const void *arg, sw_status *status)
{
    geometry_swap *swap = (geometry_swap *)arg;
    if (n->kind != swap->kind)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: node %#x is not a %s node", swap->fn,
                        n->id,
                        swap->kind == SW_NODE_NURBS     ? "NURBS"
                        : swap->kind == SW_NODE_TSPLINE ? "TSPLINE"
                        : swap->kind == SW_NODE_MESH    ? "MESH"
                        : swap->kind == SW_NODE_SHAPE   ? "SHAPE"
                                                        : "LABEL");
    sw_sg_scene *old = n->geom;
    n->geom = swap->geom;
    n->geom_faces = sw_sg_scene_view_ptr(n->geom)->n_faces;
    n->geom_triangles = sw__rt_geom_triangles(n->geom);
    swap->geom = old;
    return SW_OK;
}

sw_result sw_node_set_visible(sw_scene scene, sw_node node, int32_t visible, sw_status *status)
{
    return edit_node(scene, node, "sw_node_set_visible", edit_visible, &visible, status);
}

sw_result sw_node_set_color(sw_scene scene, sw_node node, const float color[4], sw_status *status)
{
    return edit_node(scene, node, "sw_node_set_color", edit_color, color, status);
}

sw_result sw_node_set_transform(sw_scene scene, sw_node node, const double transform[12],
                                sw_status *status)
{
    if (!transform)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_transform: NULL transform");
    return edit_node(scene, node, "sw_node_set_transform", edit_transform, transform, status);
}

/* Checks and builds the new geometry before locking, then swaps it in. */
static sw_result set_geometry(sw_scene scene, sw_node node, geometry_swap *swap, sw_result built,
                              sw_status *status)
{
    if (built != SW_OK)
        return built;
    sw_result r = edit_node(scene, node, swap->fn, edit_geometry, swap, status);
    sw_sg_scene_free(swap->geom); /* the node's old geometry, or the new one when it failed */
    return r;
}

sw_result sw_node_set_nurbs(sw_scene scene, sw_node node, const sw_nurbs_desc *desc,
                            sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_nurbs: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_NURBS, "sw_node_set_nurbs"};
    return set_geometry(scene, node, &swap, sw__rt_nurbs_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_tspline(sw_scene scene, sw_node node, const sw_tspline_desc *desc,
                              sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_tspline: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_TSPLINE, "sw_node_set_tspline"};
    return set_geometry(scene, node, &swap, sw__rt_tspline_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_mesh(sw_scene scene, sw_node node, const sw_mesh_desc *desc,
                           sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_mesh: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_MESH, "sw_node_set_mesh"};
    return set_geometry(scene, node, &swap, sw__rt_mesh_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_label(sw_scene scene, sw_node node, const sw_label_desc *desc,
                            sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_label: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_LABEL, "sw_node_set_label"};
    return set_geometry(scene, node, &swap, sw__rt_label_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_shape(sw_scene scene, sw_node node, const sw_shape_desc *desc,
                            sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_shape: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_SHAPE, "sw_node_set_shape"};
    return set_geometry(scene, node, &swap, sw__rt_shape_geom(desc, &swap.geom, status), status);
}

/* ---- queries -----------------------------------------------------------------------------------
 */

sw_result sw_node_get_info(sw_scene scene, sw_node node, sw_node_info *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_get_info: NULL out");
    sw_rt_scene *c;
    sw_result r = begin_edit(scene, "sw_node_get_info", &c, status);
    if (r != SW_OK)
        return r;
    rt_node *n = NULL;
    r = find_node(c->model, node, "sw_node_get_info", &n, status);
    if (r == SW_OK) {
        memset(out, 0, sizeof *out);
        out->kind = n->kind;
        out->parent.id = n->parent->id;
        out->children = n->n_children;
        out->detached = n->parent == &c->model->detached;
        out->visible = !n->hidden;
        memcpy(out->color, n->color, sizeof out->color);
        if (out->color[3] < 0.0f)
            out->color[3] = 0.0f;
        memcpy(out->transform, n->xform, sizeof out->transform);
        out->faces = n->geom_faces;
        out->triangles = n->geom_triangles;
        sw__status_ok(status);
    }
    end_edit(c);
    return r;
}

/* out = a * b for row-major 3x4 affine maps. */
static void compose(const double a[12], const double b[12], double out[12])
{
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double s = j == 3 ? a[4 * i + 3] : 0.0;
            for (int k = 0; k < 3; k++)
                s += a[4 * i + k] * b[4 * k + j];
            out[4 * i + j] = s;
        }
    }
}

static void map_point(const double m[12], const double p[3], double w, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + w * m[4 * i + 3];
}

sw_result sw_node_get_camera(sw_scene scene, sw_node node, sw_camera *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_get_camera: NULL out");
    sw_rt_scene *c;
    sw_result r = begin_edit(scene, "sw_node_get_camera", &c, status);
    if (r != SW_OK)
        return r;
    rt_node *n = NULL;
    r = find_node(c->model, node, "sw_node_get_camera", &n, status);
    if (r == SW_OK && (n->kind != SW_NODE_CAMERA || n->parent == &c->model->detached))
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                     "sw_node_get_camera: node %#x is not a CAMERA in the tree", node.id);
    if (r == SW_OK) {
        double world[12], next[12];
        memcpy(world, k_identity, sizeof world);
        for (const rt_node *a = n->parent; a && a->id; a = a->parent) {
            compose(a->xform, world, next);
            memcpy(world, next, sizeof world);
        }
        map_point(world, n->camera.eye, 1.0, out->eye);
        map_point(world, n->camera.target, 1.0, out->target);
        map_point(world, n->camera.up, 0.0, out->up);
        out->fovy_deg = n->camera.fovy_deg;
        sw__status_ok(status);
    }
    end_edit(c);
    return r;
}

sw_result sw_scene_get_revisions(sw_scene scene, sw_scene_revisions *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_get_revisions: NULL out");
    sw_rt_scene *c;
    sw_result r = begin_edit(scene, "sw_scene_get_revisions", &c, status);
    if (r != SW_OK)
        return r;
    out->latest = c->model->revision;
    out->published = atomic_load_explicit(&c->model->published_revision, memory_order_acquire);
    out->compiles = atomic_load_explicit(&c->model->compiles, memory_order_relaxed);
    end_edit(c);
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_scene_flush(sw_scene scene, sw_status *status)
{
    sw_rt_scene *c;
    sw_result r = sw_rt_scene_lookup(scene, &c, status);
    if (r != SW_OK)
        return r;
    sw_rt_scene *v = NULL;
    if (!c->model)
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                     "sw_scene_flush: scene %#x was loaded from a file", scene.id);
    else
        r = sw_rt_model_acquire_version(c->model, 1, &v, status);
    if (v)
        sw_rt_scene_release(v);
    sw_rt_scene_release(c);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

/* ---- shared with api_immediate.c ---------------------------------------------------------------
 */

sw_result sw__rt_read_transform(const double in[12], const char *fn, double out[12],
                                sw_status *status)
{
    return read_transform(in, fn, out, status);
}

sw_result sw__rt_read_color(const float in[4], const char *fn, float out[4], sw_status *status)
{
    return read_color(in, fn, out, status);
}

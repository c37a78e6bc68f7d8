/* SPDX-License-Identifier: MIT */
/* Node scenes: compiling the node tree into an immutable version (the scene graph's own scene,
 * built with sw_sg_builder, with its BVH and back-patch cones), publishing it by one atomic
 * pointer exchange, and reclaiming the version it replaces after a grace period
 * (CONVENTIONS.md, Threads: "built aside and published by one atomic pointer swap; the old one
 * is reclaimed after a grace period"). The compile task runs in the model's one-worker pool, so
 * walkthrough frames, which only read the published pointer, never wait for it. */
#include "api_nodes_internal.h"
#include "sw_hooks.h"

#include "sw_lod_face_cones.h"
#include "sw_sg_bvh.h"
#include "sw_sg_generate.h"
#include "sw_status_util.h"

#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The pool's task kind of node scenes' compiles. */
static sw_th_task_kind_slot k_compile = SW_TH_TASK_KIND_SLOT("compile");

/* ---- compiling ---------------------------------------------------------------------------------
 */

typedef struct compile_state {
    sw_sg_builder *b;
    uint32_t n_nodes;     /* nodes in b (sw__sg_append_model needs the count) */
    uint32_t *face_nodes; /* node handle id per builder face */
    uint32_t n_face_nodes, cap_face_nodes;
    uint32_t *mesh_nodes; /* node handle id per builder mesh */
    uint32_t n_mesh_nodes, cap_mesh_nodes, n_meshes;
    int oom;
} compile_state;

/* ids[count..n) = node_id (the records a geometry node's scene just appended). */
static int note_records(uint32_t **ids, uint32_t *count, uint32_t *cap, uint32_t n,
                        uint32_t node_id)
{
    if (n > *cap) {
        uint32_t c = *cap ? *cap : 16;
        while (c < n)
            c *= 2;
        uint32_t *grown = sw__realloc(*ids, c * sizeof *grown);
        if (!grown)
            return 0;
        *ids = grown;
        *cap = c;
    }
    while (*count < n)
        (*ids)[(*count)++] = node_id;
    return 1;
}

static const float *node_color(const rt_node *n)
{
    return n->color[3] < 0.0f ? NULL : n->color;
}

static uint32_t add_node(compile_state *cs, sw_sg_node_kind kind, uint32_t parent, uint32_t ref,
                         const double *xform, const rt_node *n)
{
    uint32_t i = sw_sg_builder_add_node(cs->b, kind, parent, ref, xform, node_color(n), n->name);
    if (i == SW_SG_NONE)
        cs->oom = 1;
    else
        cs->n_nodes++;
    return i;
}

/* A geometry node: its private scene appended as a detached prototype (*proto its root), drawn
 * by an INSTANCE carrying the node's transform and colour, so one code path serves surfaces,
 * T-splines and imported files alike. */
static sw_result append_geometry(compile_state *cs, const rt_node *n, uint32_t *proto,
                                 sw_status *status)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(n->geom);
    sw_result r = sw__sg_append_model(cs->b, v, cs->n_nodes, proto, status);
    if (r != SW_OK)
        return r;
    cs->n_nodes += v->n_nodes;
    cs->n_meshes += v->n_meshes;
    if (!note_records(&cs->face_nodes, &cs->n_face_nodes, &cs->cap_face_nodes,
                      sw_sg_builder_face_count(cs->b), n->id) ||
        !note_records(&cs->mesh_nodes, &cs->n_mesh_nodes, &cs->cap_mesh_nodes, cs->n_meshes, n->id))
        cs->oom = 1;
    return SW_OK;
}

static void reset_compiled(rt_node *first)
{
    for (rt_node *n = first; n; n = n->next) {
        n->compiled = SW_SG_NONE;
        reset_compiled(n->first_child);
    }
}

/* Pass 1: every visible node but instances, parents before children. */
static sw_result compile_subtree(compile_state *cs, rt_node *first, uint32_t parent,
                                 sw_status *status)
{
    for (rt_node *n = first; n && !cs->oom; n = n->next) {
        if (n->hidden || n->kind == SW_NODE_INSTANCE || n->kind == SW_NODE_CAMERA)
            continue;
        if (n->kind == SW_NODE_GROUP || n->kind == SW_NODE_TRANSFORM) {
            sw_sg_node_kind k = n->kind == SW_NODE_GROUP ? SW_SG_NODE_GROUP : SW_SG_NODE_TRANSFORM;
            n->compiled = add_node(cs, k, parent, 0, n->xform, n);
            if (n->compiled == SW_SG_NONE)
                break;
            sw_result r = compile_subtree(cs, n->first_child, n->compiled, status);
            if (r != SW_OK)
                return r;
            continue;
        }
        uint32_t proto = SW_SG_NONE;
        sw_result r = append_geometry(cs, n, &proto, status);
        if (r != SW_OK)
            return r;
        n->compiled = add_node(cs, SW_SG_NODE_INSTANCE, parent, proto, n->xform, n);
    }
    return SW_OK;
}

/* Pass 2 gathers instance nodes whose ancestors were compiled; each is added once its target
 * has been (an instance of an instance waits for it), or dropped when the target is hidden. */
typedef struct pending {
    rt_node **items;
    uint32_t count, cap;
} pending;

static int pending_push(pending *p, rt_node *n)
{
    if (p->count == p->cap) {
        uint32_t cap = p->cap ? p->cap * 2 : 16;
        rt_node **grown = sw__realloc(p->items, cap * sizeof *grown);
        if (!grown)
            return 0;
        p->items = grown;
        p->cap = cap;
    }
    p->items[p->count++] = n;
    return 1;
}

static int gather_instances(rt_node *first, int parent_compiled, pending *p)
{
    for (rt_node *n = first; n; n = n->next) {
        if (n->kind == SW_NODE_INSTANCE) {
            if (parent_compiled && !n->hidden && !pending_push(p, n))
                return 0;
        } else if (!gather_instances(n->first_child, n->compiled != SW_SG_NONE, p)) {
            return 0;
        }
    }
    return 1;
}

static uint32_t parent_index(const rt_node *n)
{
    return n->parent->id == 0 ? (n->parent->kind == SW_NODE_GROUP ? 0u : SW_SG_NONE)
                              : n->parent->compiled; /* the root, or the detached sentinel */
}

/* Pending instances carry mark = 1. An instance of a pending instance waits for it; there are
 * no cycles (sw_node_add refuses them), so every round adds or drops at least one. */
static void compile_instances(compile_state *cs, pending *p)
{
    int progress = 1;
    while (progress && p->count && !cs->oom) {
        progress = 0;
        for (uint32_t i = 0; i < p->count; i++) {
            rt_node *n = p->items[i];
            const rt_node *t = n->target;
            if (t->mark == 1)
                continue;
            if (t->compiled != SW_SG_NONE) /* else its target is hidden: n draws nothing */
                n->compiled =
                    add_node(cs, SW_SG_NODE_INSTANCE, parent_index(n), t->compiled, n->xform, n);
            n->mark = 0;
            p->items[i--] = p->items[--p->count];
            progress = 1;
        }
    }
}

static sw_result copy_tree(sw_rt_model *m, compile_state *cs, sw_status *status)
{
    cs->b = sw_sg_builder_create();
    if (!cs->b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "node scene: out of memory");
    cs->n_nodes = 1; /* the builder's root group: the model's root */
    reset_compiled(m->root.first_child);
    reset_compiled(m->detached.first_child);
    sw_result r = compile_subtree(cs, m->root.first_child, 0, status);
    if (r == SW_OK)
        r = compile_subtree(cs, m->detached.first_child, SW_SG_NONE, status);
    pending p = {0};
    if (r == SW_OK && (!gather_instances(m->root.first_child, 1, &p) ||
                       !gather_instances(m->detached.first_child, 1, &p)))
        cs->oom = 1;
    for (uint32_t i = 0; i < p.count; i++)
        p.items[i]->mark = 1; /* pending */
    if (r == SW_OK && !cs->oom)
        compile_instances(cs, &p);
    for (uint32_t i = 0; i < p.count; i++)
        p.items[i]->mark = 0;
    sw__free(p.items);
    if (r == SW_OK && cs->oom)
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "node scene: out of memory compiling");
    return r;
}

/* The version's extras, made before it is published: stats (ready), the BVH renderers cull with
 * and picks use, the back-patch cones. */
static sw_result finish_version(sw_sg_scene *sg, compile_state *cs, uint64_t lineage,
                                uint64_t revision, sw_rt_scene **out, sw_status *status)
{
    sw_rt_scene *v = sw_rt_scene_alloc(sg);
    if (!v) {
        sw__free(cs->face_nodes);
        sw__free(cs->mesh_nodes);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "node scene: out of memory");
    }
    v->face_nodes = cs->face_nodes;
    v->mesh_nodes = cs->mesh_nodes;
    v->lineage = lineage;
    v->revision = revision;
    sw_result r = sw_sg_scene_compute_stats(sg, &v->stats);
    if (r != SW_OK)
        sw__fail(status, r, "node scene: out of memory walking the compiled scene");
    if (r == SW_OK)
        r = sw_sg_bvh_build(sg, &v->pick_bvh, status);
    if (r == SW_OK)
        r = sw_lod_face_cones_build(sg, &v->prebuilt_cones, status);
    if (r != SW_OK) {
        sw_rt_scene_release(v);
        return r;
    }
    v->prebuilt_bvh = v->pick_bvh;
    v->ready = 1;
    v->ready_result = SW_OK;
    *out = v;
    return SW_OK;
}

sw_result sw__rt_model_compile(sw_rt_model *m, int unlock, sw_rt_scene **out, uint64_t *revision,
                               sw_status *status)
{
    compile_state cs = {0};
    *revision = m->revision;
    sw_result r = copy_tree(m, &cs, status);
    if (unlock)
        pthread_mutex_unlock(&m->edit_lock);
    if (r != SW_OK) {
        sw_sg_builder_free(cs.b);
        sw__free(cs.face_nodes);
        sw__free(cs.mesh_nodes);
        return r;
    }
    sw_sg_scene *sg = NULL;
    r = sw_sg_builder_finish(cs.b, &sg, status);
    if (r != SW_OK) {
        sw__free(cs.face_nodes);
        sw__free(cs.mesh_nodes);
        return r;
    }
    return finish_version(sg, &cs, m->serial, *revision, out, status);
}

/* ---- publication and grace period ---------------------------------------------------------- */

/* Waits until no reader counted in readers[parity] is inside its read section. Only the compile
 * task (and the model's creation and destruction) publish, one at a time. */
static void wait_readers(sw_rt_model *m, unsigned parity)
{
    /* seq_cst: pairs with the reader's seq_cst increment; see sw__rt_model_publish. */
    while (atomic_load_explicit(&m->readers[parity], memory_order_seq_cst) != 0)
        sched_yield();
}

void sw__rt_model_publish(sw_rt_model *m, sw_rt_scene *v)
{
    /* seq_cst exchange: a reader whose counter increment comes after it (in the single total
     * order of seq_cst operations) loads v, never the old version; a reader whose increment
     * comes before it is waited for below. Two flips of the epoch, as in userspace RCU: the
     * readers of each parity drain, while new readers go to the other one (no starvation). */
    sw_rt_scene *old = atomic_exchange_explicit(&m->published, v, memory_order_seq_cst);
    atomic_store_explicit(&m->published_revision, v->revision, memory_order_release);
    for (int flip = 0; flip < 2; flip++) {
        unsigned e = atomic_fetch_add_explicit(&m->epoch, 1u, memory_order_seq_cst);
        wait_readers(m, e & 1u);
    }
    if (old)
        sw_rt_scene_release(old); /* frames still drawing it hold their own references */
}

/* A walkthrough frame's read: never blocks. */
static sw_rt_scene *acquire_published(sw_rt_model *m)
{
    /* seq_cst: the increment is ordered before the pointer load, and both against the
     * publisher's exchange and its reads of the counters (sw__rt_model_publish). */
    unsigned e = atomic_load_explicit(&m->epoch, memory_order_seq_cst) & 1u;
    atomic_fetch_add_explicit(&m->readers[e], 1u, memory_order_seq_cst);
    sw_rt_scene *v = atomic_load_explicit(&m->published, memory_order_seq_cst);
    sw_rt_scene_retain(v); /* the model's reference keeps v alive inside the read section */
    /* release: the retain is done before the publisher may see the section left. */
    atomic_fetch_sub_explicit(&m->readers[e], 1u, memory_order_release);
    return v;
}

/* ---- the compile task ---------------------------------------------------------------------- */

static void compile_task(void *ctx)
{
    sw_rt_model *m = ctx;
    sw_status st = {0};
    sw_rt_scene *v = NULL;
    uint64_t revision = 0;
    pthread_mutex_lock(&m->edit_lock);
    sw_result r = sw__rt_model_compile(m, 1, &v, &revision, &st); /* unlocks */
    if (r == SW_OK) {
        sw__rt_model_publish(m, v);
        atomic_fetch_add_explicit(&m->compiles, 1u, memory_order_relaxed);
    }
    if (r != SW_OK && m->name) {
        char message[sizeof st.message];
        snprintf(message, sizeof message, "scene \"%.64s\": %.400s", m->name, st.message);
        memcpy(st.message, message, sizeof message);
    }
    pthread_mutex_lock(&m->pub_lock);
    m->compiled_revision = revision;
    m->compile_result = r;
    m->compile_status = st;
    pthread_cond_broadcast(&m->pub_cond);
    pthread_mutex_unlock(&m->pub_lock);

    /* Edits made while this one compiled: one more round gathers them all. */
    pthread_mutex_lock(&m->edit_lock);
    int again = m->revision != revision;
    if (again) {
        sw_th_task t = {.fn = compile_task,
                        .ctx = m,
                        .priority = SW_TH_PRIORITY_BACKGROUND,
                        .kind = sw_th_task_kind_of(&k_compile)};
        again = sw_th_pool_submit(m->pool, &t) == SW_OK;
    }
    m->compile_queued = again;
    pthread_mutex_unlock(&m->edit_lock);
}

/* Under the edit lock: a compile task unless one is queued (it then looks at the revision when
 * it finishes). A failed submission (out of memory for a small task) is retried by the next
 * edit or wait. */
static void schedule_compile(sw_rt_model *m)
{
    if (m->compile_queued)
        return;
    sw_th_task t = {.fn = compile_task,
                    .ctx = m,
                    .priority = SW_TH_PRIORITY_BACKGROUND,
                    .kind = sw_th_task_kind_of(&k_compile)};
    m->compile_queued = sw_th_pool_submit(m->pool, &t) == SW_OK;
}

void sw__rt_model_edited(sw_rt_model *m)
{
    m->revision++;
    schedule_compile(m);
}

sw_result sw_rt_model_acquire_version(sw_rt_model *m, int latest, sw_rt_scene **out,
                                      sw_status *status)
{
    *out = NULL;
    if (latest) {
        pthread_mutex_lock(&m->edit_lock);
        uint64_t target = m->revision;
        if (atomic_load_explicit(&m->published_revision, memory_order_acquire) < target)
            schedule_compile(m);
        pthread_mutex_unlock(&m->edit_lock);
        pthread_mutex_lock(&m->pub_lock);
        const int waits = m->compiled_revision < target; /* for the compile task: a pool wait */
        if (waits)
            sw_th_wait_begin();
        while (m->compiled_revision < target)
            pthread_cond_wait(&m->pub_cond, &m->pub_lock);
        if (waits)
            sw_th_wait_end();
        sw_result r = atomic_load_explicit(&m->published_revision, memory_order_acquire) >= target
                          ? SW_OK
                          : m->compile_result;
        if (r != SW_OK && status)
            *status = m->compile_status;
        pthread_mutex_unlock(&m->pub_lock);
        if (r != SW_OK)
            return r;
    }
    *out = acquire_published(m);
    return SW_OK;
}

/* SPDX-License-Identifier: MIT */
/* The scene container: the builder (growable record arrays and the double pool), the immutable
 * scene with its accessors, and the traversal that expands instances and composes transforms and
 * colours. Records and layout: sw_sg_scene.h; the arrays are the same whether built here or
 * mapped from a .sws file (sws_file.c). Guthe et al. 2005 §3 renders every face occurrence the
 * traversal yields as rational Bézier patches under its world transform. */
#include "sw_sg_scene_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <assert.h>
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

const char *const sw__sg_section_names[SW__SG_SEC_COUNT] = {
    "FACES",   "LOOPS", "CURVES", "NODES",  "ADJACENCY", "POOL",
    "STRINGS", "META",  "LODS",   "MESHES", "INDICES",   "SHAPES",
};
const uint32_t sw__sg_section_record_size[SW__SG_SEC_COUNT] = {
    sizeof(sw_sg_face_rec),
    sizeof(sw_sg_loop_rec),
    sizeof(sw_sg_curve_rec),
    sizeof(sw_sg_node_rec),
    sizeof(sw_sg_adjacency_rec),
    sizeof(double),
    1,
    16,
    1, /* LODS: opaque bytes */
    sizeof(sw_sg_mesh_rec),
    sizeof(uint32_t),
    sizeof(sw_sg_shape_rec),
};

static const double identity12[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
static const float default_color[4] = {0.8f, 0.8f, 0.8f, 1.0f};

const char *sw_sg_surface_kind_str(uint32_t kind)
{
    static const char *const names[] = {
#define SW__KIND_TEXT(id, text) text,
        SW_SG_SURFACE_KIND_XMACRO(SW__KIND_TEXT)
#undef SW__KIND_TEXT
    };
    if (kind >= SW_SG_KIND_COUNT)
        return "unknown";
    return names[kind];
}

/* ---- builder --------------------------------------------------------------------------------- */

typedef struct sw__vec {
    unsigned char *data;
    size_t n, cap, elem, max; /* max: element count limit (indices must stay below SW_SG_NONE) */
} sw__vec;

struct sw_sg_builder {
    sw__vec vec[SW__SG_SEC_COUNT]; /* indexed by SW__SG_SEC_* (META and LODS unused) */
    sw__vec last_child;            /* uint32 per node: O(1) append of a child */
    uint32_t root;
};

static void vec_init(sw__vec *v, size_t elem, size_t max)
{
    memset(v, 0, sizeof *v);
    v->elem = elem;
    v->max = max;
}

/* Makes room for `count` more elements; returns the index of the first, or SIZE_MAX. */
static size_t vec_grow(sw__vec *v, size_t count)
{
    if (count > v->max - v->n)
        return SIZE_MAX;
    size_t need = v->n + count;
    if (need > v->cap) {
        size_t cap = v->cap ? v->cap : 16;
        while (cap < need)
            cap = cap > SIZE_MAX / 2 ? need : cap * 2;
        if (cap > v->max)
            cap = v->max;
        if (cap > SIZE_MAX / v->elem)
            return SIZE_MAX;
        unsigned char *d = sw__realloc(v->data, cap * v->elem);
        if (!d)
            return SIZE_MAX;
        v->data = d;
        v->cap = cap;
    }
    size_t first = v->n;
    v->n = need;
    return first;
}

static uint32_t vec_push(sw__vec *v, const void *elem)
{
    size_t i = vec_grow(v, 1);
    if (i == SIZE_MAX)
        return SW_SG_NONE;
    memcpy(v->data + i * v->elem, elem, v->elem);
    return (uint32_t)i;
}

sw_sg_builder *sw_sg_builder_create(void)
{
    sw_sg_builder *b = sw__calloc(1, sizeof *b);
    if (!b)
        return NULL;
    const size_t rec_max = (size_t)SW_SG_NONE - 1; /* SW_SG_NONE itself is never an index */
    for (int s = 0; s < SW__SG_SEC_COUNT; s++)
        vec_init(&b->vec[s], sw__sg_section_record_size[s],
                 sw__sg_is_array_section(s) ? rec_max : 0);
    vec_init(&b->vec[SW__SG_SEC_POOL], sizeof(double), SIZE_MAX / sizeof(double));
    vec_init(&b->vec[SW__SG_SEC_INDICES], sizeof(uint32_t), SIZE_MAX / sizeof(uint32_t));
    vec_init(&b->last_child, sizeof(uint32_t), rec_max);
    b->root = 0;
    if (sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, SW_SG_NONE, SW_SG_NONE, NULL, NULL, NULL) !=
        0) {
        sw_sg_builder_free(b);
        return NULL;
    }
    return b;
}

void sw_sg_builder_free(sw_sg_builder *b)
{
    if (!b)
        return;
    for (int s = 0; s < SW__SG_SEC_COUNT; s++)
        sw__free(b->vec[s].data);
    sw__free(b->last_child.data);
    sw__free(b);
}

uint64_t sw_sg_builder_push_doubles(sw_sg_builder *b, const double *values, size_t count)
{
    sw__vec *v = &b->vec[SW__SG_SEC_POOL];
    size_t i = vec_grow(v, count);
    if (i == SIZE_MAX)
        return UINT64_MAX;
    if (count)
        memcpy(v->data + i * sizeof(double), values, count * sizeof(double));
    return i;
}

uint32_t sw_sg_builder_push_string(sw_sg_builder *b, const char *s)
{
    sw__vec *v = &b->vec[SW__SG_SEC_STRINGS];
    size_t len = strlen(s) + 1;
    size_t i = vec_grow(v, len);
    if (i == SIZE_MAX)
        return SW_SG_NONE;
    memcpy(v->data + i, s, len);
    return (uint32_t)i;
}

uint32_t sw_sg_builder_add_face(sw_sg_builder *b, const sw_sg_face_rec *face)
{
    return vec_push(&b->vec[SW__SG_SEC_FACES], face);
}

uint32_t sw_sg_builder_add_loop(sw_sg_builder *b, const sw_sg_loop_rec *loop)
{
    return vec_push(&b->vec[SW__SG_SEC_LOOPS], loop);
}

uint32_t sw_sg_builder_add_curve(sw_sg_builder *b, const sw_sg_curve_rec *curve)
{
    return vec_push(&b->vec[SW__SG_SEC_CURVES], curve);
}

uint32_t sw_sg_builder_add_adjacency(sw_sg_builder *b, uint32_t face_a, uint32_t face_b)
{
    sw_sg_adjacency_rec r = {face_a, face_b};
    return vec_push(&b->vec[SW__SG_SEC_ADJACENCY], &r);
}

uint64_t sw_sg_builder_push_indices(sw_sg_builder *b, const uint32_t *indices, size_t count)
{
    sw__vec *v = &b->vec[SW__SG_SEC_INDICES];
    size_t i = vec_grow(v, count);
    if (i == SIZE_MAX)
        return UINT64_MAX;
    if (count)
        memcpy(v->data + i * sizeof(uint32_t), indices, count * sizeof(uint32_t));
    return i;
}

uint32_t sw_sg_builder_add_mesh(sw_sg_builder *b, const sw_sg_mesh_rec *mesh)
{
    sw_sg_mesh_rec r = *mesh;
    const double *p = (const double *)b->vec[SW__SG_SEC_POOL].data + r.positions;
    assert(r.positions <= b->vec[SW__SG_SEC_POOL].n &&
           3 * (uint64_t)r.n_vertices <= b->vec[SW__SG_SEC_POOL].n - r.positions);
    sw_sg_mesh_box(p, r.n_vertices, r.box);
    return vec_push(&b->vec[SW__SG_SEC_MESHES], &r);
}

uint32_t sw_sg_builder_add_shape(sw_sg_builder *b, const sw_sg_shape_rec *shape)
{
    sw_sg_shape_rec r = *shape;
    const sw_sg_scene_view v = {
        .loops = (const sw_sg_loop_rec *)(const void *)b->vec[SW__SG_SEC_LOOPS].data,
        .curves = (const sw_sg_curve_rec *)(const void *)b->vec[SW__SG_SEC_CURVES].data,
        .pool = (const double *)(const void *)b->vec[SW__SG_SEC_POOL].data,
    };
    assert(r.first_loop <= b->vec[SW__SG_SEC_LOOPS].n &&
           r.n_loops <= b->vec[SW__SG_SEC_LOOPS].n - r.first_loop);
    sw_sg_shape_box(&v, r.first_loop, r.n_loops, r.box);
    return vec_push(&b->vec[SW__SG_SEC_SHAPES], &r);
}

uint32_t sw_sg_builder_add_node(sw_sg_builder *b, sw_sg_node_kind kind, uint32_t parent,
                                uint32_t ref, const double xform[12], const float color[4],
                                const char *name)
{
    sw__vec *nodes = &b->vec[SW__SG_SEC_NODES];
    assert(parent == SW_SG_NONE || parent < nodes->n);
    sw_sg_node_rec r;
    memset(&r, 0, sizeof r);
    r.kind = (uint32_t)kind;
    r.parent = parent;
    r.first_child = SW_SG_NONE;
    r.next_sibling = SW_SG_NONE;
    r.ref = ref;
    r.name = name ? sw_sg_builder_push_string(b, name) : SW_SG_NONE;
    if (name && r.name == SW_SG_NONE)
        return SW_SG_NONE;
    if (color)
        memcpy(r.color, color, sizeof r.color);
    else
        r.color[3] = -1.0f;
    memcpy(r.xform, xform ? xform : identity12, sizeof r.xform);

    const uint32_t none = SW_SG_NONE;
    if (vec_grow(&b->last_child, 1) == SIZE_MAX)
        return SW_SG_NONE;
    uint32_t idx = vec_push(nodes, &r);
    if (idx == SW_SG_NONE) {
        b->last_child.n--;
        return SW_SG_NONE;
    }
    memcpy(b->last_child.data + (size_t)idx * sizeof(uint32_t), &none, sizeof none);
    if (parent != SW_SG_NONE) {
        sw_sg_node_rec *all = (sw_sg_node_rec *)nodes->data;
        uint32_t *last = (uint32_t *)b->last_child.data;
        if (last[parent] == SW_SG_NONE)
            all[parent].first_child = idx;
        else
            all[last[parent]].next_sibling = idx;
        last[parent] = idx;
    }
    return idx;
}

double *sw_sg_builder_pool_ptr(sw_sg_builder *b)
{
    return (double *)b->vec[SW__SG_SEC_POOL].data;
}

sw_sg_face_rec *sw_sg_builder_face_ptr(sw_sg_builder *b, uint32_t face)
{
    assert(face < b->vec[SW__SG_SEC_FACES].n);
    return (sw_sg_face_rec *)b->vec[SW__SG_SEC_FACES].data + face;
}

uint32_t sw_sg_builder_face_count(const sw_sg_builder *b)
{
    return (uint32_t)b->vec[SW__SG_SEC_FACES].n;
}

void sw_sg_builder_set_root(sw_sg_builder *b, uint32_t node)
{
    assert(node < b->vec[SW__SG_SEC_NODES].n);
    b->root = node;
}

/* Moves the builder's arrays into `scene` (shrunk to size). */
static void builder_move_arrays(sw_sg_builder *b, sw_sg_scene *scene)
{
    for (int s = 0; s < SW__SG_SEC_COUNT; s++) {
        if (!sw__sg_is_array_section(s))
            continue;
        sw__vec *v = &b->vec[s];
        if (v->n && v->n < v->cap) {
            unsigned char *d = sw__realloc(v->data, v->n * v->elem);
            if (d)
                v->data = d;
        }
        scene->owned[s] = v->data;
        scene->owned_bytes += v->n * v->elem;
        v->data = NULL;
    }
    sw_sg_scene_view *w = &scene->view;
    w->faces = scene->owned[SW__SG_SEC_FACES];
    w->loops = scene->owned[SW__SG_SEC_LOOPS];
    w->curves = scene->owned[SW__SG_SEC_CURVES];
    w->nodes = scene->owned[SW__SG_SEC_NODES];
    w->adjacency = scene->owned[SW__SG_SEC_ADJACENCY];
    w->pool = scene->owned[SW__SG_SEC_POOL];
    w->strings = scene->owned[SW__SG_SEC_STRINGS];
    w->n_faces = (uint32_t)b->vec[SW__SG_SEC_FACES].n;
    w->n_loops = (uint32_t)b->vec[SW__SG_SEC_LOOPS].n;
    w->n_curves = (uint32_t)b->vec[SW__SG_SEC_CURVES].n;
    w->n_nodes = (uint32_t)b->vec[SW__SG_SEC_NODES].n;
    w->n_adjacency = (uint32_t)b->vec[SW__SG_SEC_ADJACENCY].n;
    w->n_pool = b->vec[SW__SG_SEC_POOL].n;
    w->n_strings = b->vec[SW__SG_SEC_STRINGS].n;
    w->root = b->root;
    w->meshes = scene->owned[SW__SG_SEC_MESHES];
    w->indices = scene->owned[SW__SG_SEC_INDICES];
    w->n_meshes = (uint32_t)b->vec[SW__SG_SEC_MESHES].n;
    w->n_indices = b->vec[SW__SG_SEC_INDICES].n;
    w->shapes = scene->owned[SW__SG_SEC_SHAPES];
    w->n_shapes = (uint32_t)b->vec[SW__SG_SEC_SHAPES].n;
}

sw_result sw_sg_builder_finish(sw_sg_builder *b, sw_sg_scene **out, sw_status *status)
{
    *out = NULL;
    sw_sg_scene *scene = sw__calloc(1, sizeof *scene);
    char *path = sw__calloc(1, 1);
    if (!scene || !path) {
        sw__free(scene);
        sw__free(path);
        sw_sg_builder_free(b);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "scene: out of memory");
    }
    scene->path = path;
    scene->serial = sw__sg_next_serial();
    builder_move_arrays(b, scene);
    sw_sg_builder_free(b);
    sw_result r = sw_sg_scene_validate(&scene->view, "scene", status);
    if (r != SW_OK) {
        sw_sg_scene_free(scene);
        return r;
    }
    scene->verified = SW_SG_SEC_ALL;
    scene->validated = 1;
    *out = scene;
    sw__status_ok(status);
    return SW_OK;
}

/* ---- the scene ------------------------------------------------------------------------------- */

const sw_sg_scene_view *sw_sg_scene_view_ptr(const sw_sg_scene *scene)
{
    return &scene->view;
}

const char *sw_sg_scene_path_ptr(const sw_sg_scene *scene)
{
    return scene->path;
}

uint64_t sw_sg_scene_serial(const sw_sg_scene *scene)
{
    return scene->serial;
}

uint64_t sw__sg_next_serial(void)
{
    static _Atomic uint64_t next = 0;
    /* relaxed: only uniqueness matters, and the scene is published to other threads later */
    return atomic_fetch_add_explicit(&next, 1u, memory_order_relaxed) + 1u;
}

const void *sw__sg_view_section(const sw_sg_scene_view *view, int s, uint64_t *bytes,
                                uint64_t *count)
{
    const void *p = NULL;
    uint64_t n = 0;
    switch (s) {
    case SW__SG_SEC_FACES:
        p = view->faces, n = view->n_faces;
        break;
    case SW__SG_SEC_LOOPS:
        p = view->loops, n = view->n_loops;
        break;
    case SW__SG_SEC_CURVES:
        p = view->curves, n = view->n_curves;
        break;
    case SW__SG_SEC_NODES:
        p = view->nodes, n = view->n_nodes;
        break;
    case SW__SG_SEC_ADJACENCY:
        p = view->adjacency, n = view->n_adjacency;
        break;
    case SW__SG_SEC_POOL:
        p = view->pool, n = view->n_pool;
        break;
    case SW__SG_SEC_STRINGS:
        p = view->strings, n = view->n_strings;
        break;
    case SW__SG_SEC_MESHES:
        p = view->meshes, n = view->n_meshes;
        break;
    case SW__SG_SEC_INDICES:
        p = view->indices, n = view->n_indices;
        break;
    case SW__SG_SEC_SHAPES:
        p = view->shapes, n = view->n_shapes;
        break;
    default:
        assert(!"not an array section");
    }
    *count = n;
    *bytes = n * sw__sg_section_record_size[s];
    return p;
}

void sw_sg_scene_face_surface(const sw_sg_scene *scene, uint32_t face, sw_sg_surface *out)
{
    assert(face < scene->view.n_faces);
    const sw_sg_face_rec *f = &scene->view.faces[face];
    const double *pool = scene->view.pool;
    out->deg_u = (int32_t)f->deg_u;
    out->deg_v = (int32_t)f->deg_v;
    out->n_u = (int32_t)f->n_u;
    out->n_v = (int32_t)f->n_v;
    out->knots_u = pool + f->knots_u;
    out->knots_v = pool + f->knots_v;
    out->cpw = pool + f->cpw;
}

void sw_sg_scene_curve(const sw_sg_scene *scene, uint32_t curve, sw_sg_curve *out)
{
    assert(curve < scene->view.n_curves);
    const sw_sg_curve_rec *c = &scene->view.curves[curve];
    out->degree = (int32_t)c->degree;
    out->n = (int32_t)c->n;
    out->dim = 3;
    out->knots = scene->view.pool + c->knots;
    out->cpw = scene->view.pool + c->cpw;
}

void sw_sg_shape_box(const sw_sg_scene_view *v, uint32_t first_loop, uint32_t n_loops,
                     double box[4])
{
    box[0] = box[1] = INFINITY;
    box[2] = box[3] = -INFINITY;
    for (uint32_t L = first_loop; L < first_loop + n_loops; ++L) {
        const sw_sg_loop_rec *l = &v->loops[L];
        for (uint32_t k = l->first_curve; k < l->first_curve + l->n_curves; ++k) {
            const double *cpw = v->pool + v->curves[k].cpw;
            for (uint32_t i = 0; i < v->curves[k].n; ++i)
                for (int d = 0; d < 2; ++d) {
                    double x = cpw[3 * i + d] / cpw[3 * i + 2];
                    box[d] = fmin(box[d], x);
                    box[2 + d] = fmax(box[2 + d], x);
                }
        }
    }
}

void sw_sg_mesh_box(const double *positions, uint32_t n, double box[6])
{
    for (int k = 0; k < 3; k++) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            const double x = positions[3 * (size_t)i + k];
            box[k] = x < box[k] ? x : box[k];
            box[3 + k] = x > box[3 + k] ? x : box[3 + k];
        }
}

void sw_sg_scene_mesh(const sw_sg_scene *scene, uint32_t mesh, const double **positions,
                      const double **normals, const uint32_t **indices)
{
    assert(mesh < scene->view.n_meshes);
    const sw_sg_mesh_rec *m = &scene->view.meshes[mesh];
    *positions = scene->view.pool + m->positions;
    *normals = m->normals == SW_SG_NO_NORMALS ? NULL : scene->view.pool + m->normals;
    *indices = scene->view.indices + m->indices;
}

size_t sw_sg_scene_memory(const sw_sg_scene *scene)
{
    return sizeof *scene + strlen(scene->path) + 1 + scene->owned_bytes + scene->map_size;
}

void sw_sg_scene_free(sw_sg_scene *scene)
{
    if (!scene)
        return;
    for (int s = 0; s < SW__SG_SEC_COUNT; s++)
        sw__free(scene->owned[s]);
    if (scene->map && scene->map_on_heap)
        sw__free(scene->map);
    else if (scene->map)
        munmap(scene->map, scene->map_size);
    sw__free(scene->path);
    sw__free(scene);
}

/* ---- traversal ------------------------------------------------------------------------------- */

/* world = parent * local for row-major 3x4 affine matrices. */
static void compose(const double p[12], const double l[12], double w[12])
{
    for (int r = 0; r < 3; r++) {
        const double *pr = p + 4 * r;
        for (int c = 0; c < 4; c++)
            w[4 * r + c] = pr[0] * l[c] + pr[1] * l[4 + c] + pr[2] * l[8 + c];
        w[4 * r + 3] += pr[3];
    }
}

/* A pending node with the transform and colour of its parent. follow: its next siblings come
 * after it (false for an instance's prototype, whose siblings belong to another subtree). */
typedef struct trav_entry {
    uint32_t node, depth;
    int follow;
    float color[4];
    double world[12];
} trav_entry;

typedef struct trav_stack {
    trav_entry *e;
    size_t n, cap;
    trav_entry local[32];
} trav_stack;

static int trav_push(trav_stack *st, uint32_t node, uint32_t depth, int follow,
                     const double world[12], const float color[4])
{
    if (st->n == st->cap) {
        size_t cap = st->cap * 2;
        trav_entry *e =
            st->e == st->local ? sw__malloc(cap * sizeof *e) : sw__realloc(st->e, cap * sizeof *e);
        if (!e)
            return 0;
        if (st->e == st->local)
            memcpy(e, st->local, sizeof st->local);
        st->e = e;
        st->cap = cap;
    }
    trav_entry *t = &st->e[st->n++];
    t->node = node;
    t->depth = depth;
    t->follow = follow;
    memcpy(t->color, color, sizeof t->color);
    memcpy(t->world, world, sizeof t->world);
    return 1;
}

/* Iterative depth-first walk (no recursion: CAD assemblies nest deeply). The depth guard only
 * matters for an unvalidated scene: a validated one has no cycle, so no path is longer than
 * n_nodes. One of the visitors is set: faces, or the nodes of kind `ref_kind` (meshes, shapes). */
static sw_result traverse(const sw_sg_scene *scene, sw_sg_visit_fn visit,
                          sw_sg_mesh_visit_fn visit_ref, uint32_t ref_kind, void *ctx)
{
    const sw_sg_scene_view *v = &scene->view;
    if (v->root >= v->n_nodes)
        return SW_OK;
    trav_stack st = {.n = 0, .cap = 32};
    st.e = st.local;
    int ok = trav_push(&st, v->root, 0, 0, identity12, default_color);
    while (ok && st.n) {
        trav_entry e = st.e[--st.n];
        if (e.node >= v->n_nodes || e.depth > v->n_nodes)
            continue;
        const sw_sg_node_rec *nd = &v->nodes[e.node];
        if (e.follow && nd->next_sibling != SW_SG_NONE)
            ok = trav_push(&st, nd->next_sibling, e.depth, 1, e.world, e.color);
        double world[12];
        compose(e.world, nd->xform, world);
        const float *color = nd->color[3] < 0.0f ? e.color : nd->color;
        if (visit && nd->kind == SW_SG_NODE_SURFACE && nd->ref < v->n_faces) {
            if (visit(ctx, nd->ref, world, color))
                break;
        }
        if (visit_ref && nd->kind == ref_kind &&
            nd->ref < (ref_kind == SW_SG_NODE_MESH ? v->n_meshes : v->n_shapes)) {
            if (visit_ref(ctx, nd->ref, e.node, world, color))
                break;
        }
        if (ok && nd->first_child != SW_SG_NONE)
            ok = trav_push(&st, nd->first_child, e.depth + 1, 1, world, color);
        if (ok && nd->kind == SW_SG_NODE_INSTANCE)
            ok = trav_push(&st, nd->ref, e.depth + 1, 0, world, color);
    }
    if (st.e != st.local)
        sw__free(st.e);
    return ok ? SW_OK : SW_ERR_OUT_OF_MEMORY;
}

sw_result sw_sg_scene_traverse(const sw_sg_scene *scene, sw_sg_visit_fn visit, void *ctx)
{
    return traverse(scene, visit, NULL, 0, ctx);
}

sw_result sw_sg_scene_traverse_meshes(const sw_sg_scene *scene, sw_sg_mesh_visit_fn visit,
                                      void *ctx)
{
    return traverse(scene, NULL, visit, SW_SG_NODE_MESH, ctx);
}

sw_result sw_sg_scene_traverse_shapes(const sw_sg_scene *scene, sw_sg_mesh_visit_fn visit,
                                      void *ctx)
{
    return traverse(scene, NULL, visit, SW_SG_NODE_SHAPE, ctx);
}

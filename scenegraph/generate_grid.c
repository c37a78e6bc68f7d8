/* SPDX-License-Identifier: MIT */
/* The grid generator (sw_sg_generate.h). */
#include "sw_sg_bvh.h"
#include "sw_hooks.h"
#include "sw_sg_generate.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The lattice for n cells: nx the smallest side with nx^dims >= n, then the others as small as
 * they can be, so the last layer (or row) is the only partial one. */
static void lattice(uint32_t n, int32_t dims, uint32_t out[3])
{
    uint64_t nx = 1;
    while ((dims == 3 ? nx * nx * nx : nx * nx) < n)
        ++nx;
    uint64_t ny = 1;
    if (dims == 3)
        while (nx * ny * ny < n)
            ++ny;
    else
        ny = (n + nx - 1) / nx;
    out[0] = (uint32_t)nx;
    out[1] = (uint32_t)ny;
    out[2] = (uint32_t)((n + nx * ny - 1) / (nx * ny));
}

/* The model's meshes, their offsets shifted by pool (where its pool went) and by where its
 * indices go; *first = the index of its first mesh in b. */
static int copy_meshes(const sw_sg_scene_view *v, sw_sg_builder *b, uint64_t pool, uint32_t *first)
{
    *first = 0;
    if (!v->n_meshes)
        return 1;
    const uint64_t idx = sw_sg_builder_push_indices(b, v->indices, v->n_indices);
    int ok = idx != UINT64_MAX;
    for (uint32_t i = 0; ok && i < v->n_meshes; ++i) {
        sw_sg_mesh_rec m = v->meshes[i];
        m.positions += pool;
        if (m.normals != SW_SG_NO_NORMALS)
            m.normals += pool;
        m.indices += idx;
        const uint32_t got = sw_sg_builder_add_mesh(b, &m);
        if (i == 0)
            *first = got;
        ok = got != SW_SG_NONE && got == *first + i;
    }
    return ok;
}

/* The model's shapes, their loops shifted by loop_base (where its loops went); *first = the
 * index of its first shape in b. */
static int copy_shapes(const sw_sg_scene_view *v, sw_sg_builder *b, uint32_t loop_base,
                       uint32_t *first)
{
    *first = 0;
    int ok = 1;
    for (uint32_t i = 0; ok && i < v->n_shapes; ++i) {
        sw_sg_shape_rec s = v->shapes[i];
        s.first_loop += loop_base;
        const uint32_t got = sw_sg_builder_add_shape(b, &s);
        if (i == 0)
            *first = got;
        ok = got != SW_SG_NONE && got == *first + i;
    }
    return ok;
}

/* Appends the geometry records of the model to `b` with indices and pool offsets shifted by what
 * `b` already holds (names come with the nodes); base[0..4] = face, loop, curve, mesh, shape
 * index bases. */
static sw_result copy_arrays(const sw_sg_scene_view *v, sw_sg_builder *b, uint32_t base[5],
                             sw_status *status)
{
    const uint64_t pool = v->n_pool ? sw_sg_builder_push_doubles(b, v->pool, v->n_pool) : 0;
    base[0] = sw_sg_builder_face_count(b);
    base[1] = base[2] = 0; /* the indices the first appends return */
    int ok = pool != UINT64_MAX;
    for (uint32_t i = 0; ok && i < v->n_curves; ++i) {
        sw_sg_curve_rec c = v->curves[i];
        c.knots += pool;
        c.cpw += pool;
        const uint32_t got = sw_sg_builder_add_curve(b, &c);
        if (i == 0)
            base[2] = got;
        ok = got != SW_SG_NONE && got == base[2] + i;
    }
    for (uint32_t i = 0; ok && i < v->n_loops; ++i) {
        sw_sg_loop_rec l = v->loops[i];
        l.first_curve += base[2];
        const uint32_t got = sw_sg_builder_add_loop(b, &l);
        if (i == 0)
            base[1] = got;
        ok = got != SW_SG_NONE && got == base[1] + i;
    }
    for (uint32_t i = 0; ok && i < v->n_faces; ++i) {
        sw_sg_face_rec f = v->faces[i];
        f.knots_u += pool;
        f.knots_v += pool;
        f.cpw += pool;
        f.first_loop += base[1];
        ok = sw_sg_builder_add_face(b, &f) == base[0] + i;
    }
    for (uint32_t i = 0; ok && i < v->n_adjacency; ++i)
        ok = sw_sg_builder_add_adjacency(b, base[0] + v->adjacency[i].face_a,
                                         base[0] + v->adjacency[i].face_b) != SW_SG_NONE;
    ok = ok && copy_meshes(v, b, pool, &base[3]);
    ok = ok && copy_shapes(v, b, base[1], &base[4]);
    if (!ok)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "copying a model: out of memory");
    return SW_OK;
}

/* Preorder of the model's node forest (every parentless node, in index order, its subtree first
 * child first), so that a node is added after its parent; map[i] = the builder index of node i,
 * which is base + its position in that order. */
static sw_result node_order(const sw_sg_scene_view *v, uint32_t base, uint32_t *order,
                            uint32_t *map, sw_status *status)
{
    uint32_t *stack = sw__malloc((v->n_nodes ? v->n_nodes : 1) * sizeof *stack);
    if (!stack)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "copying a model: out of memory");
    uint32_t n = 0;
    for (uint32_t r = 0; r < v->n_nodes; ++r) {
        if (v->nodes[r].parent != SW_SG_NONE)
            continue;
        uint32_t top = 0;
        stack[top++] = r;
        while (top > 0) {
            const uint32_t i = stack[--top];
            map[i] = base + n;
            order[n++] = i;
            /* children pushed last first, so the first child is taken first */
            uint32_t first = top;
            for (uint32_t c = v->nodes[i].first_child; c != SW_SG_NONE;
                 c = v->nodes[c].next_sibling)
                stack[top++] = c;
            for (uint32_t a = first, z = top; a + 1 < z; ++a, --z) {
                uint32_t t = stack[a];
                stack[a] = stack[z - 1];
                stack[z - 1] = t;
            }
        }
    }
    sw__free(stack);
    if (n != v->n_nodes) /* validation rules this out; the copy loop relies on it */
        return sw__fail(status, SW_ERR_FORMAT, "copying a model: %u of its %u nodes unreachable",
                        v->n_nodes - n, v->n_nodes);
    return SW_OK;
}

/* Adds the model's nodes as detached nodes of the builder (the prototype), refs remapped. */
static sw_result copy_nodes(const sw_sg_scene_view *v, sw_sg_builder *b, uint32_t base,
                            const uint32_t geom_base[5], uint32_t *proto, sw_status *status)
{
    uint32_t *order = sw__malloc((v->n_nodes ? v->n_nodes : 1) * sizeof *order);
    uint32_t *map = sw__malloc((v->n_nodes ? v->n_nodes : 1) * sizeof *map);
    sw_result r = order && map
                      ? node_order(v, base, order, map, status)
                      : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "copying a model: out of memory");
    for (uint32_t k = 0; r == SW_OK && k < v->n_nodes; ++k) {
        const sw_sg_node_rec *s = &v->nodes[order[k]];
        const uint32_t parent = s->parent == SW_SG_NONE ? SW_SG_NONE : map[s->parent];
        const uint32_t ref = s->kind == SW_SG_NODE_INSTANCE  ? map[s->ref]
                             : s->kind == SW_SG_NODE_SURFACE ? geom_base[0] + s->ref
                             : s->kind == SW_SG_NODE_MESH    ? geom_base[3] + s->ref
                             : s->kind == SW_SG_NODE_SHAPE   ? geom_base[4] + s->ref
                                                             : s->ref;
        const char *name = s->name == SW_SG_NONE ? NULL : v->strings + s->name;
        const uint32_t got = sw_sg_builder_add_node(b, (sw_sg_node_kind)s->kind, parent, ref,
                                                    s->xform, s->color, name);
        if (got != base + k)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "copying a model: out of memory");
    }
    *proto = r == SW_OK ? map[v->root] : SW_SG_NONE;
    sw__free(order);
    sw__free(map);
    return r;
}

sw_result sw__sg_append_model(sw_sg_builder *b, const sw_sg_scene_view *model, uint32_t node_base,
                              uint32_t *proto, sw_status *status)
{
    uint32_t base[5];
    sw_result r = copy_arrays(model, b, base, status);
    return r == SW_OK ? copy_nodes(model, b, node_base, base, proto, status) : r;
}

static sw_result check_desc(const sw_sg_grid_desc *d, sw_status *status)
{
    if (d->count < 1 || d->count > SW_SG_GRID_MAX_COUNT)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "grid: count %u outside 1..%u", d->count,
                        (unsigned)SW_SG_GRID_MAX_COUNT);
    if (d->dims != 2 && d->dims != 3)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "grid: %d dimensions (2 or 3)",
                        (int)d->dims);
    if (!(d->spacing >= 0.0) || !isfinite(d->spacing))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "grid: spacing %g (positive, or 0 for "
                        "the model's box)",
                        d->spacing);
    return SW_OK;
}

/* The model's box and occurrence count (sw_sg_occurrences_box), the spacing, the limit on
 * occurrences. */
static sw_result measure(const sw_sg_scene *model, const sw_sg_grid_desc *d, sw_sg_grid_report *rep,
                         sw_status *status)
{
    uint64_t per = 0;
    sw_result r = sw_sg_occurrences_box(model, &per, rep->model_box, status);
    if (r != SW_OK)
        return r;
    if (per == 0)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "grid: the model draws no faces");
    rep->occurrences = per * d->count;
    if (rep->occurrences > INT32_MAX)
        return sw__fail(status, SW_ERR_LIMIT,
                        "grid: %u instances x %llu face occurrences = %llu occurrences; the BVH "
                        "holds at most 2^31 - 1",
                        d->count, (unsigned long long)per, (unsigned long long)rep->occurrences);
    double ext[3], largest = 0.0;
    for (int k = 0; k < 3; ++k) {
        ext[k] = rep->model_box[3 + k] - rep->model_box[k];
        largest = fmax(largest, ext[k]);
    }
    if (d->spacing == 0.0 && !(largest > 0.0 && isfinite(largest)))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "grid: the model's box has extent %g: give a spacing", largest);
    for (int k = 0; k < 3; ++k)
        rep->spacing[k] = d->spacing > 0.0 ? d->spacing : ext[k] + 0.25 * largest;
    uint32_t n[3];
    lattice(d->count, d->dims, n);
    rep->nx = n[0];
    rep->ny = n[1];
    rep->nz = n[2];
    return SW_OK;
}

static sw_result add_instances(sw_sg_builder *b, const sw_sg_grid_desc *d,
                               const sw_sg_grid_report *rep, uint32_t proto, sw_status *status)
{
    for (uint32_t i = 0; i < d->count; ++i) {
        const uint32_t cell[3] = {i % rep->nx, (i / rep->nx) % rep->ny, i / (rep->nx * rep->ny)};
        double m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        for (int k = 0; k < 3; ++k)
            m[4 * k + 3] = cell[k] * rep->spacing[k];
        if (sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, m, NULL, NULL) == SW_SG_NONE)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid: instance %u of %u: out of memory",
                            i, d->count);
        if (d->progress && (i & 0xffffu) == 0)
            d->progress(d->user_data, 0.9 * i / d->count, "instances");
    }
    return SW_OK;
}

sw_result sw_sg_generate_grid(const sw_sg_scene *model, const sw_sg_grid_desc *desc,
                              sw_sg_scene **out, sw_sg_grid_report *report, sw_status *status)
{
    *out = NULL;
    sw_sg_grid_report rep;
    memset(&rep, 0, sizeof rep);
    sw_result r = check_desc(desc, status);
    if (r == SW_OK)
        r = measure(model, desc, &rep, status);
    if (r != SW_OK)
        return r;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid: out of memory");
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(model);
    uint32_t proto = SW_SG_NONE;
    r = sw__sg_append_model(b, v, 1, &proto, status); /* the builder holds its root only */
    if (r == SW_OK)
        r = add_instances(b, desc, &rep, proto, status);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    if (desc->progress)
        desc->progress(desc->user_data, 0.9, "validating");
    r = sw_sg_builder_finish(b, out, status);
    if (desc->progress)
        desc->progress(desc->user_data, 1.0, "done");
    if (r == SW_OK && report)
        *report = rep;
    return r;
}

/* SPDX-License-Identifier: MIT */
/* Validation of a scene's arrays before anything dereferences them: every index, pool offset and
 * count against the array sizes (in 64-bit arithmetic that cannot overflow), the node graph for
 * cycles (child links and instance references together), and each face's and curve's geometry
 * through sw_sg_surface_validate / sw_sg_curve_validate. Mapped .sws files are hostile input
 * (CONVENTIONS.md, Errors): this is the "validate" step after sws_file.c's "parse". */
#include "sw_sg_scene_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct vctx {
    const sw_sg_scene_view *v;
    const char *what;
    const sw__sg_section_info *sec; /* may be NULL */
    sw_status *status;
} vctx;

/* " at offset N" for record i of section s of a mapped file, "" in memory. */
static const char *where(const vctx *c, int s, uint64_t i, char buf[48])
{
    buf[0] = '\0';
    if (c->sec)
        snprintf(buf, 48, " at offset %llu",
                 (unsigned long long)(c->sec[s].offset + i * sw__sg_section_record_size[s]));
    return buf;
}

/* [off, off + count) lies inside the pool; count is at most 2^64 - 1 by construction. */
static int pool_range_ok(const sw_sg_scene_view *v, uint64_t off, uint64_t count)
{
    return off <= v->n_pool && count <= v->n_pool - off;
}

static int all_finite(const double *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

static sw_result check_face_record(const vctx *c, uint32_t i, const sw_sg_face_rec *f)
{
    char at[48];
    const sw_sg_scene_view *v = c->v;
    where(c, SW__SG_SEC_FACES, i, at);
    if (f->deg_u < 1 || f->deg_u > SW_SG_MAX_DEGREE || f->deg_v < 1 || f->deg_v > SW_SG_MAX_DEGREE)
        return sw__fail(c->status, SW_ERR_INVALID_GEOMETRY, "%s: face %u%s: degree %ux%u", c->what,
                        i, at, f->deg_u, f->deg_v);
    if (f->n_u <= f->deg_u || f->n_v <= f->deg_v || f->n_u > INT32_MAX || f->n_v > INT32_MAX)
        return sw__fail(c->status, SW_ERR_INVALID_GEOMETRY,
                        "%s: face %u%s: %ux%u control points for degree %ux%u", c->what, i, at,
                        f->n_u, f->n_v, f->deg_u, f->deg_v);
    /* n < 2^31 and deg < 32: the sums fit; n_u * n_v * 4 < 2^64. */
    uint64_t nku = (uint64_t)f->n_u + f->deg_u + 1, nkv = (uint64_t)f->n_v + f->deg_v + 1;
    uint64_t ncp = (uint64_t)f->n_u * f->n_v * 4u;
    if (!pool_range_ok(v, f->knots_u, nku) || !pool_range_ok(v, f->knots_v, nkv) ||
        !pool_range_ok(v, f->cpw, ncp))
        return sw__fail(c->status, SW_ERR_FORMAT,
                        "%s: face %u%s: knots/control points (pool offsets %llu, %llu, %llu) "
                        "outside the pool of %llu doubles",
                        c->what, i, at, (unsigned long long)f->knots_u,
                        (unsigned long long)f->knots_v, (unsigned long long)f->cpw,
                        (unsigned long long)v->n_pool);
    if (f->first_loop > v->n_loops || f->n_loops > v->n_loops - f->first_loop)
        return sw__fail(c->status, SW_ERR_FORMAT, "%s: face %u%s: loops [%u, +%u) of %u", c->what,
                        i, at, f->first_loop, f->n_loops, v->n_loops);
    if (f->kind >= SW_SG_KIND_COUNT || (f->flags & ~(uint32_t)SW_SG_FACE_FLAGS_ALL))
        return sw__fail(c->status, SW_ERR_FORMAT, "%s: face %u%s: kind %u, flags 0x%x", c->what, i,
                        at, f->kind, f->flags);
    if (!all_finite(f->uv_box, 4) || f->uv_box[0] > f->uv_box[1] || f->uv_box[2] > f->uv_box[3] ||
        !isfinite(f->tolerance) || f->tolerance < 0.0)
        return sw__fail(c->status, SW_ERR_INVALID_GEOMETRY,
                        "%s: face %u%s: bad uv box or tolerance", c->what, i, at);
    return SW_OK;
}

static sw_result check_faces(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_faces; i++) {
        const sw_sg_face_rec *f = &v->faces[i];
        sw_result r = check_face_record(c, i, f);
        if (r != SW_OK)
            return r;
        sw_sg_surface s = {(int32_t)f->deg_u, (int32_t)f->deg_v,    (int32_t)f->n_u,
                           (int32_t)f->n_v,   v->pool + f->knots_u, v->pool + f->knots_v,
                           v->pool + f->cpw};
        /* The face's name is only formatted when it is needed, for the message. */
        if (sw_sg_surface_validate(&s, c->what, NULL) != SW_OK) {
            char what[300], at[48];
            snprintf(what, sizeof what, "%s: face %u%s", c->what, i,
                     where(c, SW__SG_SEC_FACES, i, at));
            return sw_sg_surface_validate(&s, what, c->status);
        }
    }
    return SW_OK;
}

static sw_result check_loops(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_loops; i++) {
        const sw_sg_loop_rec *l = &v->loops[i];
        char at[48];
        if (l->n_curves == 0 || l->first_curve > v->n_curves ||
            l->n_curves > v->n_curves - l->first_curve ||
            (l->flags & ~(uint32_t)SW_SG_LOOP_OUTER) || l->reserved != 0)
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: loop %u%s: curves [%u, +%u) of %u, flags 0x%x, reserved %u",
                            c->what, i, where(c, SW__SG_SEC_LOOPS, i, at), l->first_curve,
                            l->n_curves, v->n_curves, l->flags, l->reserved);
    }
    return SW_OK;
}

/* Index checks of one curve record; `what` is formatted by the caller only on failure. */
static int curve_record_ok(const sw_sg_scene_view *v, const sw_sg_curve_rec *k, sw_result *r)
{
    if (k->degree < 1 || k->degree > SW_SG_MAX_DEGREE || k->n <= k->degree || k->n > INT32_MAX) {
        *r = SW_ERR_INVALID_GEOMETRY;
        return 0;
    }
    if (!pool_range_ok(v, k->knots, (uint64_t)k->n + k->degree + 1) ||
        !pool_range_ok(v, k->cpw, (uint64_t)k->n * 3u)) {
        *r = SW_ERR_FORMAT;
        return 0;
    }
    return 1;
}

static sw_result check_curves(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_curves; i++) {
        const sw_sg_curve_rec *k = &v->curves[i];
        sw_result r = SW_OK;
        int record_ok = curve_record_ok(v, k, &r);
        sw_sg_curve cv = {(int32_t)k->degree, (int32_t)k->n, 3, NULL, NULL};
        if (record_ok) {
            cv.knots = v->pool + k->knots;
            cv.cpw = v->pool + k->cpw;
            if (sw_sg_curve_validate(&cv, c->what, NULL) == SW_OK)
                continue;
        }
        char what[300], at[48];
        snprintf(what, sizeof what, "%s: curve %u%s", c->what, i,
                 where(c, SW__SG_SEC_CURVES, i, at));
        if (record_ok)
            return sw_sg_curve_validate(&cv, what, c->status);
        return sw__fail(c->status, r,
                        "%s: degree %u with %u control points at pool offsets %llu, %llu (pool "
                        "of %llu doubles)",
                        what, k->degree, k->n, (unsigned long long)k->knots,
                        (unsigned long long)k->cpw, (unsigned long long)v->n_pool);
    }
    return SW_OK;
}

static int node_link_ok(uint32_t link, uint32_t n)
{
    return link == SW_SG_NONE || link < n;
}

static sw_result check_node_records(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_nodes; i++) {
        const sw_sg_node_rec *nd = &v->nodes[i];
        char at[48];
        where(c, SW__SG_SEC_NODES, i, at);
        int ref_ok = nd->kind == SW_SG_NODE_SURFACE    ? nd->ref < v->n_faces
                     : nd->kind == SW_SG_NODE_INSTANCE ? nd->ref < v->n_nodes
                     : nd->kind == SW_SG_NODE_MESH     ? nd->ref < v->n_meshes
                     : nd->kind == SW_SG_NODE_SHAPE    ? nd->ref < v->n_shapes
                                                       : 1;
        if (nd->kind > SW_SG_NODE_SHAPE || !ref_ok)
            return sw__fail(c->status, SW_ERR_FORMAT, "%s: node %u%s: kind %u, ref %u", c->what, i,
                            at, nd->kind, nd->ref);
        if (!node_link_ok(nd->parent, v->n_nodes) || !node_link_ok(nd->first_child, v->n_nodes) ||
            !node_link_ok(nd->next_sibling, v->n_nodes))
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: node %u%s: parent %u, first child %u, next sibling %u of %u "
                            "nodes",
                            c->what, i, at, nd->parent, nd->first_child, nd->next_sibling,
                            v->n_nodes);
        if (nd->name != SW_SG_NONE && nd->name >= v->n_strings)
            return sw__fail(c->status, SW_ERR_FORMAT, "%s: node %u%s: name offset %u of %llu",
                            c->what, i, at, nd->name, (unsigned long long)v->n_strings);
        int color_ok = 1;
        for (int k = 0; k < 4; k++)
            color_ok &= isfinite(nd->color[k]) != 0;
        if (!color_ok || !all_finite(nd->xform, 12))
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: node %u%s: non-finite colour or "
                            "transform",
                            c->what, i, at);
        for (int k = 0; k < 12; k++)
            if (!(fabs(nd->xform[k]) <= SW_SG_XFORM_MAX)) /* the rule: sw_sg_geom.h */
                return sw__fail(c->status, SW_ERR_INVALID_GEOMETRY,
                                "%s: node %u%s: transform entry %d is %g, beyond %g (products "
                                "would overflow)",
                                c->what, i, at, k, nd->xform[k], SW_SG_XFORM_MAX);
    }
    return SW_OK;
}

/* Every child chain is consistent with the parent links and visits each node at most once, so
 * walking a chain terminates; together with the DFS below the node graph is a DAG. */
static sw_result check_child_chains(const vctx *c, unsigned char *seen)
{
    const sw_sg_scene_view *v = c->v;
    uint64_t in_chains = 0, with_parent = 0;
    for (uint32_t p = 0; p < v->n_nodes; p++) {
        if (v->nodes[p].parent != SW_SG_NONE)
            with_parent++;
        for (uint32_t k = v->nodes[p].first_child; k != SW_SG_NONE; k = v->nodes[k].next_sibling) {
            char at[48];
            if (seen[k] || v->nodes[k].parent != p)
                return sw__fail(c->status, SW_ERR_FORMAT,
                                "%s: node %u%s: listed as a child of node %u (parent %u)%s",
                                c->what, k, where(c, SW__SG_SEC_NODES, k, at), p,
                                v->nodes[k].parent, seen[k] ? " twice" : "");
            seen[k] = 1;
            in_chains++;
        }
    }
    if (in_chains != with_parent)
        return sw__fail(c->status, SW_ERR_FORMAT,
                        "%s: %llu nodes have a parent but %llu are in their parents' child lists",
                        c->what, (unsigned long long)with_parent, (unsigned long long)in_chains);
    return SW_OK;
}

/* Iterative three-colour DFS over child and instance edges. The stack holds each grey node and
 * where its edge iteration stands: the next child to visit, then (once) the instance reference. */
typedef struct dfs_frame {
    uint32_t node, next_child;
    int ref_done;
} dfs_frame;

static sw_result check_cycles(const vctx *c, unsigned char *color, dfs_frame *stack)
{
    const sw_sg_scene_view *v = c->v;
    memset(color, 0, v->n_nodes);
    for (uint32_t start = 0; start < v->n_nodes; start++) {
        if (color[start])
            continue;
        size_t n = 0;
        stack[n++] = (dfs_frame){start, v->nodes[start].first_child, 0};
        color[start] = 1;
        while (n) {
            dfs_frame *f = &stack[n - 1];
            const sw_sg_node_rec *nd = &v->nodes[f->node];
            uint32_t next = SW_SG_NONE;
            if (f->next_child != SW_SG_NONE) {
                next = f->next_child;
                f->next_child = v->nodes[next].next_sibling;
            } else if (!f->ref_done && nd->kind == SW_SG_NODE_INSTANCE) {
                f->ref_done = 1;
                next = nd->ref;
            }
            if (next == SW_SG_NONE) {
                color[f->node] = 2;
                n--;
                continue;
            }
            if (color[next] == 1) {
                char at[48];
                return sw__fail(c->status, SW_ERR_FORMAT,
                                "%s: node %u%s: cycle in the node graph (through node %u)", c->what,
                                f->node, where(c, SW__SG_SEC_NODES, f->node, at), next);
            }
            if (color[next] == 0) {
                color[next] = 1;
                stack[n++] = (dfs_frame){next, v->nodes[next].first_child, 0};
            }
        }
    }
    return SW_OK;
}

static sw_result check_nodes(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    char at[48];
    if (v->root >= v->n_nodes)
        return sw__fail(c->status, SW_ERR_FORMAT, "%s: META%s: root node %u of %u nodes", c->what,
                        where(c, SW__SG_SEC_META, 0, at), v->root, v->n_nodes);
    sw_result r = check_node_records(c);
    if (r != SW_OK)
        return r;
    unsigned char *marks = sw__calloc(v->n_nodes, 1);
    dfs_frame *stack = sw__malloc((size_t)v->n_nodes * sizeof *stack);
    if (!marks || !stack) {
        sw__free(marks);
        sw__free(stack);
        return sw__fail(c->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory validating %u nodes",
                        c->what, v->n_nodes);
    }
    r = check_child_chains(c, marks);
    if (r == SW_OK)
        r = check_cycles(c, marks, stack);
    sw__free(marks);
    sw__free(stack);
    return r;
}

/* A mesh's ranges, flags, indices (each below its vertex count), finite positions and normals,
 * and its stored box (exactly the positions' box: culling and picking trust it). */
static sw_result check_mesh(const vctx *c, uint32_t i, const sw_sg_mesh_rec *m)
{
    const sw_sg_scene_view *v = c->v;
    char at[48];
    where(c, SW__SG_SEC_MESHES, i, at);
    const uint64_t nv3 = 3 * (uint64_t)m->n_vertices, ni = 3 * (uint64_t)m->n_triangles;
    if (m->n_vertices < 3 || m->n_triangles < 1 || m->flags || m->reserved)
        return sw__fail(c->status, SW_ERR_FORMAT,
                        "%s: mesh %u%s: %u vertices, %u triangles, flags 0x%x, reserved %u "
                        "(at least 3 and 1, zero flags)",
                        c->what, i, at, m->n_vertices, m->n_triangles, m->flags, m->reserved);
    if (!pool_range_ok(v, m->positions, nv3) ||
        (m->normals != SW_SG_NO_NORMALS && !pool_range_ok(v, m->normals, nv3)) ||
        m->indices > v->n_indices || ni > v->n_indices - m->indices)
        return sw__fail(c->status, SW_ERR_FORMAT,
                        "%s: mesh %u%s: positions %llu, normals %llu or indices %llu outside the "
                        "pool (%llu doubles) or INDICES (%llu)",
                        c->what, i, at, (unsigned long long)m->positions,
                        (unsigned long long)m->normals, (unsigned long long)m->indices,
                        (unsigned long long)v->n_pool, (unsigned long long)v->n_indices);
    const uint32_t *idx = v->indices + m->indices;
    for (uint64_t k = 0; k < ni; k++)
        if (idx[k] >= m->n_vertices)
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: mesh %u%s: index %llu (triangle %llu) is %u of %u vertices",
                            c->what, i, at, (unsigned long long)k, (unsigned long long)(k / 3),
                            idx[k], m->n_vertices);
    const double *p = v->pool + m->positions;
    for (uint64_t k = 0; k < nv3; k++)
        if (!(fabs(p[k]) <= SW_SG_COORD_MAX) || /* finite, and the rule of sw_sg_geom.h */
            (m->normals != SW_SG_NO_NORMALS && !isfinite(v->pool[m->normals + k])))
            return sw__fail(c->status, SW_ERR_INVALID_GEOMETRY,
                            "%s: mesh %u%s: vertex %llu: non-finite position or normal", c->what, i,
                            at, (unsigned long long)(k / 3));
    double box[6];
    sw_sg_mesh_box(p, m->n_vertices, box);
    if (memcmp(box, m->box, sizeof box) != 0)
        return sw__fail(c->status, SW_ERR_FORMAT,
                        "%s: mesh %u%s: stored box is not the box of its positions", c->what, i,
                        at);
    return SW_OK;
}

static sw_result check_meshes(const vctx *c)
{
    for (uint32_t i = 0; i < c->v->n_meshes; i++) {
        sw_result r = check_mesh(c, i, &c->v->meshes[i]);
        if (r != SW_OK)
            return r;
    }
    return SW_OK;
}

/* A shape's loop range, flags and stored box (exactly its curves' control points' box: culling
 * trusts it). Runs after the loops and curves are checked. */
static sw_result check_shapes(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_shapes; i++) {
        const sw_sg_shape_rec *s = &v->shapes[i];
        char at[48];
        where(c, SW__SG_SEC_SHAPES, i, at);
        const int screen = (s->flags & SW_SG_SHAPE_SCREEN) != 0;
        if (s->n_loops == 0 || s->first_loop > v->n_loops ||
            s->n_loops > v->n_loops - s->first_loop ||
            (s->flags & ~(uint32_t)SW_SG_SHAPE_FLAGS_ALL) || s->reserved ||
            (screen ? !(s->px_size > 0.0 && s->px_size <= SW_SG_SHAPE_MAX_PX) : s->px_size != 0.0))
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: shape %u%s: loops [%u, +%u) of %u, flags 0x%x, reserved %u, %g px "
                            "per unit",
                            c->what, i, at, s->first_loop, s->n_loops, v->n_loops, s->flags,
                            s->reserved, s->px_size);
        double box[4];
        sw_sg_shape_box(v, s->first_loop, s->n_loops, box);
        if (memcmp(box, s->box, sizeof box) != 0)
            return sw__fail(c->status, SW_ERR_FORMAT,
                            "%s: shape %u%s: stored box is not the box of its curves", c->what, i,
                            at);
    }
    return SW_OK;
}

static sw_result check_misc(const vctx *c)
{
    const sw_sg_scene_view *v = c->v;
    for (uint32_t i = 0; i < v->n_adjacency; i++) {
        char at[48];
        if (v->adjacency[i].face_a >= v->n_faces || v->adjacency[i].face_b >= v->n_faces)
            return sw__fail(c->status, SW_ERR_FORMAT, "%s: adjacency %u%s: faces %u, %u of %u",
                            c->what, i, where(c, SW__SG_SEC_ADJACENCY, i, at),
                            v->adjacency[i].face_a, v->adjacency[i].face_b, v->n_faces);
    }
    /* A terminating NUL at the end makes every name offset below n_strings a valid C string. */
    if (v->n_strings && v->strings[v->n_strings - 1] != '\0') {
        char at[48];
        return sw__fail(c->status, SW_ERR_FORMAT, "%s: strings%s: not NUL-terminated", c->what,
                        where(c, SW__SG_SEC_STRINGS, v->n_strings - 1, at));
    }
    return SW_OK;
}

sw_result sw__sg_scene_validate_at(const sw_sg_scene_view *view, const char *what,
                                   const sw__sg_section_info *sec, sw_status *status)
{
    vctx c = {view, what ? what : "scene", sec, status};
    /* Cheap structural checks first, geometry last: a bad index is reported as such. */
    sw_result r = check_misc(&c);
    if (r == SW_OK)
        r = check_nodes(&c);
    if (r == SW_OK)
        r = check_loops(&c);
    if (r == SW_OK)
        r = check_faces(&c);
    if (r == SW_OK)
        r = check_curves(&c);
    if (r == SW_OK)
        r = check_meshes(&c);
    if (r == SW_OK)
        r = check_shapes(&c);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

sw_result sw_sg_scene_validate(const sw_sg_scene_view *view, const char *what, sw_status *status)
{
    return sw__sg_scene_validate_at(view, what, NULL, status);
}

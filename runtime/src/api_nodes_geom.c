/* SPDX-License-Identifier: MIT */
/* Node scenes: each geometry node's desc checked and turned into its private one-object scene
 * (api_nodes_internal.h, sw__rt_make_geom): trimmed NURBS surfaces, T-splines, imported files,
 * triangle meshes, planar outlines and text labels (the text module's glyph outlines). The tree
 * that holds them is api_nodes.c's. */
#include "api_nodes_internal.h"
#include "sw_hooks.h"
#include "sw_sg_text.h"
#include "sw_sg_trim.h"
#include "sw_sg_tspline.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- geometry: private one-object scenes -------------------------------------------------------
 */

static double *homogeneous(const double *points, const double *weights, uint32_t n, int dim)
{
    double *cpw = sw__malloc((size_t)n * (size_t)(dim + 1) * sizeof *cpw);
    if (!cpw)
        return NULL;
    for (uint32_t i = 0; i < n; i++) {
        double w = weights ? weights[i] : 1.0;
        for (int k = 0; k < dim; k++)
            cpw[(size_t)i * (dim + 1) + k] = w * points[(size_t)i * dim + k];
        cpw[(size_t)i * (dim + 1) + dim] = w;
    }
    return cpw;
}

static uint64_t push_homogeneous(sw_sg_builder *b, const double *points, const double *weights,
                                 uint32_t n, int dim)
{
    double *cpw = homogeneous(points, weights, n, dim);
    uint64_t at = cpw ? sw_sg_builder_push_doubles(b, cpw, (size_t)n * (dim + 1)) : UINT64_MAX;
    sw__free(cpw);
    return at;
}

/* The loops' counts and pointers (a surface's trim loops, a shape's outline); their geometry is
 * checked as it is pushed (add_loop). */
static sw_result check_loops_desc(const char *fn, const sw_trim_loop *loops, uint32_t n,
                                  sw_status *status)
{
    if (n && !loops)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "%s: %u loops but NULL loops", fn, n);
    if (n > SW__NODES_MAX_LOOPS)
        return sw__fail(status, SW_ERR_LIMIT, "%s: %u loops (at most %u)", fn, n,
                        SW__NODES_MAX_LOOPS);
    for (uint32_t l = 0; l < n; l++) {
        const sw_trim_loop *lp = &loops[l];
        if (!lp->curves || lp->curve_count < 1 || lp->curve_count > SW__NODES_MAX_LOOPS)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "%s: loop %u has no curves (or NULL curves)", fn, l);
        for (uint32_t c = 0; c < lp->curve_count; c++) {
            const sw_trim_curve *tc = &lp->curves[c];
            if (tc->degree < 1 || tc->degree > SW_SG_MAX_DEGREE || tc->count < tc->degree + 1 ||
                tc->count > SW__NODES_MAX_POINTS)
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "%s: loop %u curve %u: degree %u with %u control points", fn, l, c,
                                tc->degree, tc->count);
            if (!tc->knots || !tc->points)
                return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                                "%s: loop %u curve %u: NULL knots or points", fn, l, c);
        }
    }
    return SW_OK;
}

static sw_result check_nurbs_desc(const sw_nurbs_desc *d, sw_status *status)
{
    const char *fn = "NURBS surface";
    if (d->degree_u < 1 || d->degree_u > SW_SG_MAX_DEGREE || d->degree_v < 1 ||
        d->degree_v > SW_SG_MAX_DEGREE)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "%s: degrees %u x %u out of 1..%d", fn,
                        d->degree_u, d->degree_v, SW_SG_MAX_DEGREE);
    if (d->count_u < d->degree_u + 1 || d->count_v < d->degree_v + 1)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s: %u x %u control points for degrees %u x %u (need degree + 1)", fn,
                        d->count_u, d->count_v, d->degree_u, d->degree_v);
    if ((uint64_t)d->count_u * d->count_v > SW__NODES_MAX_POINTS)
        return sw__fail(status, SW_ERR_LIMIT, "%s: %u x %u control points (at most %u)", fn,
                        d->count_u, d->count_v, SW__NODES_MAX_POINTS);
    if (!d->knots_u || !d->knots_v || !d->points)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "%s: NULL knots or points", fn);
    return check_loops_desc(fn, d->loops, d->loop_count, status);
}

/* One loop's curves pushed, checked and snapped closed (sw_sg_trim_snap_loop); *box grows by
 * their control points (the hull bounds the curves: weights are positive). */
static sw_result add_loop(sw_sg_builder *b, const char *fn, const sw_trim_loop *lp, uint32_t index,
                          double max_gap, double box[4], uint32_t *loop_out, sw_status *status)
{
    uint32_t nc = lp->curve_count;
    uint64_t *kn = sw__malloc(nc * sizeof *kn), *cp = sw__malloc(nc * sizeof *cp);
    double **ptrs = sw__malloc(nc * sizeof *ptrs);
    int32_t *counts = sw__malloc(nc * sizeof *counts);
    sw_result r = kn && cp && ptrs && counts ? SW_OK : SW_ERR_OUT_OF_MEMORY;
    for (uint32_t c = 0; r == SW_OK && c < nc; c++) {
        const sw_trim_curve *tc = &lp->curves[c];
        kn[c] = sw_sg_builder_push_doubles(b, tc->knots, tc->count + tc->degree + 1);
        cp[c] = push_homogeneous(b, tc->points, tc->weights, tc->count, 2);
        counts[c] = (int32_t)tc->count;
        if (kn[c] == UINT64_MAX || cp[c] == UINT64_MAX)
            r = SW_ERR_OUT_OF_MEMORY;
    }
    if (r == SW_ERR_OUT_OF_MEMORY)
        sw__fail(status, r, "%s: out of memory", fn);
    char what[64];
    snprintf(what, sizeof what, "%s, loop %u", fn, index);
    double *pool = sw_sg_builder_pool_ptr(b); /* stable until the next push */
    double own[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    for (uint32_t c = 0; r == SW_OK && c < nc; c++) {
        const sw_trim_curve *tc = &lp->curves[c];
        sw_sg_curve curve = {(int32_t)tc->degree, counts[c], 3, pool + kn[c], pool + cp[c]};
        r = sw_sg_curve_validate(&curve, what, status);
        ptrs[c] = pool + cp[c];
        for (uint32_t i = 0; r == SW_OK && i < tc->count; i++) {
            double u = tc->points[2 * i], v = tc->points[2 * i + 1];
            own[0] = fmin(own[0], u), own[1] = fmax(own[1], u);
            own[2] = fmin(own[2], v), own[3] = fmax(own[3], v);
        }
    }
    /* A loop whose control points (the curves' hull) span no width or no height encloses no area:
     * its trim texture would be empty, so the caller meant something else. */
    if (r == SW_OK && !(own[1] - own[0] > max_gap && own[3] - own[2] > max_gap))
        r = sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                     "%s: degenerate, its curves span [%g, %g] x [%g, %g] (no area)", what, own[0],
                     own[1], own[2], own[3]);
    if (r == SW_OK) {
        box[0] = fmin(box[0], own[0]), box[1] = fmax(box[1], own[1]);
        box[2] = fmin(box[2], own[2]), box[3] = fmax(box[3], own[3]);
    }
    if (r == SW_OK)
        r = sw_sg_trim_snap_loop((int32_t)nc, ptrs, counts, max_gap, what, status);
    sw_sg_loop_rec rec = {SW_SG_NONE, nc, index == 0 ? SW_SG_LOOP_OUTER : 0u, 0};
    for (uint32_t c = 0; r == SW_OK && c < nc; c++) {
        const sw_trim_curve *tc = &lp->curves[c];
        sw_sg_curve_rec cr = {tc->degree, tc->count, kn[c], cp[c]};
        uint32_t ci = sw_sg_builder_add_curve(b, &cr);
        if (ci == SW_SG_NONE)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
        if (c == 0)
            rec.first_curve = ci;
    }
    if (r == SW_OK && (*loop_out = sw_sg_builder_add_loop(b, &rec)) == SW_SG_NONE)
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    sw__free(kn);
    sw__free(cp);
    sw__free(ptrs);
    sw__free(counts);
    return r;
}

static sw_result fill_surface(sw_sg_builder *b, const sw_nurbs_desc *d, sw_sg_face_rec *rec,
                              sw_status *status)
{
    rec->deg_u = d->degree_u, rec->deg_v = d->degree_v;
    rec->n_u = d->count_u, rec->n_v = d->count_v;
    rec->knots_u = sw_sg_builder_push_doubles(b, d->knots_u, d->count_u + d->degree_u + 1);
    rec->knots_v = sw_sg_builder_push_doubles(b, d->knots_v, d->count_v + d->degree_v + 1);
    rec->cpw = push_homogeneous(b, d->points, d->weights, d->count_u * d->count_v, 3);
    if (rec->knots_u == UINT64_MAX || rec->knots_v == UINT64_MAX || rec->cpw == UINT64_MAX)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "NURBS surface: out of memory");
    const double *pool = sw_sg_builder_pool_ptr(b);
    sw_sg_surface s = {(int32_t)rec->deg_u, (int32_t)rec->deg_v, (int32_t)rec->n_u,
                       (int32_t)rec->n_v,   pool + rec->knots_u, pool + rec->knots_v,
                       pool + rec->cpw};
    sw_result r = sw_sg_surface_validate(&s, "NURBS surface", status);
    if (r != SW_OK)
        return r;
    sw_sg_knots_domain(s.knots_u, s.deg_u, s.n_u, &rec->uv_box[0], &rec->uv_box[1]);
    sw_sg_knots_domain(s.knots_v, s.deg_v, s.n_v, &rec->uv_box[2], &rec->uv_box[3]);
    return SW_OK;
}

/* The trim loops of a face; the face's uv_box shrinks to the loops' box inside its domain. */
static sw_result fill_loops(sw_sg_builder *b, const sw_nurbs_desc *d, sw_sg_face_rec *rec,
                            sw_status *status)
{
    double dom[4];
    memcpy(dom, rec->uv_box, sizeof dom);
    double max_gap = 1e-6 * fmax(dom[1] - dom[0], dom[3] - dom[2]);
    double box[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    for (uint32_t l = 0; l < d->loop_count; l++) {
        uint32_t li = SW_SG_NONE;
        sw_result r = add_loop(b, "NURBS surface", &d->loops[l], l, max_gap, box, &li, status);
        if (r != SW_OK)
            return r;
        if (l == 0)
            rec->first_loop = li;
    }
    rec->n_loops = d->loop_count;
    rec->flags |= SW_SG_FACE_TRIMMED;
    rec->uv_box[0] = fmax(dom[0], box[0]), rec->uv_box[1] = fmin(dom[1], box[1]);
    rec->uv_box[2] = fmax(dom[2], box[2]), rec->uv_box[3] = fmin(dom[3], box[3]);
    if (!(rec->uv_box[0] < rec->uv_box[1] && rec->uv_box[2] < rec->uv_box[3]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "NURBS surface: its trim loops lie outside its domain [%g, %g] x [%g, %g]",
                        dom[0], dom[1], dom[2], dom[3]);
    return SW_OK;
}

sw_result sw__rt_nurbs_geom(const sw_nurbs_desc *d, sw_sg_scene **out, sw_status *status)
{
    sw_result r = check_nurbs_desc(d, status);
    if (r != SW_OK)
        return r;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "NURBS surface: out of memory");
    sw_sg_face_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.kind = SW_SG_KIND_BSPLINE;
    rec.flags = d->reversed ? SW_SG_FACE_REVERSED : 0u;
    rec.tolerance = 1e-7;
    r = fill_surface(b, d, &rec, status);
    if (r == SW_OK && d->loop_count)
        r = fill_loops(b, d, &rec, status);
    uint32_t face = r == SW_OK ? sw_sg_builder_add_face(b, &rec) : SW_SG_NONE;
    if (r == SW_OK &&
        (face == SW_SG_NONE ||
         sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, NULL, NULL) == SW_SG_NONE))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "NURBS surface: out of memory");
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    return sw_sg_builder_finish(b, out, status);
}

static sw_result tspline_from_arrays(const sw_tspline_desc *d, sw_sg_tspline **ts,
                                     sw_status *status)
{
    if (d->point_count < 1 || d->point_count > SW__NODES_MAX_POINTS)
        return sw__fail(status, SW_ERR_LIMIT, "T-spline: %u points (1..%u)", d->point_count,
                        SW__NODES_MAX_POINTS);
    if (!d->points || !d->knots_u || !d->knots_v)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "T-spline: NULL points or knots");
    double *cpw = homogeneous(d->points, d->weights, d->point_count, 3);
    if (!cpw)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "T-spline: out of memory");
    sw_sg_tspline_desc td = {d->point_count,
                             cpw,
                             d->knots_u,
                             d->knots_v,
                             {d->domain[0], d->domain[1], d->domain[2], d->domain[3]}};
    sw_result r = sw_sg_tspline_create(&td, "T-spline", ts, status);
    sw__free(cpw);
    return r;
}

sw_result sw__rt_tspline_geom(const sw_tspline_desc *d, sw_sg_scene **out, sw_status *status)
{
    sw_sg_tspline *ts = NULL;
    sw_result r = d->tsm_path ? sw_sg_tspline_load(d->tsm_path, &ts, status)
                              : tspline_from_arrays(d, &ts, status);
    if (r != SW_OK)
        return r;
    sw_sg_builder *b = sw_sg_builder_create();
    r = b ? sw_sg_tspline_add_to_builder(b, ts, 0, NULL, NULL, NULL, NULL, status)
          : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "T-spline: out of memory");
    sw_sg_tspline_free(ts);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    return sw_sg_builder_finish(b, out, status);
}

static sw_result import_geom(const sw_node_desc *d, sw_sg_scene **out, sw_status *status)
{
    sw_scene_load_desc ld = {d->import_path, NULL, d->import_warning, d->user_data, NULL, 0};
    sw_result r = sw_rt_scene_read(&ld, out, NULL, status);
    if (r == SW_OK)
        r = sw_sg_scene_require(*out, SW_SG_SEC_ALL, status); /* a mapped .sws: verify it now */
    if (r != SW_OK) {
        sw_sg_scene_free(*out);
        *out = NULL;
    }
    return r;
}

/* ---- meshes ---- */

static sw_result check_mesh_desc(const sw_mesh_desc *d, sw_status *status)
{
    const char *fn = "mesh";
    if (d->vertex_count < 3 || d->vertex_count > SW__NODES_MAX_MESH || d->triangle_count < 1 ||
        d->triangle_count > SW__NODES_MAX_MESH)
        return sw__fail(status, SW_ERR_LIMIT, "%s: %u vertices and %u triangles (3..%u and 1..%u)",
                        fn, d->vertex_count, d->triangle_count, SW__NODES_MAX_MESH,
                        SW__NODES_MAX_MESH);
    if (!d->positions || !d->indices)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "%s: NULL positions or indices", fn);
    for (uint32_t i = 0; i < d->vertex_count; i++) {
        const double *p = d->positions + 3 * (size_t)i;
        if (!sw__rt_all_finite(p, 3) || !(fmax(fmax(fabs(p[0]), fabs(p[1])), fabs(p[2])) <=
                                          SW_SG_COORD_MAX)) /* the rule: scenegraph/sw_sg_geom.h */
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: vertex %u: position (%g, %g, %g) is not finite or beyond %g", fn,
                            i, p[0], p[1], p[2], SW_SG_COORD_MAX);
        const double *n = d->normals ? d->normals + 3 * (size_t)i : NULL;
        if (n && (!sw__rt_all_finite(n, 3) || !(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0)))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: vertex %u: normal (%g, %g, %g) is not finite and non-zero", fn, i,
                            n[0], n[1], n[2]);
    }
    const size_t n_idx = 3 * (size_t)d->triangle_count;
    for (size_t k = 0; k < n_idx; k++)
        if (d->indices[k] >= d->vertex_count)
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: index %zu (triangle %zu, corner %zu) is %u, not below the %u "
                            "vertices",
                            fn, k, k / 3, k % 3, d->indices[k], d->vertex_count);
    return SW_OK;
}

/* The normals scaled to unit length, pushed (*at = SW_SG_NO_NORMALS when the mesh has none);
 * 0 when out of memory. */
static int push_unit_normals(sw_sg_builder *b, const sw_mesh_desc *d, uint64_t *at)
{
    *at = SW_SG_NO_NORMALS;
    if (!d->normals)
        return 1;
    const size_t n = 3 * (size_t)d->vertex_count;
    double *unit = sw__malloc(n * sizeof *unit);
    if (!unit)
        return 0;
    for (size_t i = 0; i < n; i += 3) {
        const double *v = d->normals + i;
        const double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int k = 0; k < 3; k++)
            unit[i + k] = v[k] / len;
    }
    *at = sw_sg_builder_push_doubles(b, unit, n);
    sw__free(unit);
    return *at != UINT64_MAX;
}

/* A private scene of one mesh drawn by one MESH node under its root. */
sw_result sw__rt_mesh_geom(const sw_mesh_desc *d, sw_sg_scene **out, sw_status *status)
{
    sw_result r = check_mesh_desc(d, status);
    if (r != SW_OK)
        return r;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh: out of memory");
    sw_sg_mesh_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.n_vertices = d->vertex_count;
    rec.n_triangles = d->triangle_count;
    rec.positions = sw_sg_builder_push_doubles(b, d->positions, 3 * (size_t)d->vertex_count);
    const int normals_ok = push_unit_normals(b, d, &rec.normals);
    rec.indices = sw_sg_builder_push_indices(b, d->indices, 3 * (size_t)d->triangle_count);
    uint32_t mesh = SW_SG_NONE;
    if (rec.positions != UINT64_MAX && normals_ok && rec.indices != UINT64_MAX)
        mesh = sw_sg_builder_add_mesh(b, &rec);
    if (mesh == SW_SG_NONE ||
        sw_sg_builder_add_node(b, SW_SG_NODE_MESH, 0, mesh, NULL, NULL, NULL) == SW_SG_NONE) {
        sw_sg_builder_free(b);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh: out of memory");
    }
    return sw_sg_builder_finish(b, out, status);
}

/* ---- shapes ---- */

/* The largest extent of the loops' control points (their finite ones): the outline's size, which
 * the closing snap is relative to. */
static double loops_size(const sw_trim_loop *loops, uint32_t n)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t l = 0; l < n; l++)
        for (uint32_t c = 0; c < loops[l].curve_count; c++)
            for (uint32_t i = 0; i < loops[l].curves[c].count; i++)
                for (int k = 0; k < 2; k++) {
                    double x = loops[l].curves[c].points[2 * i + k];
                    if (isfinite(x)) {
                        lo[k] = fmin(lo[k], x);
                        hi[k] = fmax(hi[k], x);
                    }
                }
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    return size > 0.0 && isfinite(size) ? size : 0.0;
}

/* A private scene of one outline drawn by one SHAPE node under its root (flags, px_size: as
 * sw_sg_shape_rec's). */
static sw_result shape_scene(const char *fn, const sw_trim_loop *loops, uint32_t n_loops,
                             uint32_t flags, double px_size, sw_sg_scene **out, sw_status *status)
{
    if (n_loops < 1)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: no loops", fn);
    sw_result r = check_loops_desc(fn, loops, n_loops, status);
    if (r != SW_OK)
        return r;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    const double max_gap = 1e-6 * loops_size(loops, n_loops);
    double box[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    sw_sg_shape_rec rec = {SW_SG_NONE, n_loops, flags, 0, {0}, px_size};
    for (uint32_t l = 0; r == SW_OK && l < n_loops; l++) {
        uint32_t li = SW_SG_NONE;
        r = add_loop(b, fn, &loops[l], l, max_gap, box, &li, status);
        if (l == 0)
            rec.first_loop = li;
    }
    uint32_t shape = r == SW_OK ? sw_sg_builder_add_shape(b, &rec) : SW_SG_NONE;
    if (r == SW_OK &&
        (shape == SW_SG_NONE ||
         sw_sg_builder_add_node(b, SW_SG_NODE_SHAPE, 0, shape, NULL, NULL, NULL) == SW_SG_NONE))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    return sw_sg_builder_finish(b, out, status);
}

sw_result sw__rt_shape_geom(const sw_shape_desc *d, sw_sg_scene **out, sw_status *status)
{
    return shape_scene("shape", d->loops, d->loop_count, 0, 0.0, out, status);
}

/* ---- labels ---- */

static sw_result check_label_desc(const sw_label_desc *d, size_t *len, sw_status *status)
{
    if (!d->text)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "label: NULL text");
    *len = strnlen(d->text, SW__NODES_MAX_LABEL + 1);
    if (*len == 0 || *len > SW__NODES_MAX_LABEL)
        return sw__fail(status, *len ? SW_ERR_LIMIT : SW_ERR_INVALID_ARGUMENT,
                        "label: %s text (1..%u bytes)", *len ? "too long a" : "an empty",
                        SW__NODES_MAX_LABEL);
    const double most = d->screen_size ? SW_SG_SHAPE_MAX_PX : 1e15;
    if (!(d->size > 0.0 && d->size <= most))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "label: size %g outside (0, %g]%s",
                        d->size, most, d->screen_size ? " pixels" : "");
    if (d->align < 0 || d->align > 2)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "label: align %d (0 start, 1 middle, 2 end)", (int)d->align);
    return SW_OK;
}

/* The glyph outline's pieces as the loops of a shape: em units times `scale`, shifted by -shift
 * along the baseline. */
static sw_result label_loops(const sw_sg_text_outline *t, double scale, double shift,
                             sw_trim_loop **loops_out, sw_trim_curve **curves_out,
                             double **nums_out, sw_status *status)
{
    static const double k_knots[4][8] = {
        {0}, {0, 0, 1, 1}, {0, 0, 0, 1, 1, 1}, {0, 0, 0, 0, 1, 1, 1, 1}};
    sw_trim_loop *loops = sw__calloc(t->n_contours, sizeof *loops);
    sw_trim_curve *curves = sw__calloc(t->n_pieces, sizeof *curves);
    double *nums = sw__calloc(t->n_pieces, 8 * sizeof *nums);
    if (!loops || !curves || !nums) {
        sw__free(loops);
        sw__free(curves);
        sw__free(nums);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "label: out of memory");
    }
    for (size_t i = 0; i < t->n_pieces; i++) {
        const sw_sg_text_piece *q = &t->pieces[i];
        double *p = nums + 8 * i;
        for (uint32_t k = 0; k <= q->degree; k++) {
            p[2 * k] = scale * (q->p[k][0] - shift);
            p[2 * k + 1] = scale * q->p[k][1];
        }
        curves[i] = (sw_trim_curve){q->degree, q->degree + 1, k_knots[q->degree], p, NULL};
    }
    for (uint32_t k = 0; k < t->n_contours; k++) {
        size_t first = k ? t->contour_end[k - 1] : 0;
        loops[k] = (sw_trim_loop){curves + first, (uint32_t)(t->contour_end[k] - first)};
    }
    *loops_out = loops;
    *curves_out = curves;
    *nums_out = nums;
    return SW_OK;
}

/* A label: its glyphs' outlines (the text module) as a shape, scaled to its size in the world,
 * or in em units drawn `size` pixels per em on screen. */
sw_result sw__rt_label_geom(const sw_label_desc *d, sw_sg_scene **out, sw_status *status)
{
    size_t len = 0;
    sw_result r = check_label_desc(d, &len, status);
    if (r != SW_OK)
        return r;
    sw_sg_text_outline t;
    r = sw_sg_text_outline_make(d->font_path, d->text, len, &t, status);
    if (r != SW_OK)
        return r;
    if (t.n_contours == 0) {
        sw_sg_text_outline_free(&t);
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "label: \"%.40s\" has no glyph outline to draw (spaces only?)", d->text);
    }
    sw_trim_loop *loops = NULL;
    sw_trim_curve *curves = NULL;
    double *nums = NULL;
    r = label_loops(&t, d->screen_size ? 1.0 : d->size, 0.5 * d->align * t.advance, &loops, &curves,
                    &nums, status);
    if (r == SW_OK)
        r = shape_scene("label", loops, t.n_contours, d->screen_size ? SW_SG_SHAPE_SCREEN : 0u,
                        d->screen_size ? d->size : 0.0, out, status);
    sw__free(loops);
    sw__free(curves);
    sw__free(nums);
    sw_sg_text_outline_free(&t);
    return r;
}

/* Triangles of a geometry scene's meshes (each once). */
uint32_t sw__rt_geom_triangles(const sw_sg_scene *geom)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(geom);
    uint64_t n = 0;
    for (uint32_t i = 0; i < v->n_meshes; i++)
        n += v->meshes[i].n_triangles;
    return n > UINT32_MAX ? UINT32_MAX : (uint32_t)n;
}

sw_result sw__rt_make_geom(const sw_node_desc *d, sw_sg_scene **out, sw_status *status)
{
    *out = NULL;
    switch (d->kind) {
    case SW_NODE_NURBS:
        if (!d->nurbs)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: NURBS without nurbs");
        return sw__rt_nurbs_geom(d->nurbs, out, status);
    case SW_NODE_TSPLINE:
        if (!d->tspline)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "sw_node_add: TSPLINE without tspline");
        return sw__rt_tspline_geom(d->tspline, out, status);
    case SW_NODE_IMPORT:
        if (!d->import_path)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "sw_node_add: IMPORT without import_path");
        return import_geom(d, out, status);
    case SW_NODE_MESH:
        if (!d->mesh)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: MESH without mesh");
        return sw__rt_mesh_geom(d->mesh, out, status);
    case SW_NODE_SHAPE:
        if (!d->shape)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: SHAPE without shape");
        return sw__rt_shape_geom(d->shape, out, status);
    case SW_NODE_LABEL:
        if (!d->label)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: LABEL without label");
        return sw__rt_label_geom(d->label, out, status);
    default:
        return SW_OK;
    }
}

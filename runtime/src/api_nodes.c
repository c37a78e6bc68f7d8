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

#define SW__NODES_MAX_POINTS (1u << 20)
#define SW__NODES_MAX_LOOPS 65536u
#define SW__NODES_MAX_LABEL 1024u     /* bytes of a label's text */
#define SW__NODES_MAX_MESH (1u << 24) /* vertices, and triangles, of one mesh */

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

static int all_finite(const double *v, size_t n)
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
    if (!all_finite(in, 12) || !(fabs(det) > 1e-300))
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

static sw_result tspline_geom(const sw_tspline_desc *d, sw_sg_scene **out, sw_status *status)
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
        if (!all_finite(p, 3) || !(fmax(fmax(fabs(p[0]), fabs(p[1])), fabs(p[2])) <=
                                   SW_SG_COORD_MAX)) /* the rule: scenegraph/sw_sg_geom.h */
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s: vertex %u: position (%g, %g, %g) is not finite or beyond %g", fn,
                            i, p[0], p[1], p[2], SW_SG_COORD_MAX);
        const double *n = d->normals ? d->normals + 3 * (size_t)i : NULL;
        if (n && (!all_finite(n, 3) || !(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0)))
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
static sw_result mesh_geom(const sw_mesh_desc *d, sw_sg_scene **out, sw_status *status)
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

static sw_result shape_geom(const sw_shape_desc *d, sw_sg_scene **out, sw_status *status)
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
static sw_result label_geom(const sw_label_desc *d, sw_sg_scene **out, sw_status *status)
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
static uint32_t geom_triangles(const sw_sg_scene *geom)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(geom);
    uint64_t n = 0;
    for (uint32_t i = 0; i < v->n_meshes; i++)
        n += v->meshes[i].n_triangles;
    return n > UINT32_MAX ? UINT32_MAX : (uint32_t)n;
}

static sw_result make_geom(const sw_node_desc *d, sw_sg_scene **out, sw_status *status)
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
        return tspline_geom(d->tspline, out, status);
    case SW_NODE_IMPORT:
        if (!d->import_path)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "sw_node_add: IMPORT without import_path");
        return import_geom(d, out, status);
    case SW_NODE_MESH:
        if (!d->mesh)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: MESH without mesh");
        return mesh_geom(d->mesh, out, status);
    case SW_NODE_SHAPE:
        if (!d->shape)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: SHAPE without shape");
        return shape_geom(d->shape, out, status);
    case SW_NODE_LABEL:
        if (!d->label)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "sw_node_add: LABEL without label");
        return label_geom(d->label, out, status);
    default:
        return SW_OK;
    }
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
        r = make_geom(d, &n->geom, status);
    if (r != SW_OK) {
        free_node(n);
        return r;
    }
    if (n->geom) {
        n->geom_faces = sw_sg_scene_view_ptr(n->geom)->n_faces;
        n->geom_triangles = geom_triangles(n->geom);
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
    n->geom_triangles = geom_triangles(n->geom);
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
    return set_geometry(scene, node, &swap, tspline_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_mesh(sw_scene scene, sw_node node, const sw_mesh_desc *desc,
                           sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_mesh: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_MESH, "sw_node_set_mesh"};
    return set_geometry(scene, node, &swap, mesh_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_label(sw_scene scene, sw_node node, const sw_label_desc *desc,
                            sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_label: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_LABEL, "sw_node_set_label"};
    return set_geometry(scene, node, &swap, label_geom(desc, &swap.geom, status), status);
}

sw_result sw_node_set_shape(sw_scene scene, sw_node node, const sw_shape_desc *desc,
                            sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_node_set_shape: NULL desc");
    geometry_swap swap = {NULL, SW_NODE_SHAPE, "sw_node_set_shape"};
    return set_geometry(scene, node, &swap, shape_geom(desc, &swap.geom, status), status);
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

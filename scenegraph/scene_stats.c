/* SPDX-License-Identifier: MIT */
/* Scene statistics for `splinewalk info`: counts by surface kind, trims, Bézier patches after
 * extraction (Guthe et al. 2005 §3 starts from those patches), degrees, instances, face
 * occurrences after instance expansion, and the world bounding box of the surfaces. */
#include "sw_sg_scene_internal.h"
#include "sw_hooks.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#define SW__STATS_GRID 17 /* samples per direction of each face's trim box */

typedef struct stats_ctx {
    const sw_sg_scene *scene;
    sw_sg_scene_stats *out;
    double *face_boxes; /* per face: local box of its samples (min xyz, max xyz), or NULL */
} stats_ctx;

static void box_add(double box[6], const double p[3])
{
    for (int r = 0; r < 3; r++) {
        if (p[r] < box[r])
            box[r] = p[r];
        if (p[r] > box[3 + r])
            box[3 + r] = p[r];
    }
}

/* Whether the surface is one bilinear piece: degree 1 x 1, one span each way, equal weights. On
 * any rectangle of its domain each coordinate is then bilinear in (u, v), so every sample of the
 * grid below is a convex combination of the four corner samples, and the corners alone give the
 * box. Most faces of generated buildings are such planes: sampling them on the full grid was most
 * of the time a 10^6-surface building took before its first frame (sw_scene_get_info's stats are
 * computed on a scene's first use). */
static int is_bilinear(const sw_sg_surface *s)
{
    if (s->deg_u != 1 || s->deg_v != 1 || s->n_u != 2 || s->n_v != 2)
        return 0;
    const double w = s->cpw[3];
    return s->cpw[7] == w && s->cpw[11] == w && s->cpw[15] == w;
}

/* The box of the face sampled on a grid over its trim box (uv_box), not of its control net: a
 * converted cylinder's net can reach far beyond the trimmed face (linkrods.step's box grew 7x),
 * which made camera presets frame a speck. A sampled box may miss a bulge between samples by a
 * little; the presets' 10 % margin covers that, and culling uses its own rigorous boxes. */
static void face_sample_box(const sw_sg_scene *scene, uint32_t face, double box[6])
{
    const sw_sg_face_rec *f = &scene->view.faces[face];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, face, &s);
    for (int r = 0; r < 3; r++) {
        box[r] = DBL_MAX;
        box[3 + r] = -DBL_MAX;
    }
    /* the grid's corners only, for a bilinear face: the same box (see is_bilinear) */
    const int step = is_bilinear(&s) ? SW__STATS_GRID - 1 : 1;
    for (int j = 0; j < SW__STATS_GRID; j += step) {
        double v = f->uv_box[2] + (f->uv_box[3] - f->uv_box[2]) * j / (SW__STATS_GRID - 1);
        for (int i = 0; i < SW__STATS_GRID; i += step) {
            double u = f->uv_box[0] + (f->uv_box[1] - f->uv_box[0]) * i / (SW__STATS_GRID - 1);
            double p[3];
            sw_sg_surface_eval(&s, u, v, p);
            box_add(box, p);
        }
    }
}

/* Grows the world box by the face's local box, its eight corners placed in the world. */
static int stats_visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)color;
    stats_ctx *c = ctx;
    const double *local = c->face_boxes + (size_t)face * 6;
    for (int k = 0; k < 8; k++) {
        double q[3] = {local[(k & 1) ? 3 : 0], local[(k & 2) ? 4 : 1], local[(k & 4) ? 5 : 2]};
        double p[3];
        for (int r = 0; r < 3; r++) {
            const double *m = world + 4 * r;
            p[r] = m[0] * q[0] + m[1] * q[1] + m[2] * q[2] + m[3];
        }
        box_add(c->out->bbox, p);
    }
    c->out->face_occurrences++;
    return 0;
}

/* Grows the world box by the mesh's box corners placed in the world (an affine map's image of a
 * box lies in the box of its corners' images). */
static int stats_visit_mesh(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                            const float color[4])
{
    (void)node;
    (void)color;
    stats_ctx *c = ctx;
    const sw_sg_mesh_rec *m = &c->scene->view.meshes[mesh];
    for (int k = 0; k < 8; k++) {
        double q[3] = {m->box[(k & 1) ? 3 : 0], m->box[(k & 2) ? 4 : 1], m->box[(k & 4) ? 5 : 2]};
        double p[3];
        for (int r = 0; r < 3; r++) {
            const double *w = world + 4 * r;
            p[r] = w[0] * q[0] + w[1] * q[1] + w[2] * q[2] + w[3];
        }
        box_add(c->out->bbox, p);
    }
    c->out->mesh_occurrences++;
    c->out->triangle_occurrences += m->n_triangles;
    return 0;
}

/* Grows the world box by the shape's plane box corners (z = 0) placed in the world. */
static int stats_visit_shape(void *ctx, uint32_t shape, uint32_t node, const double world[12],
                             const float color[4])
{
    (void)node;
    (void)color;
    stats_ctx *c = ctx;
    const sw_sg_shape_rec *sh = &c->scene->view.shapes[shape];
    const int screen = (sh->flags & SW_SG_SHAPE_SCREEN) != 0; /* a label on screen: its anchor */
    for (int k = 0; k < 4; k++) {
        double q[2] = {screen ? 0.0 : sh->box[(k & 1) ? 2 : 0],
                       screen ? 0.0 : sh->box[(k & 2) ? 3 : 1]},
               p[3];
        for (int r = 0; r < 3; r++) {
            const double *w = world + 4 * r;
            p[r] = w[0] * q[0] + w[1] * q[1] + w[3];
        }
        box_add(c->out->bbox, p);
    }
    c->out->shape_occurrences++;
    return 0;
}

static void face_stats(const sw_sg_scene_view *v, sw_sg_scene_stats *out)
{
    for (uint32_t i = 0; i < v->n_faces; i++) {
        const sw_sg_face_rec *f = &v->faces[i];
        out->faces_by_kind[f->kind < SW_SG_KIND_COUNT ? f->kind : SW_SG_KIND_OTHER]++;
        if (f->flags & SW_SG_FACE_TRIMMED)
            out->trimmed_faces++;
        if (f->deg_u > out->max_deg_u)
            out->max_deg_u = f->deg_u;
        if (f->deg_v > out->max_deg_v)
            out->max_deg_v = f->deg_v;
        out->control_points += (uint64_t)f->n_u * f->n_v;
        int32_t su =
            sw_sg_knots_segment_count(v->pool + f->knots_u, (int32_t)f->deg_u, (int32_t)f->n_u);
        int32_t sv =
            sw_sg_knots_segment_count(v->pool + f->knots_v, (int32_t)f->deg_v, (int32_t)f->n_v);
        out->bezier_patches += (uint64_t)su * (uint64_t)sv;
    }
}

sw_result sw_sg_scene_compute_stats(const sw_sg_scene *scene, sw_sg_scene_stats *out)
{
    const sw_sg_scene_view *v = &scene->view;
    memset(out, 0, sizeof *out);
    out->faces = v->n_faces;
    out->loops = v->n_loops;
    out->curves = v->n_curves;
    out->nodes = v->n_nodes;
    out->adjacency = v->n_adjacency;
    face_stats(v, out);
    for (uint32_t i = 0; i < v->n_curves; i++)
        if (v->curves[i].degree > out->max_curve_degree)
            out->max_curve_degree = v->curves[i].degree;
    for (uint32_t i = 0; i < v->n_nodes; i++)
        if (v->nodes[i].kind == SW_SG_NODE_INSTANCE)
            out->instances++;
    for (int r = 0; r < 3; r++) {
        out->bbox[r] = DBL_MAX;
        out->bbox[3 + r] = -DBL_MAX;
    }
    stats_ctx c = {scene, out, sw__malloc(((size_t)v->n_faces + 1) * 6 * sizeof(double))};
    if (!c.face_boxes)
        return SW_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < v->n_faces; i++)
        face_sample_box(scene, i, c.face_boxes + (size_t)i * 6);
    sw_result r = sw_sg_scene_traverse(scene, stats_visit, &c);
    sw__free(c.face_boxes);
    out->meshes = v->n_meshes;
    for (uint32_t i = 0; i < v->n_meshes; i++)
        out->mesh_triangles += v->meshes[i].n_triangles;
    if (r == SW_OK && v->n_meshes)
        r = sw_sg_scene_traverse_meshes(scene, stats_visit_mesh, &c);
    out->shapes = v->n_shapes;
    if (r == SW_OK && v->n_shapes)
        r = sw_sg_scene_traverse_shapes(scene, stats_visit_shape, &c);
    if (out->face_occurrences == 0 && out->mesh_occurrences == 0 && out->shape_occurrences == 0)
        memset(out->bbox, 0, sizeof out->bbox); /* nothing drawn: an empty box at the origin */
    out->memory_bytes = sw_sg_scene_memory(scene);
    return r;
}

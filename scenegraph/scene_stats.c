/* Scene statistics for `splinewalk info`: counts by surface kind, trims, Bézier patches after
 * extraction (Guthe et al. 2005 §3 starts from those patches), degrees, instances, face
 * occurrences after instance expansion, and the world bounding box of the control nets. */
#include "sw_sg_scene_internal.h"

#include <float.h>
#include <string.h>

typedef struct stats_ctx {
    const sw_sg_scene *scene;
    sw_sg_scene_stats *out;
} stats_ctx;

/* Grows the box by every control point of the face (projected by its weight) placed in the
 * world: the convex hull property makes this a bound of the surface. */
static int stats_visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)color;
    stats_ctx *c = ctx;
    const sw_sg_scene_view *v = &c->scene->view;
    const sw_sg_face_rec *f = &v->faces[face];
    const double *cp = v->pool + f->cpw;
    uint64_t n = (uint64_t)f->n_u * f->n_v;
    double *box = c->out->bbox;
    for (uint64_t i = 0; i < n; i++, cp += 4) {
        double x = cp[0] / cp[3], y = cp[1] / cp[3], z = cp[2] / cp[3];
        for (int r = 0; r < 3; r++) {
            const double *m = world + 4 * r;
            double w = m[0] * x + m[1] * y + m[2] * z + m[3];
            if (w < box[r])
                box[r] = w;
            if (w > box[3 + r])
                box[3 + r] = w;
        }
    }
    c->out->face_occurrences++;
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
    stats_ctx c = {scene, out};
    sw_result r = sw_sg_scene_traverse(scene, stats_visit, &c);
    if (out->face_occurrences == 0)
        memset(out->bbox, 0, sizeof out->bbox); /* nothing drawn: an empty box at the origin */
    out->memory_bytes = sw_sg_scene_memory(scene);
    return r;
}

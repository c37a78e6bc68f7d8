/* SPDX-License-Identifier: MIT */
/* bench/degrees: the scene drawn for one frame — see source_scene.h. */
#include "source_scene.h"
#include "sw_lod_sampling.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const float k_color[4] = {0.8f, 0.8f, 0.8f, 1.0f};
static const double k_cubic_knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};

static uint32_t add_cubic_loop(sw_sg_builder *b, const sw_lod_cubic_set *set)
{
    const uint64_t knots = sw_sg_builder_push_doubles(b, k_cubic_knots, 8);
    uint32_t first = SW_SG_NONE;
    for (int32_t i = 0; i < set->count; ++i) {
        sw_sg_curve_rec c = {3, 4, knots, sw_sg_builder_push_doubles(b, set->pieces[i].cpw, 12)};
        const uint32_t id = sw_sg_builder_add_curve(b, &c);
        first = i == 0 ? id : first;
    }
    sw_sg_loop_rec l = {first, (uint32_t)set->count, SW_SG_LOOP_OUTER, 0};
    return sw_sg_builder_add_loop(b, &l);
}

sw_result bd_source_scene(const sw_sg_surface *s, const sw_lod_cubic_set *loop,
                          const double uv_box[4], sw_sg_scene **out, sw_status *status)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "source scene: out of memory");
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = (uint32_t)s->deg_u;
    f.deg_v = (uint32_t)s->deg_v;
    f.n_u = (uint32_t)s->n_u;
    f.n_v = (uint32_t)s->n_v;
    f.knots_u = sw_sg_builder_push_doubles(b, s->knots_u, (size_t)(s->n_u + s->deg_u + 1));
    f.knots_v = sw_sg_builder_push_doubles(b, s->knots_v, (size_t)(s->n_v + s->deg_v + 1));
    f.cpw = sw_sg_builder_push_doubles(b, s->cpw, (size_t)s->n_u * (size_t)s->n_v * 4);
    f.kind = SW_SG_KIND_BSPLINE;
    f.flags = SW_SG_FACE_TRIMMED;
    f.first_loop = add_cubic_loop(b, loop);
    f.n_loops = 1;
    memcpy(f.uv_box, uv_box, sizeof f.uv_box);
    f.tolerance = 1e-7;
    const uint32_t face = sw_sg_builder_add_face(b, &f);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, k_color, "surface");
    return sw_sg_builder_finish(b, out, status);
}

double bd_parametric_speed(const sw_sg_surface *s, const double uv_box[4])
{
    sw_sg_bezier_set set;
    sw_status st = {0};
    if (sw_sg_surface_extract_bezier_in(s, uv_box[0], uv_box[1], uv_box[2], uv_box[3], &set, &st) !=
        SW_OK)
        return 0.0;
    double gu = 0.0, gv = 0.0;
    for (int32_t i = 0; i < set.n_u * set.n_v; ++i) {
        const sw_sg_bezier_patch *p = &set.patches[i];
        sw_lod_patch_bounds pb;
        sw_lod_rational_bezier_bounds(p->deg_u, p->deg_v, p->cpw, &pb);
        gu = fmax(gu, pb.d1[0] / (p->u1 - p->u0)); /* local derivative over the patch's span */
        gv = fmax(gv, pb.d1[1] / (p->v1 - p->v0));
    }
    sw_sg_bezier_set_free(&set);
    return sqrt(gu * gu + gv * gv);
}

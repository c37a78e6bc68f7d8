/* SPDX-License-Identifier: MIT */
/* The planar faces of a scene as occluders (occlusion.h): each face that is a plane
 * (sw_sg_surface_affine) gets its outline once per scene, in object space: its trim loops
 * flattened at a thousandth of its parameter box and mapped by the plane, or its parameter box when
 * it is untrimmed. Curved faces are not occluders (what they hide is still culled by planes), nor
 * are outlines of more than MAX_POINTS points or loops flattened at their floor (their distance
 * from the exact loop is not known). */
#include "occlusion.h"
#include "sw_hooks.h"
#include "sw_sg_geom.h"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_POINTS = 4096 };
static const double k_flatten = 1e-3; /* of the parameter box's larger side */

typedef struct builder {
    sw_gpu_occluders *oc;
    size_t cap_first, cap_count, cap_points;
} builder;

static int push_point(builder *b, const double o[3], const double du[3], const double dv[3],
                      double u, double v)
{
    sw_gpu_occluders *oc = b->oc;
    if (!sw__grow((void **)&oc->points, &b->cap_points, 3 * (oc->n_points + 1), sizeof *oc->points))
        return 0;
    double *p = oc->points + 3 * oc->n_points++;
    for (int k = 0; k < 3; ++k)
        p[k] = o[k] + u * du[k] + v * dv[k];
    return 1;
}

static int push_loop(builder *b, uint32_t first, uint32_t count)
{
    sw_gpu_occluders *oc = b->oc;
    if (!sw__grow((void **)&oc->loop_first, &b->cap_first, oc->n_loops + 1,
                  sizeof *oc->loop_first) ||
        !sw__grow((void **)&oc->loop_count, &b->cap_count, oc->n_loops + 1, sizeof *oc->loop_count))
        return 0;
    oc->loop_first[oc->n_loops] = first;
    oc->loop_count[oc->n_loops++] = count;
    return 1;
}

/* The face's trim loops flattened within tol in (u, v): 1, or 0 when they cannot serve (too many
 * points, a loop flattened at its floor: its distance from the curve is not known), -1 when out
 * of memory. loops[] is filled as far as it got (the caller frees it). */
static int flatten_loops(const sw_sg_scene *scene, const sw_sg_face_rec *rec, sw_sg_polyline *loops,
                         double tol)
{
    size_t total = 0;
    for (uint32_t k = 0; k < rec->n_loops; ++k) {
        sw_status st = {0};
        sw_result r =
            sw_sg_trim_flatten_loop(scene, rec->first_loop + k, tol, MAX_POINTS, &loops[k], &st);
        if (r == SW_ERR_OUT_OF_MEMORY)
            return -1;
        if (r != SW_OK || loops[k].below_floor || loops[k].depth_capped)
            return 0;
        total += loops[k].count;
        if (total > MAX_POINTS)
            return 0;
    }
    return 1;
}

/* Face f's outline into the set when it is a plane; -1 when out of memory. */
static int add_face(builder *b, const sw_sg_scene *scene, uint32_t f)
{
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(scene)->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, f, &s);
    double o[3], du[3], dv[3];
    if (!sw_sg_surface_affine(&s, o, du, dv))
        return 0;
    const double *box = rec->uv_box;
    const double tol = k_flatten * fmax(box[1] - box[0], box[3] - box[2]);
    const double stretch = sqrt(du[0] * du[0] + du[1] * du[1] + du[2] * du[2]) +
                           sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
    if (!(tol > 0.0) || !isfinite(stretch))
        return 0;
    sw_gpu_occluders *oc = b->oc;
    sw__occ_face *of = &oc->faces[f];
    const size_t loops0 = oc->n_loops, points0 = oc->n_points;
    int ok = 1;
    if (!(rec->flags & SW_SG_FACE_TRIMMED) || rec->n_loops == 0) {
        const double c[4][2] = {
            {box[0], box[2]}, {box[1], box[2]}, {box[1], box[3]}, {box[0], box[3]}};
        for (int i = 0; i < 4 && ok; ++i)
            ok = push_point(b, o, du, dv, c[i][0], c[i][1]);
        ok = ok && push_loop(b, (uint32_t)points0, 4);
        of->err = 0.0;
    } else {
        sw_sg_polyline *loops = sw__calloc(rec->n_loops, sizeof *loops);
        if (!loops)
            return -1;
        int got = flatten_loops(scene, rec, loops, tol);
        for (uint32_t k = 0; got == 1 && ok && k < rec->n_loops; ++k) {
            const uint32_t first = (uint32_t)oc->n_points;
            for (uint32_t i = 0; i < loops[k].count && ok; ++i)
                ok = push_point(b, o, du, dv, loops[k].uv[2 * i], loops[k].uv[2 * i + 1]);
            ok = ok && push_loop(b, first, loops[k].count);
        }
        for (uint32_t k = 0; k < rec->n_loops; ++k)
            sw_sg_polyline_free(&loops[k]);
        sw__free(loops);
        if (got <= 0) {
            oc->n_loops = loops0;
            oc->n_points = points0;
            return got;
        }
        of->err = tol * stretch;
    }
    if (!ok)
        return -1;
    of->first_loop = (uint32_t)loops0;
    of->n_loops = (uint32_t)(oc->n_loops - loops0);
    oc->n_occluders++;
    return 1;
}

sw_result sw_gpu_occluders_build(const sw_sg_scene *scene, sw_gpu_occluders **out,
                                 sw_status *status)
{
    *out = NULL;
    const sw_sg_scene_view *sv = sw_sg_scene_view_ptr(scene);
    builder b = {sw__calloc(1, sizeof *b.oc), 0, 0, 0};
    if (b.oc)
        b.oc->faces = sw__calloc(sv->n_faces ? sv->n_faces : 1, sizeof *b.oc->faces);
    if (!b.oc || !b.oc->faces) {
        sw_gpu_occluders_free(b.oc);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "occluders: out of memory");
    }
    b.oc->n_faces = sv->n_faces;
    b.oc->scene_serial = sw_sg_scene_serial(scene);
    for (uint32_t f = 0; f < sv->n_faces; ++f)
        if (add_face(&b, scene, f) < 0) {
            sw_gpu_occluders_free(b.oc);
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "occluders: out of memory");
        }
    *out = b.oc;
    return SW_OK;
}

void sw_gpu_occluders_free(sw_gpu_occluders *oc)
{
    if (!oc)
        return;
    sw__free(oc->faces);
    sw__free(oc->loop_first);
    sw__free(oc->loop_count);
    sw__free(oc->points);
    sw__free(oc);
}

size_t sw_gpu_occluders_memory(const sw_gpu_occluders *oc)
{
    if (!oc)
        return 0;
    return sizeof *oc + oc->n_faces * sizeof *oc->faces +
           oc->n_loops * (sizeof *oc->loop_first + sizeof *oc->loop_count) +
           3 * oc->n_points * sizeof *oc->points;
}

uint32_t sw_gpu_occluders_count(const sw_gpu_occluders *oc)
{
    return oc ? oc->n_occluders : 0;
}

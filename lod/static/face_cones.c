/* SPDX-License-Identifier: MIT */
/* Per-face outward normal cones and the back-patch test (Kumar et al. 1997 §4.4); see
 * sw_lod_face_cones.h. */
#include "sw_lod_face_cones.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Margin of the back-facing test against rounding of the axes and angles (radians): a face just
 * short of edge-on stays drawn. */
static const double k_margin = 1e-6;

static void full_cone(sw_lod_cone *c)
{
    c->axis[0] = 0.0, c->axis[1] = 0.0, c->axis[2] = 1.0;
    sw_lod_cone_set_angle(c, M_PI);
}

/* The enclosing cone of one face's patch cones (outward). */
static sw_result face_cone(const sw_sg_scene *scene, uint32_t face, double **scratch, size_t *cap,
                           sw_lod_cone **pc, size_t *cap_pc, sw_lod_cone *out, sw_status *status)
{
    sw_sg_bezier_set set;
    sw_result r = sw_lod_face_patches(scene, face, &set, status);
    if (r != SW_OK)
        return r;
    const size_t np = (size_t)set.n_u * (size_t)set.n_v;
    if (np > *cap_pc) {
        sw_lod_cone *g = sw__realloc(*pc, np * sizeof *g);
        if (!g) {
            sw_sg_bezier_set_free(&set);
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face cones: out of memory");
        }
        *pc = g, *cap_pc = np;
    }
    const int reversed =
        (sw_sg_scene_view_ptr(scene)->faces[face].flags & SW_SG_FACE_REVERSED) != 0;
    for (size_t p = 0; p < np; ++p) {
        const sw_sg_bezier_patch *bp = &set.patches[p];
        const size_t need = sw_lod_gauss_scratch_bound(bp->deg_u, bp->deg_v);
        if (bp->deg_u <= SW_LOD_GAUSS_MAX_DEGREE && bp->deg_v <= SW_LOD_GAUSS_MAX_DEGREE &&
            need > *cap) {
            double *g = sw__realloc(*scratch, need * sizeof *g);
            if (!g) {
                sw_sg_bezier_set_free(&set);
                return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face cones: out of memory");
            }
            *scratch = g, *cap = need;
        }
        sw_lod_cone *c = &(*pc)[p];
        sw_lod_gauss_cone(bp->deg_u, bp->deg_v, bp->cpw, *scratch, c);
        if (reversed)
            for (int a = 0; a < 3; ++a)
                c->axis[a] = -c->axis[a];
    }
    sw_lod_cone_enclose(*pc, np, out);
    sw_sg_bezier_set_free(&set);
    return SW_OK;
}

sw_result sw_lod_face_cones_build(const sw_sg_scene *scene, sw_lod_face_cones **out,
                                  sw_status *status)
{
    *out = NULL;
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    sw_lod_face_cones *fc = sw__calloc(1, sizeof *fc);
    if (fc)
        fc->cones = sw__malloc((v->n_faces ? v->n_faces : 1) * sizeof *fc->cones);
    if (!fc || !fc->cones) {
        sw_lod_face_cones_free(fc);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face cones: out of memory");
    }
    fc->n_faces = v->n_faces;
    double *scratch = NULL;
    sw_lod_cone *pc = NULL;
    size_t cap = 0, cap_pc = 0;
    sw_result r = SW_OK;
    for (uint32_t i = 0; i < v->n_faces && r == SW_OK; ++i) {
        full_cone(&fc->cones[i]);
        if (!(v->faces[i].flags & SW_SG_FACE_CLOSED_SHELL))
            continue;
        r = face_cone(scene, i, &scratch, &cap, &pc, &cap_pc, &fc->cones[i], status);
        fc->n_bounded += r == SW_OK && fc->cones[i].half_angle < M_PI;
    }
    sw__free(scratch);
    sw__free(pc);
    if (r != SW_OK) {
        sw_lod_face_cones_free(fc);
        return r;
    }
    *out = fc;
    return SW_OK;
}

void sw_lod_face_cones_free(sw_lod_face_cones *fc)
{
    if (!fc)
        return;
    sw__free(fc->cones);
    sw__free(fc);
}

int sw_lod_cone_to_world(const sw_lod_cone *c, const double m[12], sw_lod_cone *out)
{
    full_cone(out);
    if (!(c->half_angle < M_PI))
        return 0;
    /* A similarity: its columns orthogonal and of one length (to a tolerance far below what the
     * margin absorbs). */
    double col[3][3], len2[3];
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i)
            col[j][i] = m[4 * i + j];
        len2[j] = col[j][0] * col[j][0] + col[j][1] * col[j][1] + col[j][2] * col[j][2];
    }
    const double s2 = len2[0], tol = 1e-9 * s2;
    if (!(s2 > 0.0) || !isfinite(s2) || fabs(len2[1] - s2) > tol || fabs(len2[2] - s2) > tol)
        return 0;
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3;
        if (fabs(col[a][0] * col[b][0] + col[a][1] * col[b][1] + col[a][2] * col[b][2]) > tol)
            return 0;
    }
    double w[3], n = 0.0;
    for (int i = 0; i < 3; ++i) {
        w[i] = m[4 * i] * c->axis[0] + m[4 * i + 1] * c->axis[1] + m[4 * i + 2] * c->axis[2];
        n += w[i] * w[i];
    }
    n = sqrt(n);
    if (!(n > 0.0))
        return 0;
    for (int i = 0; i < 3; ++i)
        out->axis[i] = w[i] / n;
    sw_lod_cone_set_angle(out, c->half_angle);
    return 1;
}

int sw_lod_cone_back_facing(const sw_lod_cone *c, const double box[6])
{
    if (!(c->half_angle < 0.5 * M_PI))
        return 0;
    double ctr[3], r2 = 0.0, d2 = 0.0, dot = 0.0;
    for (int k = 0; k < 3; ++k) {
        ctr[k] = 0.5 * (box[k] + box[3 + k]);
        const double h = 0.5 * (box[3 + k] - box[k]);
        r2 += h * h;
        d2 += ctr[k] * ctr[k];
        dot += ctr[k] * c->axis[k];
    }
    if (!(d2 > r2) || !isfinite(d2))
        return 0; /* the eye may be inside: every direction is a view direction */
    const double d = sqrt(d2), phi = asin(fmin(1.0, sqrt(r2) / d));
    const double g = acos(fmax(-1.0, fmin(1.0, dot / d)));
    return g + c->half_angle + phi < 0.5 * M_PI - k_margin;
}

/* SPDX-License-Identifier: MIT */
/* The tessellate stage's triangle path: the scene's mesh occurrences (sw_nodes.h MESH nodes, the
 * .sws MESHES section) and the static LODs' levels (stage_tessellate_static.c) go through one
 * function, sw__fr_append_triangles, into the frame's triangle mesh, drawn like the CPU grids of
 * the per-frame path: depth-tested against the surfaces, coloured and lit by the same shader, in
 * walkthrough and converged frames alike (the work is plain memory made while the frame is
 * prepared, so split frames carry it in their plan). A mesh is drawn as given: no screen-space
 * error bound applies to it (the cull stage dropped the occurrences outside the frustum). */
#include "frame_stages.h"
#include "sw_status_util.h"

#include <math.h>
#include <string.h>

/* Eye-relative position of object point p under m (the float the GPU gets). */
static void eye_position(const sw__fr_tess *f, const double m[12], const double *p, double out[3])
{
    for (int a = 0; a < 3; ++a)
        out[a] = m[4 * a] * p[0] + m[4 * a + 1] * p[1] + m[4 * a + 2] * p[2] +
                 (m[4 * a + 3] - f->env->view.eye[a]);
}

/* Each triangle with its own three vertices and its world normal: flat shading. */
static void append_flat(sw__fr_tess *f, const double m[12], const sw__fr_triangles *t)
{
    const size_t base = f->geo->mesh.n_v;
    for (uint32_t k = 0; k < t->n_triangles; ++k) {
        double w[3][3];
        for (int c = 0; c < 3; ++c)
            eye_position(f, m, t->positions + 3 * (size_t)t->triangles[3 * (size_t)k + c], w[c]);
        const double e1[3] = {w[1][0] - w[0][0], w[1][1] - w[0][1], w[1][2] - w[0][2]};
        const double e2[3] = {w[2][0] - w[0][0], w[2][1] - w[0][1], w[2][2] - w[0][2]};
        const float n[3] = {(float)(e1[1] * e2[2] - e1[2] * e2[1]),
                            (float)(e1[2] * e2[0] - e1[0] * e2[2]),
                            (float)(e1[0] * e2[1] - e1[1] * e2[0])};
        for (int c = 0; c < 3; ++c) {
            sw__gpu_vertex *v = &f->geo->mesh.v[f->geo->mesh.n_v++];
            for (int a = 0; a < 3; ++a) {
                v->pos[a] = (float)w[c][a];
                v->nrm[a] = n[a];
            }
            v->st[0] = v->st[1] = 0.0f;
        }
    }
    for (size_t k = 0; k < 3 * (size_t)t->n_triangles; ++k)
        f->geo->mesh.idx[f->geo->mesh.n_idx++] = (uint32_t)(base + k);
}

sw_result sw__fr_append_triangles(sw__fr_tess *f, const occurrence *o, const sw__fr_triangles *t,
                                  sw_status *status)
{
    const int flat = !t->normals_f && !t->normals_d;
    const size_t n_idx = 3 * (size_t)t->n_triangles;
    sw_result r = sw__gpu_mesh_reserve(&f->geo->mesh, flat ? n_idx : t->n_vertices, n_idx, status);
    if (r != SW_OK)
        return r;
    const size_t base = f->geo->mesh.n_v, first = f->geo->mesh.n_idx;
    const double *m = o->world;
    if (flat) {
        append_flat(f, m, t);
    } else {
        for (uint32_t i = 0; i < t->n_vertices; ++i) {
            double p[3], n[3];
            eye_position(f, m, t->positions + 3 * (size_t)i, p);
            for (int a = 0; a < 3; ++a)
                n[a] = t->normals_f ? (double)t->normals_f[3 * (size_t)i + a]
                                    : t->normals_d[3 * (size_t)i + a];
            sw__gpu_vertex *v = &f->geo->mesh.v[f->geo->mesh.n_v++];
            for (int a = 0; a < 3; ++a) {
                v->pos[a] = (float)p[a];
                const double *row = t->normal_matrix + 3 * a;
                v->nrm[a] = (float)(row[0] * n[0] + row[1] * n[1] + row[2] * n[2]);
            }
            v->st[0] = v->st[1] = 0.0f;
        }
        for (size_t k = 0; k < n_idx; ++k)
            f->geo->mesh.idx[f->geo->mesh.n_idx++] = (uint32_t)base + t->triangles[k];
    }
    const trim_need none = {0.0, 0.0};
    const double cell[2] = {0.0, 0.0};
    r = sw__fr_add_draw(f, o, first, 0, &none, cell, status);
    if (r == SW_OK) /* no surface parameters: host shading sees uv = 0 (sw_immediate.h) */
        memset(f->geo->draws[f->geo->n_draws - 1].uv_map, 0, sizeof f->geo->draws[0].uv_map);
    return r;
}

sw_result sw__fr_tess_meshes(sw__fr_tess *f, const sw__fr_visible *vis, sw_status *status)
{
    sw_result r = SW_OK;
    for (size_t i = 0; i < vis->n_meshes && r == SW_OK; ++i) {
        const sw__fr_mesh_occ *mo = &vis->meshes[i];
        const sw_sg_mesh_rec *rec = &f->env->sv->meshes[mo->mesh];
        sw__fr_triangles t = {0};
        const double *normals;
        sw_sg_scene_mesh(f->env->scene, mo->mesh, &t.positions, &normals, &t.triangles);
        t.normals_d = normals;
        t.n_vertices = rec->n_vertices;
        t.n_triangles = rec->n_triangles;
        sw__fr_cofactor3(mo->world, t.normal_matrix); /* normals: shading is two-sided */
        occurrence o;
        memset(&o, 0, sizeof o);
        memcpy(o.world, mo->world, sizeof o.world);
        memcpy(o.color, mo->color, sizeof o.color);
        r = sw__fr_append_triangles(f, &o, &t, status);
        f->st->meshes_drawn++;
        f->st->mesh_triangles += rec->n_triangles;
    }
    return r;
}

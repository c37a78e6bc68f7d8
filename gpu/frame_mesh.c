/* Triangle meshes in the frame: the scene's mesh occurrences (sw_nodes.h MESH nodes, the .sws
 * MESHES section) and the static LODs' levels (frame_static.c) go through one path,
 * sw__fr_append_triangles, into the frame's triangle mesh, drawn like the CPU grids of the
 * per-frame path: depth-tested against the surfaces, coloured and lit by the same shader, in
 * walkthrough and converged frames alike (the work is plain memory made while the frame is
 * prepared, so split frames carry it in their plan).
 *
 * A mesh occurrence is culled by its box (the mesh's box corners under the occurrence's
 * transform, which bound the image of the box) against the view frustum. A mesh is drawn as given:
 * no screen-space error bound applies to it. Its boxes join the scene box before the view is set,
 * so the near plane leaves a mesh close to the eye in front of it. */
#include "frame_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The cofactor matrix of the linear part of m (row-major 3x3): det(M) M^-T, the map of normals
 * under any invertible affine transform (up to a positive factor when det > 0; shading is
 * two-sided, so the sign does not matter). */
static void normal_matrix(const double m[12], double out[9])
{
    const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], g = m[6], h = m[8], i = m[9],
                 k = m[10];
    out[0] = e * k - g * i, out[1] = g * h - d * k, out[2] = d * i - e * h;
    out[3] = c * i - b * k, out[4] = a * k - c * h, out[5] = b * h - a * i;
    out[6] = b * g - c * e, out[7] = c * d - a * g, out[8] = a * e - b * d;
}

/* Eye-relative position of object point p under m (the float the GPU gets). */
static void eye_position(const frame *f, const double m[12], const double *p, double out[3])
{
    for (int a = 0; a < 3; ++a)
        out[a] = m[4 * a] * p[0] + m[4 * a + 1] * p[1] + m[4 * a + 2] * p[2] +
                 (m[4 * a + 3] - f->view.eye[a]);
}

/* Each triangle with its own three vertices and its world normal: flat shading. */
static void append_flat(frame *f, const double m[12], const sw__fr_triangles *t)
{
    const size_t base = f->mesh.n_v;
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
            sw__gpu_vertex *v = &f->mesh.v[f->mesh.n_v++];
            for (int a = 0; a < 3; ++a) {
                v->pos[a] = (float)w[c][a];
                v->nrm[a] = n[a];
            }
            v->st[0] = v->st[1] = 0.0f;
        }
    }
    for (size_t k = 0; k < 3 * (size_t)t->n_triangles; ++k)
        f->mesh.idx[f->mesh.n_idx++] = (uint32_t)(base + k);
}

sw_result sw__fr_append_triangles(frame *f, const occurrence *o, const sw__fr_triangles *t,
                                  sw_status *status)
{
    const int flat = !t->normals_f && !t->normals_d;
    const size_t n_idx = 3 * (size_t)t->n_triangles;
    sw_result r = sw__gpu_mesh_reserve(&f->mesh, flat ? n_idx : t->n_vertices, n_idx, status);
    if (r != SW_OK)
        return r;
    const size_t base = f->mesh.n_v, first = f->mesh.n_idx;
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
            sw__gpu_vertex *v = &f->mesh.v[f->mesh.n_v++];
            for (int a = 0; a < 3; ++a) {
                v->pos[a] = (float)p[a];
                const double *row = t->normal_matrix + 3 * a;
                v->nrm[a] = (float)(row[0] * n[0] + row[1] * n[1] + row[2] * n[2]);
            }
            v->st[0] = v->st[1] = 0.0f;
        }
        for (size_t k = 0; k < n_idx; ++k)
            f->mesh.idx[f->mesh.n_idx++] = (uint32_t)base + t->triangles[k];
    }
    const trim_need none = {0.0, 0.0};
    const double cell[2] = {0.0, 0.0};
    r = sw__fr_add_draw(f, o, first, 0, &none, cell, status);
    if (r == SW_OK) /* no surface parameters: host shading sees uv = 0 (sw_immediate.h) */
        memset(f->draws[f->n_draws - 1].uv_map, 0, sizeof f->draws[0].uv_map);
    return r;
}

/* ---- the scene's mesh occurrences ----------------------------------------------------------- */

typedef struct collect_ctx {
    frame *f;
    sw__fr_meshes *fm;
    double *scene_box;
    int oom;
} collect_ctx;

static int collect_mesh(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                        const float color[4])
{
    (void)node;
    collect_ctx *c = ctx;
    sw__fr_meshes *fm = c->fm;
    if (!sw__gpu_grow((void **)&fm->occ, &fm->cap, fm->n + 1, sizeof *fm->occ)) {
        c->oom = 1;
        return 1;
    }
    sw__fr_mesh_occ *o = &fm->occ[fm->n++];
    o->mesh = mesh;
    memcpy(o->world, world, sizeof o->world);
    memcpy(o->color, color, sizeof o->color);
    /* the world box as the BVH boxes occurrences, then eye-relative like the view's planes */
    sw_sg_box_transform(world, c->f->sv->meshes[mesh].box, o->box);
    for (int k = 0; k < 3; ++k) {
        o->box[k] -= c->f->view.eye[k];
        o->box[3 + k] -= c->f->view.eye[k];
        c->scene_box[k] = fmin(c->scene_box[k], o->box[k]);
        c->scene_box[3 + k] = fmax(c->scene_box[3 + k], o->box[3 + k]);
    }
    return 0;
}

sw_result sw__fr_meshes_collect(frame *f, sw__fr_meshes *fm, double scene_box[6], sw_status *status)
{
    memset(fm, 0, sizeof *fm);
    if (f->sv->n_meshes == 0)
        return SW_OK;
    collect_ctx c = {f, fm, scene_box, 0};
    if (sw_sg_scene_traverse_meshes(f->scene, collect_mesh, &c) != SW_OK || c.oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh occurrences: out of memory");
    return SW_OK;
}

sw_result sw__fr_meshes_draw(frame *f, const sw__fr_meshes *fm, sw_status *status)
{
    sw_result r = SW_OK;
    for (size_t i = 0; i < fm->n && r == SW_OK; ++i) {
        const sw__fr_mesh_occ *mo = &fm->occ[i];
        if (!sw__gpu_view_box_visible(&f->view, mo->box)) {
            f->st.meshes_culled++;
            continue;
        }
        const sw_sg_mesh_rec *rec = &f->sv->meshes[mo->mesh];
        sw__fr_triangles t = {0};
        const double *normals;
        sw_sg_scene_mesh(f->scene, mo->mesh, &t.positions, &normals, &t.triangles);
        t.normals_d = normals;
        t.n_vertices = rec->n_vertices;
        t.n_triangles = rec->n_triangles;
        normal_matrix(mo->world, t.normal_matrix);
        occurrence o;
        memset(&o, 0, sizeof o);
        memcpy(o.world, mo->world, sizeof o.world);
        memcpy(o.color, mo->color, sizeof o.color);
        r = sw__fr_append_triangles(f, &o, &t, status);
        f->st.meshes_drawn++;
        f->st.mesh_triangles += rec->n_triangles;
    }
    return r;
}

void sw__fr_meshes_free(sw__fr_meshes *fm)
{
    sw__free(fm->occ);
    memset(fm, 0, sizeof *fm);
}

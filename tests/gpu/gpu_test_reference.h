/* SPDX-License-Identifier: MIT */
/* tests/gpu: an independent reference frame for the render-path tests (test_gpu_eval
 * and test_gpu_exact compared two of the renderer's own paths, which share the Filip densities,
 * the trim-texture atlas and the Bézier extraction, so a bug in any of those passed both).
 *
 * The reference is a dense mesh of every face occurrence (sw_sg_scene_traverse), evaluated in
 * double from the face's exact NURBS (sw_sg_surface_eval: knot vectors and control points, no
 * Bézier extraction), over a uniform grid of its trim box whose cells project to at most
 * k_ref_cell_px pixels (measured on a 33 x 33 sampling of the face in the frame's view, not by
 * lod/bezier/sampling.c's bounds), each cell's two triangles kept when their centroid is inside the
 * face's trim loops by exact even-odd classification (sw_sg_trim_classify's rule, by scanlines, on
 * loops flattened to 1e-7 of the trim box; no trim texture). It is drawn by
 * sw_gpu_render_triangles (the same camera, projection and depth convention, nothing else of the
 * frame's pipeline).
 *
 * The comparison (sw_test_ref_compare), per pixel, coverage from depth (finite = covered):
 *  - a coverage error is a pixel whose coverage in the test frame is found nowhere within one
 *    pixel (3 x 3) in the reference: an edge displaced by more than about 1 px (ε_img is 0.5 px;
 *    the reference's own staircase is under half a cell), a hole, or a piece that is not there;
 *  - a depth error is a pixel covered in both, interior in both (3 x 3 covered) and smooth in the
 *    reference (its 3 x 3 depths within k_ref_depth_rel of each other), whose depths differ by
 *    more than k_ref_depth_rel (1 %) relatively.
 * The callers allow at most 4 + 0.1 % of the covered pixels as errors of each kind (isolated
 * pixels at occluding edges, where a 3 x 3 neighbourhood is smooth in the reference but not in the
 * frame). */
#ifndef SW_TESTS_GPU_REFERENCE_H
#define SW_TESTS_GPU_REFERENCE_H

#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_sg_trim.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double k_ref_cell_px = 0.5; /* largest projected cell of the reference grid */
/* relative depth tolerance on smooth interiors: ε_img bounds the projected distance only, so a
 * face seen head-on may deviate along the view ray without a pixel's error (linkrods' face 23,
 * front view: 0.29 % with densities and grids right); a density or evaluation fault that moves
 * pixels moves depths by several % */
static const double k_ref_depth_rel = 1e-2;
enum { K_REF_PROBE = 33, K_REF_MAX_CELLS = 4096 };

typedef struct sw_test_ref_mesh {
    double *pos; /* 3 per vertex, world space */
    uint32_t *idx;
    size_t n_pos, cap_pos, n_idx, cap_idx;
    const sw_sg_scene *scene;
    sw__gpu_view view;
    sw_sg_polyline **loops; /* per face, flattened on first use (NULL: not yet) */
    uint32_t *n_loops;
    double *xs; /* a row's crossings (sw__ref_row) */
    unsigned char *keep;
    size_t cap_xs, cap_keep;
    int failed;
} sw_test_ref_mesh;

/* Pixel position of an eye-relative point; 0 when it is behind the eye. */
static inline int sw__ref_project(const sw__gpu_view *v, const double p[3], double px[2])
{
    double x = 0.0, y = 0.0, w = 0.0;
    for (int k = 0; k < 3; ++k) {
        x += v->right[k] * p[k];
        y += v->up[k] * p[k];
        w += v->fwd[k] * p[k];
    }
    if (!(w > 0.0))
        return 0;
    px[0] = (x / (w * v->tan_x) + 1.0) * 0.5 * v->width;
    px[1] = (y / (w * v->tan_y) + 1.0) * 0.5 * v->height;
    return 1;
}

static inline void sw__ref_world(const double m[12], const double p[3], double out[3])
{
    for (int r = 0; r < 3; ++r)
        out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
}

static inline const sw_sg_polyline *sw__ref_face_loops(sw_test_ref_mesh *m, uint32_t face,
                                                       uint32_t *n)
{
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(m->scene)->faces[face];
    *n = 0;
    if (!(rec->flags & SW_SG_FACE_TRIMMED) || rec->n_loops == 0)
        return NULL;
    if (!m->loops[face]) {
        m->loops[face] = calloc(rec->n_loops, sizeof *m->loops[face]);
        if (!m->loops[face])
            return NULL;
        const double *b = rec->uv_box;
        const double tol = 1e-7 * fmax(b[1] - b[0], b[3] - b[2]);
        for (uint32_t k = 0; k < rec->n_loops; ++k) {
            sw_status st = {0};
            if (sw_sg_trim_flatten_loop(m->scene, rec->first_loop + k, tol, 1u << 24,
                                        &m->loops[face][k], &st) != SW_OK) {
                fprintf(stderr, "reference: face %u loop %u: %s\n", face, k, st.message);
                m->failed = 1;
                return NULL;
            }
        }
        m->n_loops[face] = rec->n_loops;
    }
    *n = m->n_loops[face];
    return m->loops[face];
}

/* Cells per direction: the longest projected polyline of the probe grid along that direction,
 * divided by the cell size. */
static inline void sw__ref_cells(const sw_test_ref_mesh *m, const sw_sg_surface *s,
                                 const double world[12], const double b[4], int32_t *nu,
                                 int32_t *nv)
{
    enum { P = K_REF_PROBE };
    static double px[P * P][2];
    static int ok[P * P];
    for (int j = 0; j < P; ++j)
        for (int i = 0; i < P; ++i) {
            double loc[3], w[3];
            sw_sg_surface_eval(s, b[0] + (b[1] - b[0]) * i / (P - 1.0),
                               b[2] + (b[3] - b[2]) * j / (P - 1.0), loc);
            sw__ref_world(world, loc, w);
            for (int k = 0; k < 3; ++k)
                w[k] -= m->view.eye[k];
            ok[j * P + i] = sw__ref_project(&m->view, w, px[j * P + i]);
        }
    double lu = 0.0, lv = 0.0;
    for (int j = 0; j < P; ++j) {
        double a = 0.0, c = 0.0;
        for (int i = 0; i + 1 < P; ++i) {
            const int p = j * P + i, q = i * P + j;
            if (ok[p] && ok[p + 1])
                a += hypot(px[p + 1][0] - px[p][0], px[p + 1][1] - px[p][1]);
            if (ok[q] && ok[q + P])
                c += hypot(px[q + P][0] - px[q][0], px[q + P][1] - px[q][1]);
        }
        lu = fmax(lu, a);
        lv = fmax(lv, c);
    }
    /* at least the probe's intervals: a face smaller than a pixel still follows its curvature */
    *nu = (int32_t)fmin(K_REF_MAX_CELLS, fmax(P - 1, ceil(lu / k_ref_cell_px)));
    *nv = (int32_t)fmin(K_REF_MAX_CELLS, fmax(P - 1, ceil(lv / k_ref_cell_px)));
}

static inline int sw__ref_cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Even-odd classification of the points (u0 + k du, v), k = 0..n-1, into keep[k], by one scanline:
 * the rule of sw_sg_trim_classify (a crossing where the edge's ends lie on either side of v, taken
 * when u lies left of it), the crossings of the row computed once and sorted. */
static inline int sw__ref_row(sw_test_ref_mesh *m, const sw_sg_polyline *loops, uint32_t n_loops,
                              double v, double u0, double du, int32_t n, unsigned char *keep)
{
    size_t nx = 0;
    for (uint32_t l = 0; l < n_loops; ++l) {
        const double *p = loops[l].uv;
        const uint32_t c = loops[l].count;
        for (uint32_t i = 0, j = c ? c - 1 : 0; i < c; j = i++) {
            const double ui = p[2 * i], vi = p[2 * i + 1], uj = p[2 * j], vj = p[2 * j + 1];
            if ((vi > v) == (vj > v))
                continue;
            if (!sw__grow((void **)&m->xs, &m->cap_xs, nx + 1, sizeof *m->xs))
                return 0;
            m->xs[nx++] = ui + (v - vi) * (uj - ui) / (vj - vi);
        }
    }
    qsort(m->xs, nx, sizeof *m->xs, sw__ref_cmp);
    size_t left = 0; /* crossings at or left of u: the point is inside when those right are odd */
    for (int32_t k = 0; k < n; ++k) {
        const double u = u0 + du * k;
        while (left < nx && !(u < m->xs[left]))
            ++left;
        keep[k] = (unsigned char)((nx - left) & 1u);
    }
    return 1;
}

static inline int sw__ref_visit(void *ctx, uint32_t face, const double world[12],
                                const float color[4])
{
    (void)color;
    sw_test_ref_mesh *m = ctx;
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(m->scene)->faces[face];
    sw_sg_surface s;
    sw_sg_scene_face_surface(m->scene, face, &s);
    const double *b = rec->uv_box;
    uint32_t n_loops = 0;
    const sw_sg_polyline *loops = sw__ref_face_loops(m, face, &n_loops);
    if (m->failed)
        return 1;
    int32_t nu, nv;
    sw__ref_cells(m, &s, world, b, &nu, &nv);
    const size_t base = m->n_pos / 3, nvert = (size_t)(nu + 1) * (size_t)(nv + 1);
    if (!sw__grow((void **)&m->pos, &m->cap_pos, m->n_pos + 3 * nvert, sizeof *m->pos) ||
        !sw__grow((void **)&m->idx, &m->cap_idx, m->n_idx + 6 * (size_t)nu * (size_t)nv,
                  sizeof *m->idx)) {
        m->failed = 1;
        return 1;
    }
    for (int32_t j = 0; j <= nv; ++j)
        for (int32_t i = 0; i <= nu; ++i) {
            double loc[3];
            sw_sg_surface_eval(&s, i == nu ? b[1] : b[0] + (b[1] - b[0]) * i / nu,
                               j == nv ? b[3] : b[2] + (b[3] - b[2]) * j / nv, loc);
            sw__ref_world(world, loc, m->pos + m->n_pos);
            m->n_pos += 3;
        }
    const double du = (b[1] - b[0]) / nu, dv = (b[3] - b[2]) / nv;
    if (!sw__grow((void **)&m->keep, &m->cap_keep, 2 * (size_t)nu, 1)) {
        m->failed = 1;
        return 1;
    }
    memset(m->keep, 1, 2 * (size_t)nu);
    for (int32_t j = 0; j < nv; ++j) {
        /* centroids of (a, c, e) at (i + 2/3, j + 1/3) and of (a, e, d) at (i + 1/3, j + 2/3) */
        const double v0 = b[2] + dv * j;
        if (loops && (!sw__ref_row(m, loops, n_loops, v0 + dv / 3.0, b[0] + du * 2.0 / 3.0, du, nu,
                                   m->keep) ||
                      !sw__ref_row(m, loops, n_loops, v0 + dv * 2.0 / 3.0, b[0] + du / 3.0, du, nu,
                                   m->keep + nu))) {
            m->failed = 1;
            return 1;
        }
        for (int32_t i = 0; i < nu; ++i) {
            const uint32_t a = (uint32_t)(base + (size_t)j * (nu + 1) + i), c = a + 1,
                           d = a + (uint32_t)nu + 1, e = d + 1;
            if (m->keep[i]) {
                m->idx[m->n_idx++] = a;
                m->idx[m->n_idx++] = c;
                m->idx[m->n_idx++] = e;
            }
            if (m->keep[nu + i]) {
                m->idx[m->n_idx++] = a;
                m->idx[m->n_idx++] = e;
                m->idx[m->n_idx++] = d;
            }
        }
    }
    return 0;
}

/* Renders the reference of `scene` for desc's view (width, height, camera; depth is asked for)
 * into *out. Returns 1 on success; *triangles: the reference's triangle count. */
static inline int sw_test_ref_render(sw_gpu_context *ctx, const sw_sg_scene *scene,
                                     const sw_gpu_frame_desc *desc, sw_gpu_image *out,
                                     size_t *triangles)
{
    sw_test_ref_mesh m;
    memset(&m, 0, sizeof m);
    m.scene = scene;
    sw_status st = {0};
    const uint32_t n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    m.loops = calloc(n_faces ? n_faces : 1, sizeof *m.loops);
    m.n_loops = calloc(n_faces ? n_faces : 1, sizeof *m.n_loops);
    int ok =
        m.loops && m.n_loops &&
        sw__gpu_view_init(&m.view, &desc->camera, desc->width, desc->height, 1e-6, &st) == SW_OK &&
        sw_sg_scene_traverse(scene, sw__ref_visit, &m) == SW_OK && !m.failed &&
        m.n_pos / 3 <= UINT32_MAX && m.n_idx <= UINT32_MAX;
    sw_gpu_frame_desc d = *desc;
    d.want_depth = 1;
    if (ok && sw_gpu_render_triangles(ctx, m.pos, (uint32_t)(m.n_pos / 3), m.idx, (uint32_t)m.n_idx,
                                      &d, out, &st) != SW_OK) {
        fprintf(stderr, "reference: %s\n", st.message);
        ok = 0;
    }
    *triangles = m.n_idx / 3;
    for (uint32_t f = 0; m.loops && f < n_faces; ++f) {
        for (uint32_t k = 0; m.loops[f] && k < m.n_loops[f]; ++k)
            sw_sg_polyline_free(&m.loops[f][k]);
        free(m.loops[f]);
    }
    free(m.loops);
    free(m.n_loops);
    sw__free(m.pos); /* the arrays sw__gpu_grow grew */
    sw__free(m.idx);
    sw__free(m.xs);
    sw__free(m.keep);
    return ok;
}

typedef struct sw_test_ref_diff {
    long covered;           /* pixels covered in the reference or the test frame */
    long coverage_errors;   /* test coverage found nowhere within 1 px in the reference */
    long depth_errors;      /* smooth interiors whose depths differ beyond k_ref_depth_rel */
    double worst_depth_rel; /* the largest relative depth difference on smooth interiors */
} sw_test_ref_diff;

static inline int sw__ref_cov(const sw_gpu_image *img, int x, int y)
{
    return isfinite(img->depth[(size_t)y * (size_t)img->width + (size_t)x]);
}

/* Both images with depth, of the same size. */
static inline sw_test_ref_diff sw_test_ref_compare(const sw_gpu_image *ref,
                                                   const sw_gpu_image *test)
{
    sw_test_ref_diff r = {0, 0, 0, 0.0};
    const int w = ref->width, h = ref->height;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int ct = sw__ref_cov(test, x, y), cr = sw__ref_cov(ref, x, y);
            r.covered += ct || cr;
            int found = 0, ref_all = 1, test_all = 1;
            double zmin = INFINITY, zmax = -INFINITY;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) {
                        ref_all = test_all = 0;
                        found |= ct == 0; /* outside the image is background */
                        continue;
                    }
                    const int c = sw__ref_cov(ref, xx, yy);
                    found |= c == ct;
                    ref_all &= c;
                    test_all &= sw__ref_cov(test, xx, yy);
                    if (c) {
                        const double z = ref->depth[(size_t)yy * (size_t)w + (size_t)xx];
                        zmin = fmin(zmin, z);
                        zmax = fmax(zmax, z);
                    }
                }
            r.coverage_errors += !found;
            if (ref_all && test_all && zmax - zmin <= k_ref_depth_rel * zmin) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                const double zr = ref->depth[i], zt = test->depth[i];
                r.depth_errors += fabs(zt - zr) > k_ref_depth_rel * zr;
                r.worst_depth_rel = fmax(r.worst_depth_rel, fabs(zt - zr) / zr);
            }
        }
    return r;
}

/* A frame against the reference: coverage and depth errors within 4 + 0.1 % of the covered
 * pixels (isolated pixels at occluding edges), at least 2 % of the frame covered. Prints the
 * figures under `label`; on failure writes PREFIX_ref.png and PREFIX_LABEL.png. 1: it passes. */
static inline int sw_test_ref_check(const sw_gpu_image *ref, const sw_gpu_image *img,
                                    size_t ref_tris, const char *label, const char *prefix)
{
    const sw_test_ref_diff df = sw_test_ref_compare(ref, img);
    const long limit = 4 + df.covered / 1000;
    const int good = df.covered > (long)img->width * img->height / 50 &&
                     df.coverage_errors <= limit && df.depth_errors <= limit;
    printf("  vs reference (%zu triangles) %dx%d, %s: %ld covered, coverage errors %ld, "
           "depth errors %ld (limit %ld; worst depth difference %.2f %%)%s\n",
           ref_tris, img->width, img->height, label, df.covered, df.coverage_errors,
           df.depth_errors, limit, 100.0 * df.worst_depth_rel, good ? "" : "  <-- FAIL");
    if (!good) {
        char path[1100];
        sw_status st = {0};
        snprintf(path, sizeof path, "%s_ref.png", prefix);
        sw_gpu_image_write(ref, path, &st);
        snprintf(path, sizeof path, "%s_%s.png", prefix, label);
        sw_gpu_image_write(img, path, &st);
    }
    return good;
}

/* Draws the scene one way of two (way 0 or 1) into img; 1 on success. */
typedef int (*sw_test_draw_way_fn)(sw_gpu_context *ctx, const sw_sg_scene *scene,
                                   const sw_gpu_frame_desc *desc, int way, sw_gpu_image *img,
                                   sw_gpu_frame_stats *fs);

/* Both ways (named names[0], names[1]) at a quarter of full's size against the independent
 * reference, PREFIX_iso or PREFIX_front the files of a failure. 1: both pass. */
static inline int sw_test_ref_view(sw_gpu_context *ctx, const sw_sg_scene *scene,
                                   const sw_gpu_frame_desc *full, const char *prefix, int iso,
                                   sw_test_draw_way_fn draw, const char *const names[2])
{
    sw_gpu_frame_desc desc = *full;
    desc.width = full->width / 4;
    desc.height = full->height / 4;
    desc.want_depth = 1;
    sw_gpu_image ref = {0};
    size_t ref_tris = 0;
    if (!sw_test_ref_render(ctx, scene, &desc, &ref, &ref_tris))
        return 0;
    /* without fat borders (crack_fill.c): they extend faces beyond their exact boundaries on
     * purpose, over whatever lies behind (linkrods, front view: 98 pixels up to 2.3 % nearer than
     * the surface they cover, >= 2 px beyond face 23's edge); the surfaces alone are compared */
    sw__gpu_set_crack_fill(ctx, 0);
    int ok = 1;
    for (int way = 0; way < 2 && ok; ++way) {
        sw_gpu_image img = {0};
        sw_gpu_frame_stats fs;
        if (!draw(ctx, scene, &desc, way, &img, &fs)) {
            ok = 0;
            break;
        }
        char prefix_view[1040];
        snprintf(prefix_view, sizeof prefix_view, "%s_%s", prefix, iso ? "iso" : "front");
        ok = sw_test_ref_check(&ref, &img, ref_tris, names[way], prefix_view);
        sw_gpu_image_free(&img);
    }
    sw__gpu_set_crack_fill(ctx, 1);
    sw_gpu_image_free(&ref);
    return ok;
}

#endif

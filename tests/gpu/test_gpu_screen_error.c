/* SPDX-License-Identifier: MIT */
/* Screen-space error, numerically (ARCHITECTURE.md "Numbers that define works"): every
 * drawn triangle of a frame stays within ε_img = 0.5 px of the exact surface. The frame's patch
 * pieces are taken from gpu/frame.c's debug hook (the same records, grid classes and parameters
 * the vertex shader or the CPU grid uses; grid parameters of shader records recomputed in float
 * as the shader does). For each triangle of each grid (cells split as gpu/grid_set.c splits them)
 * the vertices, edge midpoints and centroid are checked: the drawn point (barycentric combination
 * of the vertices, positions evaluated in double from the frame's Bézier control points) against
 * the exact surface at the same (u, v) — sw_sg_surface_eval of the face's NURBS, through the
 * occurrence transform — both projected through the frame's camera in double. This is independent
 * of the frame's Bézier extraction and of its bounds (lod/bezier/sampling.c).
 * Skipped: points whose (u, v) is outside the face's trim loops (exact even-odd classification on
 * loops flattened to 1e-7 of the parameter box; the trim texture discards them), and points not
 * on screen (behind the near plane or outside the viewport by more than 1 px).
 * Views: whole model (iso, fitted to the box), then mid (0.4 x that distance) and close-up
 * (0.15 x) looking at the middle of the piece with the most cells in the whole view.
 *
 * With --hierarchy the frame traverses the faces' bicubic hierarchies (§6-§7, a lod/ cache built in
 * a worker pool): the drawn pieces are then hierarchy nodes whose bicubics only approximate the
 * face, and the check against the exact NURBS covers their approximation error too.
 *
 * Usage: test_gpu_screen_error [--hierarchy] OUTDIR FILE...
 */
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"
#include "sw_sg_trim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double k_eps_px = 0.5;
static sw_th_pool *g_pool; /* --hierarchy: builds the hierarchies */
static const int32_t k_width = 1280, k_height = 720;

typedef struct piece {
    sw__gpu_drawn_patch d;
    double *cpw; /* owned copy */
    double world[12];
} piece;

typedef struct collector {
    piece *p;
    size_t n, cap;
    sw__gpu_view view;
    int oom;
} collector;

static void hook(void *user, const sw__gpu_drawn_patch *d)
{
    collector *c = user;
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 256;
        piece *p = realloc(c->p, cap * sizeof *p);
        if (!p) {
            c->oom = 1;
            return;
        }
        c->p = p;
        c->cap = cap;
    }
    size_t n = (size_t)(d->deg_u + 1) * (size_t)(d->deg_v + 1) * 4;
    double *cpw = malloc(n * sizeof *cpw);
    if (!cpw) {
        c->oom = 1;
        return;
    }
    memcpy(cpw, d->cpw, n * sizeof *cpw);
    piece *p = &c->p[c->n++];
    p->d = *d;
    p->cpw = cpw;
    p->d.cpw = cpw;
    memcpy(p->world, d->world, sizeof p->world);
    p->d.world = NULL;
    p->d.view = NULL;
    c->view = *d->view;
}

static void collector_clear(collector *c)
{
    for (size_t i = 0; i < c->n; ++i)
        free(c->p[i].cpw);
    c->n = 0;
}

/* Trim loops of a face, flattened once. */
typedef struct face_loops {
    sw_sg_polyline *loops;
    uint32_t n;
    int done;
} face_loops;

typedef struct stats {
    double *err;
    size_t n, cap;
    unsigned long long skipped_trim, skipped_off, triangles;
    double worst;
    int oom;
} stats;

static void push_err(stats *s, double e)
{
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 4096;
        double *p = realloc(s->err, cap * sizeof *p);
        if (!p) {
            s->oom = 1;
            return;
        }
        s->err = p;
        s->cap = cap;
    }
    s->err[s->n++] = e;
    if (e > s->worst)
        s->worst = e;
}

/* Pixel position of an eye-relative point; 0 when it is not on screen. */
static int project(const sw__gpu_view *v, const double p[3], double px[2])
{
    double x = 0.0, y = 0.0, w = 0.0;
    for (int k = 0; k < 3; ++k) {
        x += v->right[k] * p[k];
        y += v->up[k] * p[k];
        w += v->fwd[k] * p[k];
    }
    if (!(w >= v->near_plane))
        return 0;
    px[0] = (x / (w * v->tan_x) + 1.0) * 0.5 * v->width;
    px[1] = (y / (w * v->tan_y) + 1.0) * 0.5 * v->height;
    return px[0] >= -1.0 && px[0] <= v->width + 1.0 && px[1] >= -1.0 && px[1] <= v->height + 1.0;
}

/* Grid parameter k of n over [a, b] as the drawing path computes it (shader: float). */
static double grid_param(const piece *p, double a, double b, int32_t k, int32_t n)
{
    if (k == n)
        return b;
    if (p->d.gpu) {
        float fa = (float)a, fb = (float)b;
        return (double)(fa + (fb - fa) * (float)k / (float)n);
    }
    return a + (b - a) * (double)k / (double)n;
}

typedef struct gvert {
    double st[2], x[3];
} gvert;

static const double k_bc[7][3] = {{1, 0, 0},
                                  {0, 1, 0},
                                  {0, 0, 1},
                                  {.5, .5, 0},
                                  {0, .5, .5},
                                  {.5, 0, .5},
                                  {1. / 3, 1. / 3, 1. / 3}};

static void check_triangle(const sw_sg_scene *scene, const piece *p, const sw__gpu_view *v,
                           const face_loops *fl, const gvert *tri[3], stats *s)
{
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(scene)->faces[p->d.face];
    sw_sg_surface srf;
    sw_sg_scene_face_surface(scene, p->d.face, &srf);
    s->triangles++;
    for (int c = 0; c < 7; ++c) {
        double st[2] = {0, 0}, x[3] = {0, 0, 0};
        for (int r = 0; r < 3; ++r) {
            for (int k = 0; k < 2; ++k)
                st[k] += k_bc[c][r] * tri[r]->st[k];
            for (int k = 0; k < 3; ++k)
                x[k] += k_bc[c][r] * tri[r]->x[k];
        }
        double u = p->d.u0 + st[0] * (p->d.u1 - p->d.u0);
        double w = p->d.v0 + st[1] * (p->d.v1 - p->d.v0);
        if (p->d.trimmed && fl->n > 0 && !sw_sg_trim_classify(fl->loops, fl->n, u, w)) {
            s->skipped_trim++;
            continue;
        }
        (void)rec;
        double loc[3], y[3];
        sw_sg_surface_eval(&srf, u, w, loc);
        for (int r = 0; r < 3; ++r)
            y[r] = p->world[4 * r] * loc[0] + p->world[4 * r + 1] * loc[1] +
                   p->world[4 * r + 2] * loc[2] + p->world[4 * r + 3] - v->eye[r];
        double px[2], py[2];
        if (!project(v, x, px) || !project(v, y, py)) {
            s->skipped_off++;
            continue;
        }
        push_err(s, hypot(px[0] - py[0], px[1] - py[1]));
    }
}

static void check_piece(const sw_sg_scene *scene, const piece *p, const sw__gpu_view *v,
                        const face_loops *fl, stats *s)
{
    int32_t nu = p->d.nu, nv = p->d.nv;
    gvert *g = malloc((size_t)(nu + 1) * (size_t)(nv + 1) * sizeof *g);
    if (!g) {
        s->oom = 1;
        return;
    }
    sw_sg_bezier_patch bp = {p->d.deg_u, p->d.deg_v, 0, 0, 0.0, 1.0, 0.0, 1.0, p->cpw};
    for (int32_t l = 0; l <= nv; ++l)
        for (int32_t k = 0; k <= nu; ++k) {
            gvert *q = &g[(size_t)l * (size_t)(nu + 1) + (size_t)k];
            q->st[0] = grid_param(p, p->d.s0, p->d.s1, k, nu);
            q->st[1] = grid_param(p, p->d.t0, p->d.t1, l, nv);
            sw_sg_bezier_patch_eval(&bp, q->st[0], q->st[1], q->x);
        }
    for (int32_t l = 0; l < nv; ++l)
        for (int32_t k = 0; k < nu; ++k) {
            const gvert *a = &g[(size_t)l * (size_t)(nu + 1) + (size_t)k], *b = a + 1,
                        *d = a + nu + 1, *e = d + 1;
            const gvert *t0[3] = {a, b, e}, *t1[3] = {a, e, d};
            check_triangle(scene, p, v, fl, t0, s);
            check_triangle(scene, p, v, fl, t1, s);
        }
    free(g);
}

static int face_loops_get(const sw_sg_scene *scene, uint32_t face, face_loops *fl)
{
    if (fl->done)
        return 1;
    fl->done = 1;
    const sw_sg_face_rec *rec = &sw_sg_scene_view_ptr(scene)->faces[face];
    if (!(rec->flags & SW_SG_FACE_TRIMMED) || rec->n_loops == 0)
        return 1;
    fl->loops = calloc(rec->n_loops, sizeof *fl->loops);
    if (!fl->loops)
        return 0;
    const double *b = rec->uv_box;
    double tol = 1e-7 * fmax(b[1] - b[0], b[3] - b[2]);
    for (uint32_t k = 0; k < rec->n_loops; ++k) {
        sw_status st = {0};
        if (sw_sg_trim_flatten_loop(scene, rec->first_loop + k, tol, 1u << 24, &fl->loops[k],
                                    &st) != SW_OK) {
            fprintf(stderr, "face %u loop %u: %s\n", face, k, st.message);
            return 0;
        }
        fl->n++;
    }
    return 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Iso camera at `fraction` of the distance that fits the box, looking at `target` (NULL: the
 * box centre). */
static sw_gpu_camera view_camera(const double b[6], double fraction, const double *target)
{
    sw_gpu_camera c;
    memset(&c, 0, sizeof c);
    double diag = sqrt(pow(b[3] - b[0], 2) + pow(b[4] - b[1], 2) + pow(b[5] - b[2], 2));
    double dist = diag / (2.0 * tan(20.0 * M_PI / 180.0)) * 1.1 * fraction;
    for (int k = 0; k < 3; ++k) {
        c.target[k] = target ? target[k] : 0.5 * (b[k] + b[3 + k]);
        c.eye[k] = c.target[k] + dist / sqrt(3.0);
    }
    c.up[2] = 1.0;
    c.fovy_deg = 40.0;
    return c;
}

/* World point at the middle of the piece with the most cells: where close-ups look. */
static void busiest_point(const collector *c, double out[3])
{
    size_t best = 0;
    for (size_t i = 1; i < c->n; ++i)
        if ((double)c->p[i].d.nu * c->p[i].d.nv > (double)c->p[best].d.nu * c->p[best].d.nv)
            best = i;
    const piece *p = &c->p[best];
    sw_sg_bezier_patch bp = {p->d.deg_u, p->d.deg_v, 0, 0, 0.0, 1.0, 0.0, 1.0, p->cpw};
    sw_sg_bezier_patch_eval(&bp, 0.5 * (p->d.s0 + p->d.s1), 0.5 * (p->d.t0 + p->d.t1), out);
    for (int k = 0; k < 3; ++k)
        out[k] += c->view.eye[k];
}

static int run_view(sw_gpu_context *ctx, const sw_sg_scene *scene, sw_lod_cache *cache,
                    face_loops *fl, const double box[6], double fraction, const double *target,
                    const char *name, const char *prefix, collector *c)
{
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = k_width;
    desc.height = k_height;
    desc.error_px = k_eps_px;
    desc.camera = view_camera(box, fraction, target);
    desc.hierarchies = cache;
    collector_clear(c);
    sw__gpu_set_patch_hook(ctx, hook, c);
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    sw_status st = {0};
    sw_result r = sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st);
    sw__gpu_set_patch_hook(ctx, NULL, NULL);
    if (r != SW_OK || c->oom) {
        fprintf(stderr, "render: %s\n", r != SW_OK ? st.message : "out of memory");
        return 0;
    }
    char path[1100];
    snprintf(path, sizeof path, "%s_%s.png", prefix, name);
    sw_gpu_image_write(&img, path, &st);
    sw_gpu_image_free(&img);
    stats s;
    memset(&s, 0, sizeof s);
    for (size_t i = 0; i < c->n && !s.oom; ++i) {
        const piece *p = &c->p[i];
        if (!face_loops_get(scene, p->d.face, &fl[p->d.face]))
            return 0;
        check_piece(scene, p, &c->view, &fl[p->d.face], &s);
    }
    if (s.oom) {
        free(s.err);
        fprintf(stderr, "out of memory\n");
        return 0;
    }
    double median = 0.0;
    if (s.n > 0) {
        qsort(s.err, s.n, sizeof *s.err, cmp_double);
        median = s.err[s.n / 2];
    }
    int ok = s.worst <= k_eps_px && s.n > 1000;
    printf("%s %s: %zu pieces (%llu shader-evaluated patches, %llu hierarchy nodes, %llu over "
           "budget, %llu refinement rounds), %llu triangles; %zu points checked, max %.4f px, "
           "median %.4f px; skipped %llu outside the trim loops, %llu off screen%s\n",
           prefix, name, c->n, (unsigned long long)fs.patches_gpu_evaluated,
           (unsigned long long)fs.hlod_nodes, (unsigned long long)fs.hlod_over_budget,
           (unsigned long long)fs.hlod_refine_rounds, s.triangles, s.n, s.worst, median,
           s.skipped_trim, s.skipped_off, ok ? "" : "  <-- FAIL");
    if (cache && fs.hlod_nodes == 0) {
        printf("  <-- FAIL: --hierarchy drew no hierarchy node\n");
        ok = 0;
    }
    free(s.err);
    return ok;
}

static int run_file(sw_gpu_context *ctx, const char *outdir, const char *path, collector *c)
{
    sw_sg_import_desc id = {path, NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL;
    sw_status st = {0};
    if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
        fprintf(stderr, "import %s: %s\n", path, st.message);
        return 0;
    }
    sw_sg_scene_stats ss;
    sw_sg_scene_compute_stats(scene, &ss);
    uint32_t n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    face_loops *fl = calloc(n_faces ? n_faces : 1, sizeof *fl);
    int ok = fl != NULL;
    sw_lod_cache *cache = NULL;
    if (ok && g_pool && sw_lod_cache_create(scene, g_pool, NULL, &cache, &st) != SW_OK) {
        fprintf(stderr, "hierarchy cache: %s\n", st.message);
        ok = 0;
    }
    const char *base = strrchr(path, '/');
    char prefix[1024];
    snprintf(prefix, sizeof prefix, "%s/%s", outdir, base ? base + 1 : path);
    static const double fractions[3] = {1.0, 0.4, 0.15};
    static const char *const names[3] = {"whole", "mid", "close"};
    double target[3];
    for (int k = 0; k < 3 && ok; ++k) {
        ok = run_view(ctx, scene, cache, fl, ss.bbox, fractions[k], k ? target : NULL, names[k],
                      prefix, c) &&
             ok;
        if (k == 0 && c->n > 0)
            busiest_point(c, target);
    }
    for (uint32_t f = 0; fl && f < n_faces; ++f) {
        for (uint32_t k = 0; k < fl[f].n; ++k)
            sw_sg_polyline_free(&fl[f].loops[k]);
        free(fl[f].loops);
    }
    free(fl);
    sw_lod_cache_destroy(cache);
    sw_sg_scene_free(scene);
    return ok;
}

int main(int argc, char **argv)
{
    int first = 1;
    if (argc > 1 && strcmp(argv[1], "--hierarchy") == 0) {
        sw_th_pool_desc pd = {0};
        if (sw_th_pool_create(&pd, &g_pool) != SW_OK) {
            fprintf(stderr, "FAIL: worker pool\n");
            return 1;
        }
        first = 2;
    }
    if (argc < first + 2) {
        fprintf(stderr, "usage: %s [--hierarchy] OUTDIR FILE...\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    collector c;
    memset(&c, 0, sizeof c);
    int ok = 1;
    for (int a = first + 1; a < argc; ++a)
        ok = run_file(ctx, argv[first], argv[a], &c) && ok;
    collector_clear(&c);
    free(c.p);
    sw_gpu_context_free(ctx);
    sw_th_pool_destroy(g_pool);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

/* SPDX-License-Identifier: MIT */
/* Close-up zoom: from the whole model down to a view 1/10,000 of its size, every frame
 * renders (no SW_ERR_LIMIT: the trim-texture hierarchy of Guthe et al. 2005 §5.3 splits a face's
 * trim box into tiles instead of asking for one texture above the maximum size), the atlas pages
 * stay within GL_MAX_TEXTURE_SIZE, and the drawn trim edges stay within 1 px of the exact curves.
 *
 * Scene: the largest trimmed planar face of Motor-c.brep, copied alone into a new scene, so that
 * its whole trim boundary is a coverage boundary (no neighbour covers the other side, no seam).
 * Cameras: looking at a point P in the middle of its longest curved trim curve, 30° off the face
 * normal on the side the face faces, rolled 17° so that the curve is not aligned with pixel rows;
 * visible height from the model's diagonal down to diagonal / 10^4 in 9 geometric steps,
 * 640 x 360, ε_img 0.5 px. Frames are written to OUTDIR/zoom_<i>.png.
 * Reference: every loop curve sampled densely (≤ 0.25 px apart on screen) in double, mapped
 * through sw_sg_surface_eval and the camera (perspective as gpu/camera.c builds it). For each
 * sample inside the frame and not hidden (rendered depth not in front of the sample's depth), the
 * nearest coverage-boundary pixel centre (covered with an uncovered 4-neighbour or vice versa;
 * coverage = finite depth) must be within 1 px, Chebyshev distance. Samples within 1.5 px of the
 * frame's edge are skipped: the boundary outside the image is not seen.
 *
 * Per-entry size: the frame stats do not list entry sizes; sw__gpu_atlas_add refuses an entry
 * above sw__gpu_atlas_max_entry with SW_ERR_LIMIT, so SW_OK implies the bound; the test also
 * checks atlas_texels / atlas_pages <= GL_MAX_TEXTURE_SIZE^2 and the mean entry size.
 *
 * With --hierarchy the frames traverse the face's bicubic hierarchy (§6-§7): there the nodes
 * (refined below the leaves, and leaves cut into parts) carry the trim textures, and every frame
 * must draw hierarchy nodes.
 *
 * Usage: test_gpu_zoom [--hierarchy] OUTDIR Motor-c.brep [SHIFT_PX]
 * SHIFT_PX (default 0) moves the reference curve sideways on screen: a control showing that the
 * check fails for a displaced edge (e.g. 1.5).
 */
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 640, H = 360, N_FRAMES = 9 };
static double g_shift_px = 0.0;
static sw_lod_cache *g_cache; /* --hierarchy */
static const double k_fovy = 40.0, k_oblique_deg = 30.0, k_tol_px = 1.0;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize3(double v[3])
{
    double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; ++k)
        v[k] /= n;
}

/* 3D extent of a face over its trim box (corner and mid samples). */
static double face_extent(const sw_sg_scene *scene, uint32_t f)
{
    const sw_sg_face_rec *r = &sw_sg_scene_view_ptr(scene)->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, f, &s);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i <= 4; ++i)
        for (int j = 0; j <= 4; ++j) {
            double p[3];
            sw_sg_surface_eval(&s, r->uv_box[0] + (r->uv_box[1] - r->uv_box[0]) * i / 4.0,
                               r->uv_box[2] + (r->uv_box[3] - r->uv_box[2]) * j / 4.0, p);
            for (int k = 0; k < 3; ++k) {
                lo[k] = fmin(lo[k], p[k]);
                hi[k] = fmax(hi[k], p[k]);
            }
        }
    return sqrt(pow(hi[0] - lo[0], 2) + pow(hi[1] - lo[1], 2) + pow(hi[2] - lo[2], 2));
}

/* A scene holding face f of src alone (records and pool data copied, identity transform). */
static sw_result copy_face(const sw_sg_scene *src, uint32_t f, sw_sg_scene **out, sw_status *st)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(src);
    sw_sg_face_rec face = v->faces[f];
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(st, SW_ERR_OUT_OF_MEMORY, "builder");
    face.knots_u = sw_sg_builder_push_doubles(b, v->pool + face.knots_u, face.n_u + face.deg_u + 1);
    face.knots_v = sw_sg_builder_push_doubles(b, v->pool + face.knots_v, face.n_v + face.deg_v + 1);
    face.cpw = sw_sg_builder_push_doubles(b, v->pool + face.cpw, (size_t)face.n_u * face.n_v * 4);
    face.first_loop = 0;
    for (uint32_t l = 0; l < face.n_loops; ++l) {
        sw_sg_loop_rec loop = v->loops[v->faces[f].first_loop + l];
        uint32_t first = SW_SG_NONE;
        for (uint32_t c = 0; c < loop.n_curves; ++c) {
            sw_sg_curve_rec cr = v->curves[loop.first_curve + c];
            cr.knots = sw_sg_builder_push_doubles(b, v->pool + cr.knots, cr.n + cr.degree + 1);
            cr.cpw = sw_sg_builder_push_doubles(b, v->pool + cr.cpw, (size_t)cr.n * 3);
            uint32_t id = sw_sg_builder_add_curve(b, &cr);
            if (c == 0)
                first = id;
        }
        loop.first_curve = first;
        sw_sg_builder_add_loop(b, &loop);
    }
    uint32_t id = sw_sg_builder_add_face(b, &face);
    static const float grey[4] = {0.7f, 0.7f, 0.7f, 1.0f};
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, id, NULL, grey, "face");
    return sw_sg_builder_finish(b, out, st);
}

/* Window coordinates (x right, y down from the top row, pixel centres at +0.5) and view depth. */
static int project(const sw_gpu_camera *cam, const double fwd[3], const double right[3],
                   const double up[3], const double p[3], double px[2], double *depth)
{
    double d[3] = {p[0] - cam->eye[0], p[1] - cam->eye[1], p[2] - cam->eye[2]};
    double w = dot3(d, fwd);
    if (!(w > 0.0))
        return 0;
    double ty = tan(cam->fovy_deg * M_PI / 360.0), tx = ty * (double)W / (double)H;
    px[0] = (dot3(d, right) / (w * tx) + 1.0) * 0.5 * W;
    px[1] = H - (dot3(d, up) / (w * ty) + 1.0) * 0.5 * H;
    *depth = w;
    return 1;
}

typedef struct frame_check {
    const sw_gpu_image *img;
    uint8_t *boundary; /* W*H */
    sw_gpu_camera cam;
    double fwd[3], right[3], up[3];
    const sw_sg_surface *srf;
    double worst;          /* Chebyshev px */
    double worst_eucl;
    unsigned long checked, hidden, failed;
} frame_check;

static int covered(const sw_gpu_image *img, int x, int y)
{
    return isfinite(img->depth[(size_t)y * W + (size_t)x]);
}

static void mark_boundary(frame_check *fc)
{
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int c = covered(fc->img, x, y), b = 0;
            if (x > 0 && covered(fc->img, x - 1, y) != c)
                b = 1;
            if (x + 1 < W && covered(fc->img, x + 1, y) != c)
                b = 1;
            if (y > 0 && covered(fc->img, x, y - 1) != c)
                b = 1;
            if (y + 1 < H && covered(fc->img, x, y + 1) != c)
                b = 1;
            fc->boundary[(size_t)y * W + (size_t)x] = (uint8_t)b;
        }
}

/* One curve sample: skipped off screen or hidden, else its distance to the boundary pixels. */
static void check_point(frame_check *fc, const double p[3])
{
    double q[2], z;
    if (!project(&fc->cam, fc->fwd, fc->right, fc->up, p, q, &z))
        return;
    q[0] += g_shift_px;
    /* Only points whose whole tolerance neighbourhood lies in the frame: the coverage boundary
     * beyond the image edge is not seen, so a curve leaving the frame steeply would have its
     * nearest visible boundary pixel up to 2 px away with a correctly drawn edge. */
    const double m = k_tol_px + 0.5;
    if (!(q[0] >= m && q[0] < W - m && q[1] >= m && q[1] < H - m))
        return;
    int ix = (int)q[0], iy = (int)q[1];
    float d = fc->img->depth[(size_t)iy * W + (size_t)ix];
    if (isfinite(d) && (double)d < z * (1.0 - 0.02)) {
        fc->hidden++;
        return;
    }
    double best = INFINITY, best_e = INFINITY;
    for (int y = iy - 3; y <= iy + 3; ++y)
        for (int x = ix - 3; x <= ix + 3; ++x) {
            if (x < 0 || y < 0 || x >= W || y >= H || !fc->boundary[(size_t)y * W + (size_t)x])
                continue;
            double dx = fabs(x + 0.5 - q[0]), dy = fabs(y + 0.5 - q[1]);
            best = fmin(best, fmax(dx, dy));
            best_e = fmin(best_e, hypot(dx, dy));
        }
    fc->checked++;
    if (best > k_tol_px)
        fc->failed++;
    fc->worst = fmax(fc->worst, best);
    fc->worst_eucl = fmax(fc->worst_eucl, best_e);
}

static void curve_point(const frame_check *fc, const sw_sg_curve *c, double t, double p[3])
{
    double uv[2];
    sw_sg_curve_eval(c, t, uv);
    sw_sg_surface_eval(fc->srf, uv[0], uv[1], p);
}

/* Coarse samples, then every coarse interval with an end near the frame refined to <= 0.25 px. */
static void check_curve(frame_check *fc, const sw_sg_curve *c)
{
    enum { COARSE = 20000 };
    double t0, t1;
    sw_sg_knots_domain(c->knots, c->degree, c->n, &t0, &t1);
    double prev_p[3], prev_q[2] = {0, 0}, z;
    int prev_ok = 0;
    for (int i = 0; i <= COARSE; ++i) {
        double t = t0 + (t1 - t0) * i / COARSE, p[3], q[2];
        curve_point(fc, c, t, p);
        int ok = project(&fc->cam, fc->fwd, fc->right, fc->up, p, q, &z);
        if (i > 0) {
            int near = (ok && q[0] > -2.0 * W && q[0] < 3.0 * W && q[1] > -2.0 * H &&
                        q[1] < 3.0 * H) ||
                       (prev_ok && prev_q[0] > -2.0 * W && prev_q[0] < 3.0 * W &&
                        prev_q[1] > -2.0 * H && prev_q[1] < 3.0 * H);
            if (near) {
                double len = ok && prev_ok ? hypot(q[0] - prev_q[0], q[1] - prev_q[1]) : 4.0 * W;
                long n = (long)ceil(len / 0.25);
                n = n < 1 ? 1 : (n > 2000000 ? 2000000 : n);
                double ta = t0 + (t1 - t0) * (i - 1) / COARSE;
                for (long k = 0; k < n; ++k) {
                    double s[3];
                    curve_point(fc, c, ta + (t - ta) * (double)k / (double)n, s);
                    check_point(fc, s);
                }
            }
        }
        memcpy(prev_p, p, sizeof p);
        memcpy(prev_q, q, sizeof q);
        prev_ok = ok;
    }
    check_point(fc, prev_p);
}

/* Whether the curve's control polygon (in u, v) leaves its chord: a curved trim edge. */
static int is_curved(const sw_sg_curve *c)
{
    const double *q = c->cpw, *e = c->cpw + (size_t)(c->n - 1) * 3;
    double a[2] = {q[0] / q[2], q[1] / q[2]}, b[2] = {e[0] / e[2], e[1] / e[2]};
    double ch = hypot(b[0] - a[0], b[1] - a[1]), dev = 0.0;
    for (int32_t i = 1; i + 1 < c->n; ++i) {
        const double *p = c->cpw + (size_t)i * 3;
        double x = p[0] / p[2] - a[0], y = p[1] / p[2] - a[1];
        dev = fmax(dev, ch > 0.0 ? fabs(x * (b[1] - a[1]) - y * (b[0] - a[0])) / ch : hypot(x, y));
    }
    return c->degree >= 2 && dev > 1e-3 * fmax(ch, 1e-12);
}

typedef struct target {
    double p[3], normal[3], tangent[3];
} target;

/* P at the middle of the face's longest curved trim curve (else its longest curve); outward
 * normal; 3D tangent. */
static void pick_target(const sw_sg_scene *scene, uint32_t f, target *tg)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    const sw_sg_face_rec *r = &v->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, f, &s);
    double best = -1.0;
    for (uint32_t l = 0; l < r->n_loops; ++l) {
        const sw_sg_loop_rec *lp = &v->loops[r->first_loop + l];
        for (uint32_t k = 0; k < lp->n_curves; ++k) {
            sw_sg_curve c;
            sw_sg_scene_curve(scene, lp->first_curve + k, &c);
            double t0, t1, a[3], b[3], uv[2], len = 0.0;
            sw_sg_knots_domain(c.knots, c.degree, c.n, &t0, &t1);
            for (int i = 0; i <= 64; ++i) {
                sw_sg_curve_eval(&c, t0 + (t1 - t0) * i / 64.0, uv);
                sw_sg_surface_eval(&s, uv[0], uv[1], b);
                if (i > 0)
                    len += sqrt(pow(b[0] - a[0], 2) + pow(b[1] - a[1], 2) + pow(b[2] - a[2], 2));
                memcpy(a, b, sizeof a);
            }
            if (is_curved(&c))
                len *= 1e6; /* prefer a curved trim edge: a straight one may align with pixels */
            if (len <= best)
                continue;
            best = len;
            double tm = 0.5 * (t0 + t1), e = 1e-6 * (t1 - t0), uv2[2];
            sw_sg_curve_eval(&c, tm, uv);
            sw_sg_curve_eval(&c, tm + e, uv2);
            sw_sg_surface_d2 d;
            sw_sg_surface_eval_d2(&s, uv[0], uv[1], &d);
            memcpy(tg->p, d.p, sizeof tg->p);
            cross3(d.du, d.dv, tg->normal);
            if (r->flags & SW_SG_FACE_REVERSED)
                for (int q = 0; q < 3; ++q)
                    tg->normal[q] = -tg->normal[q];
            sw_sg_surface_eval(&s, uv2[0], uv2[1], b);
            for (int q = 0; q < 3; ++q)
                tg->tangent[q] = b[q] - d.p[q];
        }
    }
    normalize3(tg->normal);
    double nt = dot3(tg->normal, tg->tangent);
    for (int q = 0; q < 3; ++q)
        tg->tangent[q] -= nt * tg->normal[q];
    normalize3(tg->tangent);
}

/* Looking at P from 30° off the normal, tilted across the curve, the curve running sideways. */
static void make_camera(const target *tg, double height, frame_check *fc)
{
    double b[3], dir[3], dist = height / (2.0 * tan(k_fovy * M_PI / 360.0));
    cross3(tg->normal, tg->tangent, b);
    double a = k_oblique_deg * M_PI / 180.0;
    memset(&fc->cam, 0, sizeof fc->cam);
    for (int k = 0; k < 3; ++k) {
        dir[k] = cos(a) * tg->normal[k] + sin(a) * b[k];
        fc->cam.target[k] = tg->p[k];
        fc->cam.eye[k] = tg->p[k] + dist * dir[k];
        fc->fwd[k] = -dir[k];
    }
    /* Rolled 17° so that the curve's tangent at P is not aligned with the pixel rows. */
    double side[3], r = 17.0 * M_PI / 180.0;
    cross3(fc->fwd, tg->tangent, side);
    normalize3(side);
    for (int k = 0; k < 3; ++k)
        fc->cam.up[k] = cos(r) * side[k] + sin(r) * tg->tangent[k];
    fc->cam.fovy_deg = k_fovy;
    /* The basis exactly as gpu/camera.c derives it. */
    cross3(fc->fwd, fc->cam.up, fc->right);
    normalize3(fc->right);
    cross3(fc->right, fc->fwd, fc->up);
}

static int run_frame(sw_gpu_context *ctx, const sw_sg_scene *one, uint32_t f0, const target *tg,
                     double height, double diag, int idx, const char *outdir,
                     uint8_t *boundary)
{
    frame_check fc;
    memset(&fc, 0, sizeof fc);
    make_camera(tg, height, &fc);
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = W;
    desc.height = H;
    desc.error_px = 0.5;
    desc.camera = fc.cam;
    desc.want_depth = 1;
    desc.hierarchies = g_cache;
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    sw_status st = {0};
    sw_result r = sw_gpu_render_scene(ctx, one, &desc, &img, &fs, &st);
    if (r != SW_OK) {
        printf("frame %d (height %.6g): %s: %s  <-- FAIL\n", idx, height, sw_result_str(r),
               st.message);
        return 0;
    }
    fc.img = &img;
    fc.boundary = boundary;
    fc.srf = NULL;
    sw_sg_surface srf;
    sw_sg_scene_face_surface(one, f0, &srf);
    fc.srf = &srf;
    mark_boundary(&fc);
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(one);
    const sw_sg_face_rec *rec = &v->faces[f0];
    for (uint32_t l = 0; l < rec->n_loops; ++l)
        for (uint32_t k = 0; k < v->loops[rec->first_loop + l].n_curves; ++k) {
            sw_sg_curve c;
            sw_sg_scene_curve(one, v->loops[rec->first_loop + l].first_curve + k, &c);
            check_curve(&fc, &c);
        }
    int64_t max_tex = ctx->max_texture_size, max_entry = sw__gpu_atlas_max_entry(ctx);
    double page = fs.atlas_pages ? (double)fs.atlas_texels / (double)fs.atlas_pages : 0.0;
    double mean = fs.trim_textures ? (double)fs.trim_texels / (double)fs.trim_textures : 0.0;
    int ok = fc.failed == 0 && fc.checked > 100 && page <= (double)max_tex * (double)max_tex &&
             mean <= (double)max_entry * (double)max_entry && fs.trim_textures > 0 &&
             (!g_cache || fs.hlod_nodes > 0);
    if (g_cache)
        printf("frame %d: %llu hierarchy nodes drawn, %llu refinement rounds\n", idx,
               (unsigned long long)fs.hlod_nodes, (unsigned long long)fs.hlod_refine_rounds);
    printf("frame %d: visible height %.6g (diag / %.0f): %llu trim textures, %llu texels "
           "(atlas %llu pages of %.0f texels; max entry %lld^2, GL max %lld); %lu curve points "
           "checked, %lu hidden; max distance to the coverage boundary %.3f px Chebyshev "
           "(%.3f Euclidean), %lu beyond %.1f px%s\n",
           idx, height, diag / height, (unsigned long long)fs.trim_textures,
           (unsigned long long)fs.trim_texels, (unsigned long long)fs.atlas_pages, page,
           (long long)max_entry, (long long)max_tex, fc.checked, fc.hidden, fc.worst,
           fc.worst_eucl, fc.failed, k_tol_px, ok ? "" : "  <-- FAIL");
    char path[1200];
    snprintf(path, sizeof path, "%s/zoom_%d.png", outdir, idx);
    if (sw_gpu_image_write(&img, path, &st) != SW_OK)
        fprintf(stderr, "write %s: %s\n", path, st.message);
    sw_gpu_image_free(&img);
    return ok;
}

/* The largest trimmed planar face (no seams or poles: its whole trim boundary is an edge). */
static uint32_t pick_face(const sw_sg_scene *scene)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    uint32_t best = SW_SG_NONE;
    double best_ext = 0.0;
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        if (!(v->faces[f].flags & SW_SG_FACE_TRIMMED) || v->faces[f].kind != SW_SG_KIND_PLANE ||
            v->faces[f].n_loops == 0)
            continue;
        double e = face_extent(scene, f);
        if (e > best_ext) {
            best_ext = e;
            best = f;
        }
    }
    return best;
}

int main(int argc, char **argv)
{
    int hierarchy = argc > 1 && strcmp(argv[1], "--hierarchy") == 0;
    argc -= hierarchy;
    argv += hierarchy;
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: %s [--hierarchy] OUTDIR Motor-c.brep [SHIFT_PX]\n", argv[0]);
        return 2;
    }
    if (argc == 4)
        g_shift_px = strtod(argv[3], NULL);
    sw_status st = {0};
    sw_sg_import_desc id = {argv[2], NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL, *one = NULL;
    if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
        fprintf(stderr, "FAIL: import %s: %s\n", argv[2], st.message);
        return 1;
    }
    sw_sg_scene_stats ss;
    sw_sg_scene_compute_stats(scene, &ss);
    const double *b = ss.bbox;
    double diag = sqrt(pow(b[3] - b[0], 2) + pow(b[4] - b[1], 2) + pow(b[5] - b[2], 2));
    uint32_t f = pick_face(scene);
    if (f == SW_SG_NONE || copy_face(scene, f, &one, &st) != SW_OK) {
        fprintf(stderr, "FAIL: no trimmed planar face / copy: %s\n", st.message);
        sw_sg_scene_free(scene);
        return 1;
    }
    target tg;
    pick_target(one, 0, &tg);
    printf("face %u (extent %.4g of model diagonal %.4g, %u loops); P = (%.6g, %.6g, %.6g)\n", f,
           face_extent(scene, f), diag, sw_sg_scene_view_ptr(one)->faces[0].n_loops, tg.p[0],
           tg.p[1], tg.p[2]);
    sw_gpu_context *ctx = NULL;
    uint8_t *boundary = malloc((size_t)W * H);
    if (!boundary || sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", boundary ? st.message : "out of memory");
        free(boundary);
        sw_sg_scene_free(one);
        sw_sg_scene_free(scene);
        return 1;
    }
    int ok = 1;
    sw_th_pool *pool = NULL;
    sw_th_pool_desc pd = {0};
    if (hierarchy && (sw_th_pool_create(&pd, &pool) != SW_OK ||
                      sw_lod_cache_create(one, pool, NULL, &g_cache, &st) != SW_OK)) {
        fprintf(stderr, "FAIL: hierarchy cache: %s\n", st.message);
        ok = 0;
    }
    for (int i = 0; i < N_FRAMES && ok; ++i)
        ok = run_frame(ctx, one, 0, &tg, diag * pow(10.0, -4.0 * i / (N_FRAMES - 1)), diag, i,
                       argv[1], boundary) &&
             ok;
    sw_lod_cache_destroy(g_cache);
    sw_th_pool_destroy(pool);
    sw_gpu_context_free(ctx);
    free(boundary);
    sw_sg_scene_free(one);
    sw_sg_scene_free(scene);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

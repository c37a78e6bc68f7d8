/* bench/degrees — Guthe et al. 2005 §9, Fig. 10: approximation time and tessellation time of an
 * animated trimmed surface as its degree grows. A 10 x 10 rational B-spline surface (degrees
 * 3x3, 5x5, 7x7, uniform clamped knots) whose control points and weights move by a sine (one
 * period over the measured frames), trimmed by one closed degree-d loop of 10 control points
 * (animated.c). The surface changes every frame, so every frame redoes the whole chain:
 *
 *   approximation  the bicubic hierarchy over the trim region's box (lod/hierarchy.c: extraction,
 *                  G1 reduction, leaf subdivision, median-cut simplification, rigorous bounds,
 *                  derivative constants) and the rational cubic approximation of the trim loop;
 *   scene          the view's cut of the hierarchy as bicubic faces, the loop flattened and
 *                  clipped per face (cut_scene.c; glue a renderer with the hierarchy inside its
 *                  frame path would not need as such, timed apart);
 *   tessellation   sw_gpu_render_scene of that scene (headless GL, llvmpipe on this machine):
 *                  its frame stats' tessellate (CPU: extraction, bounds, grids), trim (trim
 *                  textures, regenerated every frame as in the paper, see render()) and draw
 *                  (upload and draw until glFinish); the readback is not counted.
 *
 * ε_img is split as the paper does (§7): half for the approximation (0.8 of it for the surface,
 * 0.2 for the trim curves: cubic approximation and flattening, through the largest |S_u|, |S_v|),
 * half for sampling (the frame's error_px). Object tolerances follow from the fixed camera
 * (bd_screen: nearest depth, frame-corner obliquity), so a drawn point stays within ε_img.
 * For comparison, the same frame path also draws the degree-d face as it is, without the
 * approximation (its degree > 3 patches are CPU grids), at the full ε_img.
 *
 * Usage: bench_degrees [--frames N (100)] [--size WxH (1024x768)] [--error PX (0.5)]
 *                      [--png PREFIX]   (PREFIX-d<d>-cut.png, -direct.png: last frame's images)
 *                      [--atlas-kept]   (trim atlas left as the frame path keeps it, see render())
 * LP_NUM_THREADS (llvmpipe's threads) is set to 2 unless already set, and printed.
 */
#include "animated.h"
#include "cut_scene.h"
#include "sw_gpu.h"
#include "sw_gpu_internal.h" /* sw__gpu_atlas_invalidate only (trim_atlas.c), see render() */
#include "sw_lod_hierarchy.h"
#include "sw_lod_reduce.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { MAX_FRAMES = 1000 };

/* Per-frame figures, one array of `frames` values each. */
enum metric {
    M_APPROX,        /* approximation ms: hierarchy + trim cubics */
    M_APPROX_TRIM,   /* of which the trim cubics */
    M_LEAF_TOL,      /* the hierarchy's leaf tolerance (object units) */
    M_LEAVES,        /* hierarchy leaves */
    M_NODES,         /* hierarchy nodes */
    M_OVER,          /* cut nodes above their tolerance */
    M_SCENE,         /* ms to make the source and cut scenes */
    M_FACES,         /* faces of the cut scene */
    M_FACES_TRIMMED, /* of which trimmed */
    M_TESS,          /* cut scene's frame stats: ms_tessellate, ms_trim, ms_draw, their sum */
    M_TRIM,
    M_DRAW,
    M_TOTAL,
    M_TRIS,   /* its triangles */
    M_D_TESS, /* the same for the source scene ("direct") */
    M_D_TRIM,
    M_D_DRAW,
    M_D_TOTAL,
    M_D_TRIS,
    M_D_GPU,  /* its patches evaluated in the vertex shader */
    M_D_CPU,  /* its patches drawn as CPU grids */
    M_REUSED, /* trim textures reused (both scenes) */
    M_COUNT
};

typedef struct bench {
    sw_gpu_context *ctx;
    int frames, width, height, atlas_kept;
    double error_px;
    const char *png;
    sw_gpu_camera camera;
    bd_screen screen;
    double *m[M_COUNT];
    double med[3][M_COUNT], max_approx[3]; /* per degree 3, 5, 7 */
} bench;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The trim atlas is emptied before every frame (unless --atlas-kept): the paper regenerates the
 * trim textures every frame, and with a new scene every frame no texture could be reused anyway;
 * left to itself the atlas keeps the unused entries of earlier frames, adding pages (each
 * addition copies every page) until it reaches its texel limit, which puts 100-400 ms spikes into
 * the first tens of frames and makes the degrees' medians depend on their order. The public API
 * has no call for this; sw__gpu_atlas_invalidate is trim_atlas.c's, as in bench/tessellation. */
static int render(bench *b, const sw_sg_scene *scene, double error_px, const char *png,
                  sw_gpu_frame_stats *fs)
{
    if (!b->atlas_kept)
        sw__gpu_atlas_invalidate(b->ctx);
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = b->width;
    desc.height = b->height;
    desc.error_px = error_px;
    desc.camera = b->camera;
    sw_gpu_image img;
    sw_status st = {0};
    if (sw_gpu_render_scene(b->ctx, scene, &desc, &img, fs, &st) != SW_OK) {
        fprintf(stderr, "render: %s\n", st.message);
        return 0;
    }
    if (png && sw_gpu_image_write(&img, png, &st) != SW_OK)
        fprintf(stderr, "%s: %s\n", png, st.message);
    sw_gpu_image_free(&img);
    return 1;
}

/* The leaf tolerance at this frame: the surface's share of ε_img at the control net's nearest
 * depth (a rational surface with positive weights lies in its control points' hull). */
static double leaf_tolerance(const bench *b, const double *cpw)
{
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < BD_N * BD_N; ++i)
        for (int k = 0; k < 3; ++k) {
            box[k] = fmin(box[k], cpw[4 * i + k] / cpw[4 * i + 3]);
            box[3 + k] = fmax(box[3 + k], cpw[4 * i + k] / cpw[4 * i + 3]);
        }
    return bd_screen_tolerance(&b->screen, bd_screen_min_depth(&b->screen, box), 0.4 * b->error_px);
}

/* What one frame produces; freed by frame_free (scenes excepted: the caller keeps them). */
typedef struct frame_out {
    sw_lod_hierarchy *h;
    sw_lod_cubic_set cubics;
    sw_sg_polyline loop;
    int32_t *nodes;
    sw_sg_scene *source, *cut;
    double trim_uv; /* trim tolerance in (u, v), for the cubics and for the flattening each */
} frame_out;

static void frame_free(frame_out *o)
{
    sw_lod_hierarchy_free(o->h);
    sw_lod_cubic_set_free(&o->cubics);
    sw_sg_polyline_free(&o->loop);
    free(o->nodes);
}

/* Approximation (timed): the hierarchy, then the trim loop's cubics at the trim share of ε_img
 * (0.1: a quarter of the surface's 0.4, half of it to the cubics, half to the flattening). */
static int approximate(bench *b, const sw_sg_surface *s, const bd_trim_loop *tl, int i,
                       frame_out *o, sw_status *st)
{
    sw_lod_hierarchy_desc hd;
    memset(&hd, 0, sizeof hd);
    hd.leaf_tolerance = leaf_tolerance(b, s->cpw);
    hd.use_box = 1;
    memcpy(hd.uv_box, tl->box, sizeof hd.uv_box);
    const double t0 = now_ms();
    if (sw_lod_hierarchy_build(s, &hd, &o->h, st) != SW_OK)
        return 0;
    const double t1 = now_ms(), speed = bd_max_parametric_speed(o->h);
    if (!(speed > 0.0)) {
        snprintf(st->message, sizeof st->message, "no representable leaf");
        return 0;
    }
    o->trim_uv = 0.125 * hd.leaf_tolerance / speed;
    sw_lod_reduce_desc rd = {o->trim_uv, 0, {0.0, 0}};
    if (sw_lod_trim_curve_to_cubics(&tl->curve, &rd, &o->cubics, st) != SW_OK)
        return 0;
    const double t2 = now_ms();
    if (i >= 0) {
        b->m[M_APPROX][i] = t2 - t0;
        b->m[M_APPROX_TRIM][i] = t2 - t1;
        b->m[M_LEAF_TOL][i] = hd.leaf_tolerance;
        b->m[M_LEAVES][i] = o->h->n_leaves;
        b->m[M_NODES][i] = o->h->n_nodes;
    }
    return 1;
}

/* The source scene and the view's cut scene (timed apart). */
static int make_scenes(bench *b, const sw_sg_surface *s, const bd_trim_loop *tl, int i,
                       frame_out *o, sw_status *st)
{
    const double t0 = now_ms();
    int32_t n = 0, over = 0;
    bd_cut_counts cc;
    if (bd_source_scene(s, &o->cubics, tl->box, &o->source, st) != SW_OK ||
        sw_sg_trim_flatten_loop(o->source, 0, o->trim_uv, 1u << 22, &o->loop, st) != SW_OK ||
        bd_select_cut(o->h, &b->screen, 0.4 * b->error_px, &o->nodes, &n, &over, st) != SW_OK ||
        bd_cut_scene(o->h, o->nodes, n, &o->loop, &o->cut, &cc, st) != SW_OK)
        return 0;
    if (!(fabs(cc.area_drawn - cc.area_loop) <= 1e-9 * cc.area_loop)) {
        snprintf(st->message, sizeof st->message,
                 "the cut's trimmed faces cover %.17g of the loop's (u, v) area %.17g",
                 cc.area_drawn, cc.area_loop);
        return 0;
    }
    if (i >= 0) {
        b->m[M_SCENE][i] = now_ms() - t0;
        b->m[M_OVER][i] = over;
        b->m[M_FACES][i] = cc.trimmed + cc.untrimmed;
        b->m[M_FACES_TRIMMED][i] = cc.trimmed;
    }
    return 1;
}

static void record_frame(bench *b, int i, const sw_gpu_frame_stats *c, const sw_gpu_frame_stats *d)
{
    double v[] = {
        [M_TESS] = c->ms_tessellate,
        [M_TRIM] = c->ms_trim,
        [M_DRAW] = c->ms_draw,
        [M_TOTAL] = c->ms_tessellate + c->ms_trim + c->ms_draw,
        [M_TRIS] = (double)c->triangles,
        [M_D_TESS] = d->ms_tessellate,
        [M_D_TRIM] = d->ms_trim,
        [M_D_DRAW] = d->ms_draw,
        [M_D_TOTAL] = d->ms_tessellate + d->ms_trim + d->ms_draw,
        [M_D_TRIS] = (double)d->triangles,
        [M_D_GPU] = (double)d->patches_gpu_evaluated,
        [M_D_CPU] = (double)(d->patches_trimmed + d->patches_untrimmed - d->patches_gpu_evaluated),
        [M_REUSED] = (double)(c->trim_reused + d->trim_reused)};
    for (int k = M_TESS; k <= M_REUSED; ++k)
        b->m[k][i] = v[k];
}

/* Frame -1 is a warm-up (shaders, buffers) with frame 0's surface. Every frame's scenes are kept
 * until the degree is done, so that no scene reuses an earlier one's address: the trim atlas
 * keys its textures by scene, and with --atlas-kept a recycled address would reuse a texture by
 * accident of the allocator. */
static int run_degree(bench *b, int d, int slot)
{
    double ku[BD_N + BD_MAX_DEGREE + 1], kv[BD_N + BD_MAX_DEGREE + 1], cpw[BD_N * BD_N * 4];
    bd_clamped_knots(d, ku);
    bd_clamped_knots(d, kv);
    bd_trim_loop tl;
    bd_trim_loop_init(d, &tl);
    sw_sg_scene **keep = calloc(2 * ((size_t)b->frames + 1), sizeof *keep);
    int ok = keep != NULL;
    for (int i = -1; i < b->frames && ok; ++i) {
        bd_animate(i < 0 ? 0 : i, b->frames, cpw);
        const sw_sg_surface s = {d, d, BD_N, BD_N, ku, kv, cpw};
        frame_out o;
        memset(&o, 0, sizeof o);
        sw_status st = {0};
        ok = approximate(b, &s, &tl, i, &o, &st) && make_scenes(b, &s, &tl, i, &o, &st);
        if (!ok)
            fprintf(stderr, "degree %d, frame %d: %s\n", d, i, st.message);
        keep[2 * (i + 1)] = o.source;
        keep[2 * (i + 1) + 1] = o.cut;
        char png[2][512] = {"", ""};
        if (b->png && i == b->frames - 1) {
            snprintf(png[0], sizeof png[0], "%s-d%d-cut.png", b->png, d);
            snprintf(png[1], sizeof png[1], "%s-d%d-direct.png", b->png, d);
        }
        sw_gpu_frame_stats fc, fd;
        ok = ok && render(b, o.cut, 0.5 * b->error_px, png[0][0] ? png[0] : NULL, &fc) &&
             render(b, o.source, b->error_px, png[1][0] ? png[1] : NULL, &fd);
        if (ok && i >= 0)
            record_frame(b, i, &fc, &fd);
        frame_free(&o);
    }
    for (int i = 0; keep && i < 2 * (b->frames + 1); ++i)
        sw_sg_scene_free(keep[i]);
    free(keep);
    if (!ok)
        return 0;
    double mx = 0.0;
    for (int i = 0; i < b->frames; ++i)
        mx = fmax(mx, b->m[M_APPROX][i]);
    b->max_approx[slot] = mx;
    for (int k = 0; k < M_COUNT; ++k)
        b->med[slot][k] = median(b->m[k], b->frames);
    return 1;
}

static void print_tables(const bench *b)
{
    const double *r = b->med[0];
    printf("\napproximation (CPU, every frame: bicubic hierarchy over the trim box + cubic trim "
           "loop), median ms per frame\n");
    printf("degree  leaf tol    approx  (max)   of which trim  leaves  nodes  over tol  x 3x3\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %.2e  %7.3f %7.3f  %7.3f        %6.0f %6.0f  %5.0f     %5.2f\n",
               3 + 2 * s, 3 + 2 * s, m[M_LEAF_TOL], m[M_APPROX], b->max_approx[s], m[M_APPROX_TRIM],
               m[M_LEAVES], m[M_NODES], m[M_OVER], m[M_APPROX] / r[M_APPROX]);
    }
    printf("\ntessellation (sw_gpu_render_scene of the view's cut as bicubic faces, error_px "
           "%.3g), median ms per frame\n",
           0.5 * b->error_px);
    printf("degree  faces (trimmed)  tessellate    trim    draw   total  triangles  x 3x3 | "
           "scene ms\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %5.0f (%5.0f)    %8.2f %7.2f %7.2f %7.2f  %9.0f  %5.2f | %6.2f\n",
               3 + 2 * s, 3 + 2 * s, m[M_FACES], m[M_FACES_TRIMMED], m[M_TESS], m[M_TRIM],
               m[M_DRAW], m[M_TOTAL], m[M_TRIS], m[M_TOTAL] / r[M_TOTAL], m[M_SCENE]);
    }
    printf("\nfor comparison: the degree-d face drawn by the same frame path as it is (no "
           "approximation; degree > 3 patches are CPU grids), error_px %.3g\n",
           b->error_px);
    printf("degree  patches GPU / CPU  tessellate    trim    draw   total  triangles  x 3x3\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %5.0f / %5.0f      %8.2f %7.2f %7.2f %7.2f  %9.0f  %5.2f\n", 3 + 2 * s,
               3 + 2 * s, m[M_D_GPU], m[M_D_CPU], m[M_D_TESS], m[M_D_TRIM], m[M_D_DRAW],
               m[M_D_TOTAL], m[M_D_TRIS], m[M_D_TOTAL] / r[M_D_TOTAL]);
    }
}

static void usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s [--frames 1..%d] [--size WxH] [--error PX] [--png PREFIX] "
            "[--atlas-kept]\n"
            "  medians over --frames frames (100) of one animation period; frame 1024x768;\n"
            "  eps_img --error px (0.5); --png writes the last frame's images; --atlas-kept\n"
            "  leaves the trim atlas across frames (default: emptied before every frame).\n"
            "  LP_NUM_THREADS is set to 2 unless already set.\n",
            argv0, MAX_FRAMES);
}

static int parse(bench *b, int argc, char **argv)
{
    for (int a = 1; a < argc; a += 2) {
        if (strcmp(argv[a], "--atlas-kept") == 0) {
            b->atlas_kept = 1;
            a--;
            continue;
        }
        const char *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (!v)
            return 0;
        if (strcmp(argv[a], "--frames") == 0)
            b->frames = atoi(v);
        else if (strcmp(argv[a], "--size") == 0) {
            if (sscanf(v, "%dx%d", &b->width, &b->height) != 2)
                return 0;
        } else if (strcmp(argv[a], "--error") == 0)
            b->error_px = atof(v);
        else if (strcmp(argv[a], "--png") == 0)
            b->png = v;
        else
            return 0;
    }
    return b->frames >= 1 && b->frames <= MAX_FRAMES && b->width >= 16 && b->width <= 8192 &&
           b->height >= 16 && b->height <= 8192 && b->error_px > 0.0 && b->error_px < 100.0;
}

int main(int argc, char **argv)
{
    static bench b = {.frames = 100, .width = 1024, .height = 768, .error_px = 0.5};
    if (!parse(&b, argc, argv)) {
        usage(argv[0]);
        return 2;
    }
    const int lp_user = getenv("LP_NUM_THREADS") != NULL;
    if (!lp_user)
        setenv("LP_NUM_THREADS", "2", 0);
    for (int k = 0; k < M_COUNT; ++k)
        if (!(b.m[k] = calloc((size_t)b.frames, sizeof *b.m[k])))
            return 1;
    sw_status st = {0};
    if (sw_gpu_context_create_headless(&b.ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    b.camera = bd_camera();
    bd_screen_init(&b.screen, &b.camera, b.width, b.height);
    printf("bench/degrees (Guthe et al. 2005 Fig. 10): %s | LP_NUM_THREADS=%s (%s) | frame %dx%d "
           "| eps_img %.3g px (approximation %.3g: surface %.3g + trim %.3g; sampling %.3g) | "
           "10x10 control points, medians of %d frames (one animation period) | trim atlas %s\n",
           sw_gpu_context_description_ptr(b.ctx), getenv("LP_NUM_THREADS"),
           lp_user ? "from the environment" : "set by the bench", b.width, b.height, b.error_px,
           0.5 * b.error_px, 0.4 * b.error_px, 0.1 * b.error_px, 0.5 * b.error_px, b.frames,
           b.atlas_kept ? "kept across frames" : "emptied before every frame");
    int ok = 1;
    for (int s = 0; s < 3 && ok; ++s)
        ok = run_degree(&b, 3 + 2 * s, s);
    if (ok) {
        print_tables(&b);
        double reused = 0.0;
        for (int s = 0; s < 3; ++s)
            reused += b.med[s][M_REUSED];
        printf("\ntrim textures reused across frames (median per frame, all degrees): %.0f\n",
               reused);
    }
    sw_gpu_context_free(b.ctx);
    for (int k = 0; k < M_COUNT; ++k)
        free(b.m[k]);
    return ok ? 0 : 1;
}

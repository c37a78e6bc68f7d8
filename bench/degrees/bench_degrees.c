/* SPDX-License-Identifier: MIT */
/* bench/degrees — Guthe et al. 2005 §9, Fig. 10: approximation time and tessellation time of an
 * animated trimmed surface as its degree grows. A 10 x 10 rational B-spline surface (degrees
 * 3x3, 5x5, 7x7, uniform clamped knots) whose control points and weights move by a sine (one
 * period over the measured frames), trimmed by one closed degree-d loop of 10 control points
 * (animated.c). The surface changes every frame, so every frame redoes the whole chain:
 *
 *   approximation  the rational cubic approximation of the trim loop (timed here), and the
 *                  bicubic hierarchy over the trim region's box (lod/hierarchy/hierarchy.c:
 * extraction, G1 reduction, leaf subdivision, median-cut simplification, rigorous bounds,
 *                  derivative constants), built in the worker pool by the frame itself from a
 *                  fresh sw_lod_cache of the frame's scene, with any refinement below its leaves
 *                  the view asks for: the frame stats' ms_hierarchy, which runs from the build
 *                  requests to the last refinement's end (gpu/stage_hierarchy.c);
 *   scene          the degree-d face trimmed by the cubic loop, and the empty cache (timed apart);
 *   tessellation   the rest of sw_gpu_render_scene (headless GL, llvmpipe on this machine): its
 *                  frame stats' tessellate (the traversal of the hierarchy, §7, bounds, grids),
 *                  trim (per-node trim textures, §4) and draw (upload and draw until glFinish);
 *                  the readback is not counted.
 *
 * ε_img is split so that a drawn point stays within it (§7): 0.1 of it for the trim loop's cubic
 * approximation (through the surface's largest parametric speed, at the control net's nearest
 * depth for the fixed camera), the rest is the frame's error_px, which gives half of ε_obj to the
 * hierarchy's nodes and the rest to sampling. For comparison, the same frame path also draws the
 * same scene without the hierarchy (desc.hierarchies NULL: the degree-d face as it is, degree > 3
 * patches as CPU grids).
 *
 * Leaf tolerance of the hierarchies (--leaf): "view" (default) asks the builder for leaves fine
 * enough for the whole view at once, the frame's criterion at the control net's nearest depth, so
 * the frame never has to refine; "frame" leaves the builder's default (1e-3 of the net's diagonal)
 * and lets the frame refine the leaves it needs below them (converged: it waits for them).
 *
 * Usage: bench_degrees [--frames N (100)] [--size WxH (1024x768)] [--error PX (0.5)]
 *                      [--leaf view|frame] [--png PREFIX] (PREFIX-d<d>-hlod.png, -direct.png)
 *                      [--atlas-fresh]   (trim atlas emptied before every frame, see render())
 * LP_NUM_THREADS (llvmpipe's threads) is set to 2 unless already set, and printed; the worker pool
 * has its default worker count (one per online processor), printed.
 */
#include "cli_numbers.h"
#include "animated.h"
#include "source_scene.h"
#include "sw_gpu.h"
#include "sw_gpu_internal.h" /* sw__gpu_atlas_invalidate only (trim_atlas.c), see render() */
#include "sw_lod_cache.h"
#include "sw_lod_reduce.h"
#include "sw_th_pool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { MAX_FRAMES = 1000 };

/* ε_img's share of the trim loop's cubic approximation. */
static const double k_trim_share = 0.1;
/* The frame's bound of an occurrence transform's stretch, sqrt(|M|_1 |M|_inf) of its linear part
 * (sw_sg_stretch_bound, scenegraph/bvh.c), is 1 for the identity this scene's node has: the node
 * errors it compares with ε_obj / 2. */
static const double k_frame_stretch = 1.0;

/* Per-frame figures, one array of `frames` values each. */
enum metric {
    M_APPROX,      /* approximation ms: trim cubics + ms_hierarchy */
    M_APPROX_TRIM, /* of which the trim cubics (speed bound included) */
    M_LEAF_TOL,    /* the hierarchy's leaf tolerance (object units) */
    M_LEAVES,      /* hierarchy leaves after the frame (refinements included) */
    M_NODES,       /* hierarchy nodes after the frame */
    M_ROUNDS,      /* refinement rounds the frame waited for */
    M_REFINED,     /* refinements published */
    M_DRAWN,       /* nodes (or parts of one) drawn */
    M_DRAWN_TRIM,  /* of which with a trim texture */
    M_OVER,        /* drawn above their share of ε_img */
    M_SCENE,       /* ms to make the scene and the empty cache */
    M_TESS,        /* hierarchy frame: ms_tessellate, ms_trim, ms_draw, their sum */
    M_TRIM,
    M_DRAW,
    M_TOTAL,
    M_TRIS,   /* its triangles */
    M_PAGES,  /* trim atlas pages after it */
    M_D_TESS, /* the same for the frame without the hierarchy ("direct") */
    M_D_TRIM,
    M_D_DRAW,
    M_D_TOTAL,
    M_D_TRIS,
    M_D_GPU,  /* its patches evaluated in the vertex shader */
    M_D_CPU,  /* its patches drawn as CPU grids */
    M_REUSED, /* trim textures reused (both frames) */
    M_COUNT
};

typedef struct bench {
    sw_gpu_context *ctx;
    sw_th_pool *pool;
    int frames, width, height, atlas_fresh, leaf_frame;
    double error_px;
    const char *png;
    sw_gpu_camera camera;
    bd_screen screen;
    double *m[M_COUNT];
    double med[3][M_COUNT], max[3][M_COUNT]; /* per degree 3, 5, 7 */
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

static double frame_error_px(const bench *b)
{
    return (1.0 - k_trim_share) * b->error_px;
}

/* With --atlas-fresh the trim atlas is emptied before every frame, as the paper regenerates the
 * trim textures every frame; by default it is left to the frame path (with a new scene every frame
 * no texture can be reused, so this measures how the atlas copes with entries that die every
 * frame). The public API has no call for this; sw__gpu_atlas_invalidate is trim_atlas.c's. */
static int render(bench *b, const sw_sg_scene *scene, sw_lod_cache *cache, const char *png,
                  sw_gpu_frame_stats *fs)
{
    if (b->atlas_fresh)
        sw__gpu_atlas_invalidate(b->ctx);
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = b->width;
    desc.height = b->height;
    desc.error_px = frame_error_px(b);
    desc.camera = b->camera;
    desc.hierarchies = cache;
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

/* Nearest view depth of the control net: a rational surface with positive weights lies in its
 * control points' hull. */
static double net_min_depth(const bench *b, const double *cpw)
{
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < BD_N * BD_N; ++i)
        for (int k = 0; k < 3; ++k) {
            box[k] = fmin(box[k], cpw[4 * i + k] / cpw[4 * i + 3]);
            box[3 + k] = fmax(box[3 + k], cpw[4 * i + k] / cpw[4 * i + 3]);
        }
    return bd_screen_min_depth(&b->screen, box);
}

/* --leaf view: what the frame asks of a node at the net's nearest depth (half of ε_obj, over the
 * stretch bound); --leaf frame: 0, the builder's default. */
static double leaf_tolerance(const bench *b, const double *cpw)
{
    if (b->leaf_frame)
        return 0.0;
    const double eps_obj =
        bd_screen_tolerance(&b->screen, net_min_depth(b, cpw), frame_error_px(b));
    return 0.5 * eps_obj / k_frame_stretch;
}

/* The trim loop's cubics (timed): its share of ε_img at the net's nearest depth, through the
 * surface's largest parametric speed over the trim box. */
static int approximate_trim(bench *b, const sw_sg_surface *s, const bd_trim_loop *tl, int i,
                            sw_lod_cubic_set *cubics, sw_status *st)
{
    const double t0 = now_ms(), speed = bd_parametric_speed(s, tl->box);
    if (!(speed > 0.0)) {
        snprintf(st->message, sizeof st->message, "no parametric speed bound (out of memory?)");
        return 0;
    }
    const double tol_obj =
        bd_screen_tolerance(&b->screen, net_min_depth(b, s->cpw), k_trim_share * b->error_px);
    sw_lod_reduce_desc rd = {tol_obj / speed, 0, {0.0, 0}};
    if (sw_lod_trim_curve_to_cubics(&tl->curve, &rd, cubics, st) != SW_OK)
        return 0;
    if (i >= 0)
        b->m[M_APPROX_TRIM][i] = now_ms() - t0;
    return 1;
}

/* The scene and its empty hierarchy cache (timed). */
static int make_scene(bench *b, const sw_sg_surface *s, const bd_trim_loop *tl,
                      const sw_lod_cubic_set *cubics, int i, sw_sg_scene **scene,
                      sw_lod_cache **cache, sw_status *st)
{
    sw_lod_cache_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.hierarchy.leaf_tolerance = leaf_tolerance(b, s->cpw);
    cd.max_readers = 1;
    const double t0 = now_ms();
    if (bd_source_scene(s, cubics, tl->box, scene, st) != SW_OK ||
        sw_lod_cache_create(*scene, b->pool, &cd, cache, st) != SW_OK)
        return 0;
    if (i >= 0)
        b->m[M_SCENE][i] = now_ms() - t0;
    return 1;
}

static void record_frame(bench *b, int i, const sw_lod_cache *cache, const sw_gpu_frame_stats *c,
                         const sw_gpu_frame_stats *d)
{
    const sw_lod_hierarchy *h = sw_lod_cache_get(cache, 0); /* nobody refines it any more */
    sw_lod_cache_stats cs;
    sw_lod_cache_stats_get(cache, &cs);
    double v[] = {
        [M_APPROX] = b->m[M_APPROX_TRIM][i] + c->ms_hierarchy,
        [M_LEAF_TOL] = h ? h->leaf_tolerance : NAN,
        [M_LEAVES] = h ? h->n_leaves : 0,
        [M_NODES] = h ? h->n_nodes : 0,
        [M_ROUNDS] = (double)c->hlod_refine_rounds,
        [M_REFINED] = (double)cs.refinements,
        [M_DRAWN] = (double)c->hlod_nodes,
        [M_DRAWN_TRIM] = (double)c->patches_trimmed,
        [M_OVER] = (double)c->hlod_over_budget,
        [M_TESS] = c->ms_tessellate,
        [M_TRIM] = c->ms_trim,
        [M_DRAW] = c->ms_draw,
        [M_TOTAL] = c->ms_tessellate + c->ms_trim + c->ms_draw,
        [M_TRIS] = (double)c->triangles,
        [M_PAGES] = (double)c->atlas_pages,
        [M_D_TESS] = d->ms_tessellate,
        [M_D_TRIM] = d->ms_trim,
        [M_D_DRAW] = d->ms_draw,
        [M_D_TOTAL] = d->ms_tessellate + d->ms_trim + d->ms_draw,
        [M_D_TRIS] = (double)d->triangles,
        [M_D_GPU] = (double)d->patches_gpu_evaluated,
        [M_D_CPU] = (double)(d->patches_trimmed + d->patches_untrimmed - d->patches_gpu_evaluated),
        [M_REUSED] = (double)(c->trim_reused + d->trim_reused)};
    for (int k = 0; k < M_COUNT; ++k)
        if (k != M_APPROX_TRIM && k != M_SCENE)
            b->m[k][i] = v[k];
}

/* One frame: approximate, make the scene, draw it with and without the hierarchy. */
static int run_frame(bench *b, int d, int i, const sw_sg_surface *s, const bd_trim_loop *tl,
                     sw_sg_scene **scene)
{
    sw_lod_cubic_set cubics;
    memset(&cubics, 0, sizeof cubics);
    sw_lod_cache *cache = NULL;
    sw_status st = {0};
    int ok = approximate_trim(b, s, tl, i, &cubics, &st) &&
             make_scene(b, s, tl, &cubics, i, scene, &cache, &st);
    if (!ok)
        fprintf(stderr, "degree %d, frame %d: %s\n", d, i, st.message);
    char png[2][512] = {"", ""};
    if (b->png && i == b->frames - 1) {
        snprintf(png[0], sizeof png[0], "%s-d%d-hlod.png", b->png, d);
        snprintf(png[1], sizeof png[1], "%s-d%d-direct.png", b->png, d);
    }
    sw_gpu_frame_stats fc, fd;
    ok = ok && render(b, *scene, cache, png[0][0] ? png[0] : NULL, &fc) &&
         render(b, *scene, NULL, png[1][0] ? png[1] : NULL, &fd);
    if (ok && fc.hlod_fallback_faces > 0) {
        fprintf(stderr, "degree %d, frame %d: the face has no hierarchy (%s)\n", d, i,
                sw_lod_cache_failure(cache, 0, &st) != SW_OK ? st.message : "not built");
        ok = 0;
    }
    if (ok && i >= 0)
        record_frame(b, i, cache, &fc, &fd);
    sw_lod_cache_destroy(cache);
    sw_lod_cubic_set_free(&cubics);
    return ok;
}

/* Frame -1 is a warm-up (shaders, buffers) with frame 0's surface. Every frame's scene is kept
 * until the degree is done, so that no scene reuses an earlier one's address: the trim atlas keys
 * its textures by scene, and a recycled address would reuse a texture by accident of the
 * allocator. */
static int run_degree(bench *b, int d, int slot)
{
    double ku[BD_N + BD_MAX_DEGREE + 1], kv[BD_N + BD_MAX_DEGREE + 1], cpw[BD_N * BD_N * 4];
    bd_clamped_knots(d, ku);
    bd_clamped_knots(d, kv);
    bd_trim_loop tl;
    bd_trim_loop_init(d, &tl);
    sw_sg_scene **keep = calloc((size_t)b->frames + 1, sizeof *keep);
    int ok = keep != NULL;
    for (int i = -1; i < b->frames && ok; ++i) {
        bd_animate(i < 0 ? 0 : i, b->frames, cpw);
        const sw_sg_surface s = {d, d, BD_N, BD_N, ku, kv, cpw};
        ok = run_frame(b, d, i, &s, &tl, &keep[i + 1]);
    }
    for (int i = 0; keep && i < b->frames + 1; ++i)
        sw_sg_scene_free(keep[i]);
    free(keep);
    if (!ok)
        return 0;
    for (int k = 0; k < M_COUNT; ++k) {
        double mx = -INFINITY;
        for (int i = 0; i < b->frames; ++i)
            mx = fmax(mx, b->m[k][i]);
        b->max[slot][k] = mx;
        b->med[slot][k] = median(b->m[k], b->frames);
    }
    return 1;
}

static void print_tables(const bench *b)
{
    const double *r = b->med[0];
    printf("\napproximation (CPU, every frame: cubic trim loop + bicubic hierarchy in the pool, "
           "built and refined by the frame), median ms per frame\n");
    printf("degree  leaf tol    approx  (max)   of which trim  leaves  nodes  refine rounds "
           "(refinements)  x 3x3\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %.2e  %7.3f %7.3f  %7.3f        %6.0f %6.0f  %5.0f (%5.0f)           "
               "%5.2f\n",
               3 + 2 * s, 3 + 2 * s, m[M_LEAF_TOL], m[M_APPROX], b->max[s][M_APPROX],
               m[M_APPROX_TRIM], m[M_LEAVES], m[M_NODES], m[M_ROUNDS], m[M_REFINED],
               m[M_APPROX] / r[M_APPROX]);
    }
    printf("\ntessellation (sw_gpu_render_scene through the hierarchy, error_px %.3g), median ms "
           "per frame\n",
           frame_error_px(b));
    printf("degree  nodes (trimmed) over  tessellate    trim (max)     draw   total  triangles  "
           "pages  x 3x3 | scene ms\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %5.0f (%5.0f) %4.0f    %8.2f %7.2f (%6.1f) %7.2f %7.2f  %9.0f  %5.0f  "
               "%5.2f | %6.2f\n",
               3 + 2 * s, 3 + 2 * s, m[M_DRAWN], m[M_DRAWN_TRIM], m[M_OVER], m[M_TESS], m[M_TRIM],
               b->max[s][M_TRIM], m[M_DRAW], m[M_TOTAL], m[M_TRIS], b->max[s][M_PAGES],
               m[M_TOTAL] / r[M_TOTAL], m[M_SCENE]);
    }
    printf("\nfor comparison: the degree-d face unchanged (desc.hierarchies NULL; degree > 3 "
           "patches are CPU grids), error_px %.3g\n",
           frame_error_px(b));
    printf("degree  patches GPU / CPU  tessellate    trim (max)     draw   total  triangles  "
           "x 3x3\n");
    for (int s = 0; s < 3; ++s) {
        const double *m = b->med[s];
        printf("%dx%d     %5.0f / %5.0f      %8.2f %7.2f (%6.1f) %7.2f %7.2f  %9.0f  %5.2f\n",
               3 + 2 * s, 3 + 2 * s, m[M_D_GPU], m[M_D_CPU], m[M_D_TESS], m[M_D_TRIM],
               b->max[s][M_D_TRIM], m[M_D_DRAW], m[M_D_TOTAL], m[M_D_TRIS],
               m[M_D_TOTAL] / r[M_D_TOTAL]);
    }
}

static void usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s [--frames 1..%d] [--size WxH] [--error PX] [--leaf view|frame]\n"
            "          [--png PREFIX] [--atlas-fresh]\n"
            "  medians over --frames frames (100) of one animation period; frame 1024x768;\n"
            "  eps_img --error px (0.5); --leaf: hierarchy leaves fine enough for the view\n"
            "  (default) or the builder's default refined by the frame; --png writes the last\n"
            "  frame's images; --atlas-fresh empties the trim atlas before every frame.\n"
            "  LP_NUM_THREADS is set to 2 unless already set.\n",
            argv0, MAX_FRAMES);
}

static int parse(bench *b, int argc, char **argv)
{
    for (int a = 1; a < argc; a += 2) {
        if (strcmp(argv[a], "--atlas-fresh") == 0) {
            b->atlas_fresh = 1;
            a--;
            continue;
        }
        const char *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (!v)
            return 0;
        if (strcmp(argv[a], "--frames") == 0)
            b->frames = atoi(v);
        else if (strcmp(argv[a], "--size") == 0) {
            if (sw_cli_parse_size(v, &b->width, &b->height))
                return 0;
        } else if (strcmp(argv[a], "--error") == 0) {
            if (sw_cli_parse_error_px(v, &b->error_px))
                return 0;
        } else if (strcmp(argv[a], "--leaf") == 0) {
            if (strcmp(v, "view") != 0 && strcmp(v, "frame") != 0)
                return 0;
            b->leaf_frame = strcmp(v, "frame") == 0;
        } else if (strcmp(argv[a], "--png") == 0)
            b->png = v;
        else
            return 0;
    }
    return b->frames >= 1 && b->frames <= MAX_FRAMES && b->width >= 16 && b->width <= 8192 &&
           b->height >= 16 && b->height <= 8192 && b->error_px > 0.0 && b->error_px < 100.0;
}

static void print_header(const bench *b, int lp_user)
{
    sw_th_pool_desc pd;
    sw_th_pool_desc_defaults(&pd, NULL); /* what sw_th_pool_create(NULL) used */
    printf("bench/degrees (Guthe et al. 2005 Fig. 10): %s | LP_NUM_THREADS=%s (%s) | pool workers "
           "%u | frame %dx%d | eps_img %.3g px (trim cubics %.3g, frame error_px %.3g: nodes "
           "half of it) | leaves: %s | 10x10 control points, medians of %d frames (one animation "
           "period) | trim atlas %s\n",
           sw_gpu_context_description_ptr(b->ctx), getenv("LP_NUM_THREADS"),
           lp_user ? "from the environment" : "set by the bench", (unsigned)pd.worker_count,
           b->width, b->height, b->error_px, k_trim_share * b->error_px, frame_error_px(b),
           b->leaf_frame ? "builder's default, refined by the frame" : "fine enough for the view",
           b->frames, b->atlas_fresh ? "emptied before every frame" : "kept by the frame path");
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
    if (sw_th_pool_create(NULL, &b.pool) != SW_OK) {
        fprintf(stderr, "worker pool could not be created\n");
        return 1;
    }
    if (sw_gpu_context_create_headless(&b.ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        sw_th_pool_destroy(b.pool);
        return 1;
    }
    b.camera = bd_camera();
    bd_screen_init(&b.screen, &b.camera, b.width, b.height);
    print_header(&b, lp_user);
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
    sw_th_pool_destroy(b.pool);
    for (int k = 0; k < M_COUNT; ++k)
        free(b.m[k]);
    return ok ? 0 : 1;
}

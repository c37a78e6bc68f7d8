/* SPDX-License-Identifier: MIT */
/* The trim atlas (gpu/trim_atlas.c, Guthe et al. 2005 §4.4) when the trim textures a frame needs
 * change every frame: an animated scene (a new scene per frame, so no texture of an earlier frame
 * can be reused) seen by a moving camera (resolution classes change too). The atlas must reuse the
 * space of textures no longer used instead of adding pages:
 *
 *   pages   after every frame, the atlas's page count is at most twice the largest count a fresh
 *           atlas needs for any single frame of the sequence (page side limited to 256 texels so
 *           that a frame needs several pages and growth shows);
 *   images  every frame is the same as the frame rendered by a fresh atlas (the same textures at
 *           other places in other pages; texel coordinates are offsets by whole texels, so the
 *           rasterised fans are the same): at most k_max_diff_px pixels differ;
 *   churn   a new array texture is the atlas's dearest step (its pages allocated and, when it
 *           grows, copied), so the kept atlas never gives pages back within the sequence (48
 *           renders, fewer than the idle frames after which it may) and grows by half its pages
 *           at least: at most 1 + log_1.5(pages) allocations;
 *   reuse   the same scene drawn again with the same camera reuses every trim texture
 *           (trim_reused == trim_textures) and gives the identical image: textures are kept
 *           across frames while their resolution class is unchanged.
 *
 * Scene of frame f: a row of N_FACES wavy bicubic faces, each trimmed by a star whose radii and
 * rotation move with f. Camera: along the row, its distance oscillating (one period per run).
 *
 * Usage: test_gpu_atlas_churn [OUTDIR]   (unused; ctest passes the binary directory)
 */
#include "sw_gpu_internal.h"
#include "gpu_test_compare.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 480, H = 320, N_FRAMES = 24, N_FACES = 8, STAR_N = 9, PAGE_SIDE = 256 };
/* Pixels allowed to differ from the fresh atlas's frame. The same loops rasterised at other whole-
 * texel offsets can only differ where float rounding of a vertex's clip coordinate moves an edge
 * across a texel centre: a handful of texels along trim edges, a few pixels each. A misplaced or
 * stale texture (wrong rectangle, wrong layer, texels of a dead entry) changes whole faces. */
static const long k_max_diff_px = 16;

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "FAIL %s: %s\n", what, st ? st->message : "");
    return 1;
}

/* Star of face i at frame f in the face's [0,1]^2, closed (first vertex repeated). */
static void star(int f, int i, double *uv, double box[4])
{
    const double ph = 2.0 * M_PI * f / N_FRAMES;
    const double ro = 0.42 + 0.05 * sin(ph + i), ri = 0.22 + 0.08 * cos(2.0 * ph - i);
    box[0] = box[2] = 1.0;
    box[1] = box[3] = 0.0;
    for (int k = 0; k <= 2 * STAR_N; ++k) {
        const double r = (k % 2) ? ri : ro, a = ph * (i % 2 ? 1 : -1) + M_PI * k / STAR_N;
        uv[2 * k] = 0.5 + r * cos(a);
        uv[2 * k + 1] = 0.5 + r * sin(a);
        box[0] = fmin(box[0], uv[2 * k]), box[1] = fmax(box[1], uv[2 * k]);
        box[2] = fmin(box[2], uv[2 * k + 1]), box[3] = fmax(box[3], uv[2 * k + 1]);
    }
}

/* The star as one closed degree-1 curve (clamped uniform knots). */
static uint32_t add_star_loop(sw_sg_builder *b, const double *uv)
{
    enum { N = 2 * STAR_N + 1 };
    double knots[N + 2], cpw[3 * N];
    for (int k = 0; k < N + 2; ++k)
        knots[k] = k == 0 ? 0.0 : k == N + 1 ? 1.0 : (double)(k - 1) / (N - 1);
    for (int k = 0; k < N; ++k)
        cpw[3 * k] = uv[2 * k], cpw[3 * k + 1] = uv[2 * k + 1], cpw[3 * k + 2] = 1.0;
    sw_sg_curve_rec c = {1, N, sw_sg_builder_push_doubles(b, knots, N + 2),
                         sw_sg_builder_push_doubles(b, cpw, 3 * N)};
    sw_sg_loop_rec l = {sw_sg_builder_add_curve(b, &c), 1, SW_SG_LOOP_OUTER, 0};
    return sw_sg_builder_add_loop(b, &l);
}

static void add_face(sw_sg_builder *b, int f, int i)
{
    static const double knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    static const float color[4] = {0.8f, 0.7f, 0.5f, 1.0f};
    double cpw[64], uv[2 * (2 * STAR_N + 1)];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            double *p = cpw + 4 * (4 * r + c);
            p[0] = 1.2 * i + c / 3.0;
            p[1] = r / 3.0;
            p[2] = 0.25 * sin(1.3 * c + 0.7 * r + i + 0.2 * f);
            p[3] = 1.0;
        }
    sw_sg_face_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.deg_u = rec.deg_v = 3;
    rec.n_u = rec.n_v = 4;
    rec.knots_u = sw_sg_builder_push_doubles(b, knots, 8);
    rec.knots_v = sw_sg_builder_push_doubles(b, knots, 8);
    rec.cpw = sw_sg_builder_push_doubles(b, cpw, 64);
    rec.kind = SW_SG_KIND_BSPLINE;
    rec.flags = SW_SG_FACE_TRIMMED;
    star(f, i, uv, rec.uv_box);
    rec.first_loop = add_star_loop(b, uv);
    rec.n_loops = 1;
    rec.tolerance = 1e-7;
    uint32_t face = sw_sg_builder_add_face(b, &rec);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, color, NULL);
}

static sw_result make_scene(int f, sw_sg_scene **out, sw_status *st)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return SW_ERR_OUT_OF_MEMORY;
    for (int i = 0; i < N_FACES; ++i)
        add_face(b, f, i);
    return sw_sg_builder_finish(b, out, st);
}

static sw_gpu_frame_desc frame_desc(int f)
{
    const double ph = 2.0 * M_PI * f / N_FRAMES, cx = 0.6 * N_FACES - 0.1;
    const double dist = 5.0 + 3.0 * sin(ph);
    sw_gpu_frame_desc d;
    memset(&d, 0, sizeof d);
    d.width = W;
    d.height = H;
    d.error_px = 0.5;
    d.camera = (sw_gpu_camera){{cx + 0.3 * dist * cos(ph), 0.5 - 0.6 * dist, 0.8 * dist},
                               {cx + 1.5 * sin(ph), 0.5, 0.0},
                               {0.0, 0.0, 1.0},
                               40.0};
    return d;
}

static sw_result render(sw_gpu_context *ctx, const sw_sg_scene *scene, int f, sw_gpu_image *img,
                        sw_gpu_frame_stats *fs, sw_status *st)
{
    sw_gpu_frame_desc d = frame_desc(f);
    return sw_gpu_render_scene(ctx, scene, &d, img, fs, st);
}

typedef struct run {
    sw_gpu_context *ctx;
    sw_sg_scene *scenes[N_FRAMES];
    sw_gpu_image kept[N_FRAMES];
    uint64_t pages_kept[N_FRAMES], pages_fresh[N_FRAMES];
    uint64_t allocations; /* array textures the kept atlas allocated over the sequence */
    int shrank;           /* the kept atlas had fewer pages after a render than before it */
    long diff[N_FRAMES];
} run;

/* The sequence through one atlas kept across frames; each frame drawn twice (reuse check). */
static int run_kept(run *r)
{
    sw_status st = {0};
    sw__gpu_atlas_set_max_side(r->ctx, PAGE_SIDE);
    int ok = 1;
    uint64_t last_pages = 0;
    for (int f = 0; f < N_FRAMES && ok; ++f) {
        sw_gpu_frame_stats a, b;
        sw_gpu_image again;
        if (render(r->ctx, r->scenes[f], f, &r->kept[f], &a, &st) != SW_OK ||
            render(r->ctx, r->scenes[f], f, &again, &b, &st) != SW_OK)
            return fail("render (kept atlas)", &st);
        sw_test_image_diff d = sw_test_compare_images(&r->kept[f], &again, 0);
        r->pages_kept[f] = b.atlas_pages > a.atlas_pages ? b.atlas_pages : a.atlas_pages;
        r->allocations += a.atlas_allocations + b.atlas_allocations;
        r->shrank |= a.atlas_pages < last_pages || b.atlas_pages < a.atlas_pages;
        last_pages = b.atlas_pages;
        if (a.trim_textures == 0 || a.trim_reused != 0 || b.trim_reused != b.trim_textures ||
            d.any != 0) {
            fprintf(stderr,
                    "FAIL frame %d: %llu trim textures, %llu reused from the previous scene, "
                    "drawn again: %llu of %llu reused, %ld pixels differ\n",
                    f, (unsigned long long)a.trim_textures, (unsigned long long)a.trim_reused,
                    (unsigned long long)b.trim_reused, (unsigned long long)b.trim_textures, d.any);
            ok = 0;
        }
        sw_gpu_image_free(&again);
    }
    return ok ? 0 : 1;
}

/* Every frame again through a fresh atlas: the pages one frame needs, and the image. */
static int run_fresh(run *r)
{
    sw_status st = {0};
    for (int f = 0; f < N_FRAMES; ++f) {
        sw__gpu_atlas_free(r->ctx);
        sw__gpu_atlas_set_max_side(r->ctx, PAGE_SIDE);
        sw_gpu_frame_stats fs;
        sw_gpu_image img;
        if (render(r->ctx, r->scenes[f], f, &img, &fs, &st) != SW_OK)
            return fail("render (fresh atlas)", &st);
        r->pages_fresh[f] = fs.atlas_pages;
        r->diff[f] = sw_test_compare_images(&r->kept[f], &img, 0).any;
        sw_gpu_image_free(&img);
    }
    return 0;
}

static int check(const run *r)
{
    uint64_t need = 0, most = 0;
    long worst = 0;
    for (int f = 0; f < N_FRAMES; ++f) {
        need = r->pages_fresh[f] > need ? r->pages_fresh[f] : need;
        most = r->pages_kept[f] > most ? r->pages_kept[f] : most;
        worst = r->diff[f] > worst ? r->diff[f] : worst;
        printf("frame %2d: pages kept %2llu, fresh %llu; pixels differing from fresh %ld\n", f,
               (unsigned long long)r->pages_kept[f], (unsigned long long)r->pages_fresh[f],
               r->diff[f]);
    }
    printf("pages: at most %llu kept, %llu for one frame; pixels differing at most %ld; %llu "
           "array textures allocated\n",
           (unsigned long long)most, (unsigned long long)need, worst,
           (unsigned long long)r->allocations);
    const double max_allocations = 1.0 + ceil(log((double)most) / log(1.5));
    int ok = need >= 2 && most <= 2 * need && worst <= k_max_diff_px && !r->shrank &&
             (double)r->allocations <= max_allocations;
    if (r->shrank || (double)r->allocations > max_allocations)
        fprintf(stderr, "FAIL the kept atlas %s, %llu array textures allocated (at most %.0f)\n",
                r->shrank ? "gave pages back" : "kept its pages",
                (unsigned long long)r->allocations, max_allocations);
    if (need < 2)
        fprintf(stderr, "FAIL the frames fit one page: the test would not see growth\n");
    return ok;
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    static run r;
    sw_status st = {0};
    for (int f = 0; f < N_FRAMES; ++f)
        if (make_scene(f, &r.scenes[f], &st) != SW_OK)
            return fail("scene", &st);
    if (sw_gpu_context_create_headless(&r.ctx, &st) != SW_OK)
        return fail("context", &st);
    printf("context: %s\n", sw_gpu_context_description_ptr(r.ctx));
    int ok = run_kept(&r) == 0 && run_fresh(&r) == 0 && check(&r);
    for (int f = 0; f < N_FRAMES; ++f) {
        sw_gpu_image_free(&r.kept[f]);
        sw_sg_scene_free(r.scenes[f]);
    }
    sw_gpu_context_free(r.ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

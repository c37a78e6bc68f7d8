/* SPDX-License-Identifier: MIT */
/* bench/gpu_frames: per-stage frame times of sw_gpu_render_scene (Guthe et al. 2005 §4.2, §4.4)
 * on imported models, iso view fitted to the scene box, medians over N frames:
 *   regen  every trim texture regenerated each frame in the same atlas pages (as the paper does)
 *   kept   the atlas kept across frames (walkthrough: textures reused while their class holds)
 *   cpu    as kept, but every patch tessellated as a CPU grid instead of evaluated in the vertex
 *          shader (§4.2; degree > 3 patches are CPU grids in both)
 *   cull   as kept, with back-patch culling of closed-shell faces by their normal cones (Kumar
 *          et al. 1997 §4.4; the cones' one-off build time is printed apart)
 * Usage: bench_gpu_frames [--frames N] [--size WxH] FILE...   (set LP_NUM_THREADS and say so)
 */
#include "cli_numbers.h"
#include "sw_gpu_internal.h"
#include "sw_lod_face_cones.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FRAMES 64

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static sw_gpu_camera iso_camera(const double b[6])
{
    static const double from[3] = {1, 1, 1}, up[3] = {0, 0, 1};
    sw_gpu_camera c;
    sw_gpu_camera_fit_box(b, from, up, &c);
    return c;
}

typedef struct series {
    double tess[MAX_FRAMES], trim[MAX_FRAMES], draw[MAX_FRAMES], total[MAX_FRAMES];
    sw_gpu_frame_stats last;
} series;

static int run(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_gpu_frame_desc *desc,
               int frames, int regen, series *s)
{
    for (int i = 0; i < frames; ++i) {
        if (regen)
            sw__gpu_atlas_invalidate(ctx);
        sw_gpu_image img;
        sw_status st = {0};
        if (sw_gpu_render_scene(ctx, scene, desc, &img, &s->last, &st) != SW_OK) {
            fprintf(stderr, "render: %s\n", st.message);
            return 0;
        }
        sw_gpu_image_free(&img);
        const sw_gpu_frame_stats *f = &s->last;
        s->tess[i] = f->ms_tessellate;
        s->trim[i] = f->ms_trim;
        s->draw[i] = f->ms_draw;
        s->total[i] = f->ms_tessellate + f->ms_trim + f->ms_draw;
    }
    return 1;
}

static void print(const char *what, series *s, int frames)
{
    const sw_gpu_frame_stats *f = &s->last;
    printf(
        "  %-6s tessellate %7.2f  trim %7.2f  draw %7.2f  total %7.2f ms | %llu faces drawn "
        "(%llu back-culled), %llu triangles, "
        "%llu shader-evaluated patches, %llu trim textures (%llu reused, %.1f Mtexels), %llu atlas "
        "pages (%.1f Mtexels), %llu switches\n",
        what, median(s->tess, frames), median(s->trim, frames), median(s->draw, frames),
        median(s->total, frames), (unsigned long long)f->faces_drawn,
        (unsigned long long)f->faces_backculled, (unsigned long long)f->triangles,
        (unsigned long long)f->patches_gpu_evaluated, (unsigned long long)f->trim_textures,
        (unsigned long long)f->trim_reused, f->trim_texels * 1e-6,
        (unsigned long long)f->atlas_pages, f->atlas_texels * 1e-6,
        (unsigned long long)f->atlas_switches);
}

int main(int argc, char **argv)
{
    int frames = 9, w = 1280, h = 720, first = 1;
    for (; first < argc && argv[first][0] == '-'; first += 2) {
        if (first + 1 >= argc)
            return 2;
        if (strcmp(argv[first], "--frames") == 0)
            frames = atoi(argv[first + 1]);
        else if (strcmp(argv[first], "--size") == 0 && sw_cli_parse_size(argv[first + 1], &w, &h))
            w = 0; /* refused below */
    }
    if (frames < 1 || frames > MAX_FRAMES || first >= argc) {
        fprintf(stderr, "usage: %s [--frames 1..%d] [--size WxH] FILE...\n", argv[0], MAX_FRAMES);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    const char *lp = getenv("LP_NUM_THREADS");
    printf("%s, LP_NUM_THREADS=%s, %dx%d, medians of %d frames\n",
           sw_gpu_context_description_ptr(ctx), lp ? lp : "(unset)", w, h, frames);
    int ok = 1;
    for (int a = first; a < argc && ok; ++a) {
        sw_sg_import_desc id = {argv[a], NULL, NULL, NULL, NULL, 0};
        sw_sg_scene *scene = NULL;
        if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
            fprintf(stderr, "%s: %s\n", argv[a], st.message);
            ok = 0;
            break;
        }
        sw_sg_scene_stats ss;
        sw_sg_scene_compute_stats(scene, &ss);
        sw_gpu_frame_desc desc;
        memset(&desc, 0, sizeof desc);
        desc.width = w;
        desc.height = h;
        desc.camera = iso_camera(ss.bbox);
        printf("%s (%u faces):\n", argv[a], ss.faces);
        series s;
        ok = run(ctx, scene, &desc, 1, 0, &s); /* warm-up: shaders, buffers */
        if (ok && run(ctx, scene, &desc, frames, 1, &s))
            print("regen", &s, frames);
        if (ok && run(ctx, scene, &desc, frames, 0, &s))
            print("kept", &s, frames);
        sw__gpu_set_eval_mode(ctx, SW__GPU_EVAL_CPU_GRIDS);
        if (ok && run(ctx, scene, &desc, frames, 0, &s))
            print("cpu", &s, frames);
        sw__gpu_set_eval_mode(ctx, SW__GPU_EVAL_AUTO);
        sw_lod_face_cones *fc = NULL;
        const double t0 = sw__clock_ms();
        if (ok && sw_lod_face_cones_build(scene, &fc, &st) != SW_OK) {
            fprintf(stderr, "%s: face cones: %s\n", argv[a], st.message);
            ok = 0;
        }
        if (ok) {
            printf("  cones: %u of %u faces bounded, built in %.1f ms\n", fc->n_bounded,
                   fc->n_faces, sw__clock_ms() - t0);
            desc.face_cones = fc;
            if (run(ctx, scene, &desc, frames, 0, &s))
                print("cull", &s, frames);
            desc.face_cones = NULL;
        }
        sw_lod_face_cones_free(fc);
        sw_sg_scene_free(scene);
    }
    sw_gpu_context_free(ctx);
    return ok ? 0 : 1;
}

/* SPDX-License-Identifier: MIT */
/* GPU evaluation (Guthe et al. 2005 §4.2) against CPU grids: imported models rendered twice in the
 * same context, once with every patch tessellated on the CPU in double (patch_grid.c, the
 * reference) and once with patches of degree <= 3 x 3 evaluated in the vertex shader on the
 * predefined grids (higher degrees stay CPU grids: both paths run in the second frame, and the
 * test requires each to draw patches over the set of models). Both use the same Filip densities
 * (the GPU path rounds them up to a grid class), trim atlas and shading. A pixel differs when its
 * coverage differs or a colour channel differs by more than k_color_tol levels (float vs double
 * normals); at most 0.1 % of the pixels covered by either may differ, per view.
 *
 * Since the two paths share densities, atlas and extraction, each view is also drawn at a quarter
 * of the size by both paths (fat borders off) and compared with an independent reference
 * (gpu_test_reference.h: a dense mesh of the exact NURBS with exact trims, drawn as plain
 * triangles): at most 4 + 0.1 % of the covered pixels may have a coverage found nowhere within
 * 1 px in the reference, or a depth off the reference's on its smooth interiors. What it catches
 * (each planted and seen failing while the two paths still agreed, 0.0000 % differ):
 * densities a quarter of what the bound asks (lod/bezier/sampling.c sw_lod_screen_segments) — all 6
 * views fail, 169-1696 depth errors and up to 98 coverage errors (limits 8-11); the trim atlas
 * read 2 texel rows off (gpu/glsl/surface_trim.frag.glsl) — 4 of 6 views fail, 13-38 depth errors.
 *
 * Usage: test_gpu_eval OUTDIR WIDTHxHEIGHT FILE...
 */
#include "gpu_test_compare.h"
#include "gpu_test_reference.h"
#include "sw_gpu_internal.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const int k_color_tol = 8;

static int render(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_gpu_frame_desc *desc,
                  sw__gpu_eval_mode mode, sw_gpu_image *img, sw_gpu_frame_stats *fs)
{
    sw_status st = {0};
    sw__gpu_set_eval_mode(ctx, mode);
    if (sw_gpu_render_scene(ctx, scene, desc, img, fs, &st) != SW_OK) {
        fprintf(stderr, "render: %s\n", st.message);
        return 0;
    }
    return 1;
}

/* CPU grids (way 0) or the default vertex-shader evaluation (way 1). */
static int draw_way(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_gpu_frame_desc *desc,
                    int way, sw_gpu_image *img, sw_gpu_frame_stats *fs)
{
    return render(ctx, scene, desc, way ? SW__GPU_EVAL_AUTO : SW__GPU_EVAL_CPU_GRIDS, img, fs);
}

/* Both paths at a quarter of the view's size against the independent reference. */
static int reference_view(sw_gpu_context *ctx, const sw_sg_scene *scene,
                          const sw_gpu_frame_desc *full, const char *prefix, int iso)
{
    static const char *const names[2] = {"cpu_grids", "gpu"};
    return sw_test_ref_view(ctx, scene, full, prefix, iso, draw_way, names);
}

typedef struct totals {
    unsigned long long gpu_patches, cpu_patches;
} totals;

static int run_view(sw_gpu_context *ctx, const sw_sg_scene *scene, const double box[6], int iso,
                    int w, int h, const char *prefix, totals *tot)
{
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = w;
    desc.height = h;
    desc.camera = sw_test_view_camera(box, iso);
    sw_gpu_image cpu, gpu;
    sw_gpu_frame_stats fc, fg;
    if (!render(ctx, scene, &desc, SW__GPU_EVAL_CPU_GRIDS, &cpu, &fc))
        return 0;
    if (!render(ctx, scene, &desc, SW__GPU_EVAL_AUTO, &gpu, &fg)) {
        sw_gpu_image_free(&cpu);
        return 0;
    }
    size_t n = (size_t)w * (size_t)h;
    sw_test_image_diff df = sw_test_compare_images(&cpu, &gpu, k_color_tol);
    long covered = df.covered, differ = df.differ, cover_differ = df.cover_differ, any = df.any;
    unsigned long long drawn = fg.patches_trimmed + fg.patches_untrimmed;
    tot->gpu_patches += fg.patches_gpu_evaluated;
    tot->cpu_patches += drawn - fg.patches_gpu_evaluated;
    double frac = (double)differ / (double)(covered ? covered : 1);
    printf("%s %s %dx%d: %llu patches drawn, %llu evaluated in the vertex shader; triangles "
           "cpu %llu gpu %llu; ms cpu (tess %.1f draw %.1f) gpu (tess %.1f draw %.1f)\n"
           "  %ld covered, %ld differ (%.4f %%; coverage %ld, any difference %ld)\n",
           prefix, iso ? "iso" : "front", w, h, drawn, (unsigned long long)fg.patches_gpu_evaluated,
           (unsigned long long)fc.triangles, (unsigned long long)fg.triangles, fc.ms_tessellate,
           fc.ms_draw, fg.ms_tessellate, fg.ms_draw, covered, differ, 100.0 * frac, cover_differ,
           any);
    char path[1024];
    sw_status st = {0};
    snprintf(path, sizeof path, "%s_%s_gpu_eval.png", prefix, iso ? "iso" : "front");
    int ok = sw_gpu_image_write(&gpu, path, &st) == SW_OK;
    sw_gpu_image_free(&cpu);
    sw_gpu_image_free(&gpu);
    ok = ok && reference_view(ctx, scene, &desc, prefix, iso);
    return ok && frac <= 0.001 && covered > (long)n / 50;
}

int main(int argc, char **argv)
{
    int w = 0, h = 0;
    if (argc < 4 || sscanf(argv[2], "%dx%d", &w, &h) != 2 || w < 16 || h < 16) {
        fprintf(stderr, "usage: %s OUTDIR WIDTHxHEIGHT FILE...\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    int ok = 1;
    totals tot = {0, 0};
    for (int a = 3; a < argc; ++a) {
        sw_sg_import_desc id = {argv[a], NULL, NULL, NULL, NULL, 0};
        sw_sg_scene *scene = NULL;
        if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
            fprintf(stderr, "import %s: %s\n", argv[a], st.message);
            ok = 0;
            continue;
        }
        sw_sg_scene_stats ss;
        sw_sg_scene_compute_stats(scene, &ss);
        const char *base = strrchr(argv[a], '/');
        char prefix[1024];
        snprintf(prefix, sizeof prefix, "%s/%s", argv[1], base ? base + 1 : argv[a]);
        ok &= run_view(ctx, scene, ss.bbox, 1, w, h, prefix, &tot);
        ok &= run_view(ctx, scene, ss.bbox, 0, w, h, prefix, &tot);
        sw_sg_scene_free(scene);
    }
    printf("patches over all views: %llu evaluated in the vertex shader, %llu as CPU grids\n",
           tot.gpu_patches, tot.cpu_patches);
    ok &= tot.gpu_patches > 0 && tot.cpu_patches > 0;
    sw_gpu_context_free(ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

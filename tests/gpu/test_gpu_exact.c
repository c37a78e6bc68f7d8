/* SPDX-License-Identifier: MIT */
/* Exact evaluation (eval_exact: NURBS evaluated in the vertex shader from knot vectors and
 * control points, any degree up to 15) against the Bézier path (Guthe et al. 2005 §4.2: extracted
 * rational Bézier patches of degree <= 3 in the vertex shader, higher degrees as CPU grids in
 * double). Both render the same models in the same context with the same densities, trim atlas
 * and shading; a pixel differs when its coverage differs or a colour channel differs by more than
 * k_color_tol levels; at most 0.1 % of the pixels covered by either may differ, per view. The
 * exact path must really be used: every drawn patch counted in patches_exact, and over the models
 * some face of degree > 3 (which the Bézier path draws on the CPU) must be drawn exactly.
 *
 * Since the two paths share densities and atlas, each view is also drawn at a quarter of the size
 * by both paths (fat borders off) and compared with an independent reference
 * (gpu_test_reference.h: a dense mesh of the exact NURBS with exact trims, drawn as plain
 * triangles): at most 4 + 0.1 % of the covered pixels may have a coverage found nowhere within
 * 1 px in the reference, or a depth off the reference's on its smooth interiors. What it catches
 * (each planted and seen failing): densities a quarter of what the bound asks
 * (lod/bezier/sampling.c sw_lod_screen_segments) — all 6 views fail against the reference, while
 * the two paths disagreed on 2 of them only; the trim atlas read 2 texel rows off
 * (gpu/glsl/surface_trim.frag.glsl) — 4 of 6 views fail, while the two paths agreed on all.
 *
 * Usage: test_gpu_exact OUTDIR WIDTHxHEIGHT FILE...
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
                  int exact, sw_gpu_image *img, sw_gpu_frame_stats *fs)
{
    sw_status st = {0};
    sw_gpu_frame_desc d = *desc;
    d.eval_exact = exact;
    if (sw_gpu_render_scene(ctx, scene, &d, img, fs, &st) != SW_OK) {
        fprintf(stderr, "render (%s): %s\n", exact ? "exact" : "bezier", st.message);
        return 0;
    }
    return 1;
}

/* Both paths at a quarter of the view's size against the independent reference. */
static int reference_view(sw_gpu_context *ctx, const sw_sg_scene *scene,
                          const sw_gpu_frame_desc *full, const char *prefix, int iso)
{
    static const char *const names[2] = {"bezier", "exact"};
    return sw_test_ref_view(ctx, scene, full, prefix, iso, render, names);
}

static int run_view(sw_gpu_context *ctx, const sw_sg_scene *scene, const double box[6], int iso,
                    int w, int h, const char *prefix)
{
    sw_gpu_frame_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.width = w;
    desc.height = h;
    desc.camera = sw_test_view_camera(box, iso);
    sw_gpu_image bez, ex;
    sw_gpu_frame_stats fb, fe;
    if (!render(ctx, scene, &desc, 0, &bez, &fb))
        return 0;
    if (!render(ctx, scene, &desc, 1, &ex, &fe)) {
        sw_gpu_image_free(&bez);
        return 0;
    }
    size_t n = (size_t)w * (size_t)h;
    sw_test_image_diff df = sw_test_compare_images(&bez, &ex, k_color_tol);
    long covered = df.covered, differ = df.differ, cover_differ = df.cover_differ;
    unsigned long long drawn = fe.patches_trimmed + fe.patches_untrimmed;
    double frac = (double)differ / (double)(covered ? covered : 1);
    printf("%s %s %dx%d: %llu patches drawn, %llu exact (bezier path: %llu in the vertex shader); "
           "triangles bezier %llu exact %llu; ms bezier (tess %.1f draw %.1f) exact (tess %.1f "
           "draw %.1f)\n  %ld covered, %ld differ (%.4f %%; coverage %ld)\n",
           prefix, iso ? "iso" : "front", w, h, drawn, (unsigned long long)fe.patches_exact,
           (unsigned long long)fb.patches_gpu_evaluated, (unsigned long long)fb.triangles,
           (unsigned long long)fe.triangles, fb.ms_tessellate, fb.ms_draw, fe.ms_tessellate,
           fe.ms_draw, covered, differ, 100.0 * frac, cover_differ);
    char path[1024];
    sw_status st = {0};
    snprintf(path, sizeof path, "%s_%s_exact.png", prefix, iso ? "iso" : "front");
    int ok = sw_gpu_image_write(&ex, path, &st) == SW_OK;
    sw_gpu_image_free(&bez);
    sw_gpu_image_free(&ex);
    ok = ok && fe.patches_exact == drawn && drawn > 0 && fb.patches_exact == 0;
    ok = ok && reference_view(ctx, scene, &desc, prefix, iso);
    return ok && frac <= 0.001 && covered > (long)n / 50;
}

/* Highest degree (max of u and v) over the scene's faces. */
static int max_degree(const sw_sg_scene *scene)
{
    const sw_sg_scene_view *sv = sw_sg_scene_view_ptr(scene);
    int m = 0;
    for (uint32_t i = 0; i < sv->n_faces; ++i) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(scene, i, &s);
        m = s.deg_u > m ? s.deg_u : m;
        m = s.deg_v > m ? s.deg_v : m;
    }
    return m;
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
    int ok = 1, top = 0;
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
        int md = max_degree(scene);
        top = md > top ? md : top;
        printf("%s: highest face degree %d\n", argv[a], md);
        const char *base = strrchr(argv[a], '/');
        char prefix[1024];
        snprintf(prefix, sizeof prefix, "%s/%s", argv[1], base ? base + 1 : argv[a]);
        ok &= run_view(ctx, scene, ss.bbox, 1, w, h, prefix);
        ok &= run_view(ctx, scene, ss.bbox, 0, w, h, prefix);
        sw_sg_scene_free(scene);
    }
    printf("highest degree over the models: %d\n", top);
    ok &= top > 3;
    sw_gpu_context_free(ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

/* SPDX-License-Identifier: MIT */
/* splinewalk render SCENE -o FRAME.png [...] */
#include "cli.h"

#include "sw_rt.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk render SCENE -o FRAME.png [--size 1280x720] [--view iso|front|top|right]\n"
    "                         [--camera ex,ey,ez,tx,ty,tz,ux,uy,uz,fovy] [--error PX]\n"
    "                         [--eval hierarchy|bezier|exact] [--[no-]static-lod] [--lod-colors]\n"
    "                         [--static-force K] [--no-proxies] [--no-occlusion] "
    "[--no-exact-edges]\n"
    "                         [--partial] [--no-kept-grids] [--memory-budget HOST[,GPU]]\n"
    "\n"
    "Renders one converged frame of SCENE (.sws, or any file `import` reads, imported on the fly)\n"
    "headlessly through EGL (Mesa's llvmpipe when there is no GPU) and writes it as PNG, or as "
    "EXR\n"
    "with a depth channel when FRAME ends in .exr. Prints how many patches were drawn trimmed by\n"
    "trim textures, untrimmed, and culled, and how long each step took. A CAD file's faces "
    "skipped\n"
    "or repaired by the import are each named in a warning on stderr and counted (as `import`\n"
    "does); a truncated IGES file is refused unless --partial. An EXR carries the capture date,\n"
    "or SOURCE_DATE_EPOCH's (seconds since 1970, UTC) when that is set: the same frame then\n"
    "gives the same bytes.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   image to write (.png or .exr; required)\n"
    "  --size WxH          frame size in pixels (default 1280x720)\n"
    "  --view NAME         camera preset fitted to the bounding box (default iso): fovy 40°,\n"
    "                      target = box centre, distance = diagonal / (2 tan 20°) x 1.1;\n"
    "                      iso from (+1,+1,+1) up +Z, front from -Y up +Z, top from +Z up +Y,\n"
    "                      right from +X up +Z\n"
    "  --camera LIST       eye, target, up and vertical field of view in degrees (overrides "
    "--view)\n"
    "  --error PX          screen-space error bound in pixels, at least 0.01 (default 0.5)\n"
    "  --eval MODE         hierarchy (default): each face drawn from its hierarchy of rational\n"
    "                      bicubic patches (Guthe et al. 2005), nodes as coarse as the error\n"
    "                      allows, built in a worker pool and evaluated in the vertex shader;\n"
    "                      bezier: each face by its own rational Bézier patches, degree <= 3\n"
    "                      in the vertex shader, higher degrees on the CPU; exact: every patch\n"
    "                      evaluated in the vertex shader from its knot vectors and control\n"
    "                      points (Krishnamurthy & Yasui), degree <= 15\n"
    "  --static-lod        super-surfaces far enough for one of their static LODs (Kumar et\n"
    "                      al. 1997) are drawn from it; the clustering and the levels are built\n"
    "                      first (or read from the scene's LOD cache: `build-lod`). The default\n"
    "                      when SCENE has a LOD cache; without one it is off (building the\n"
    "                      levels costs more than they save in one frame)\n"
    "  --no-static-lod     every face by the per-frame path, LOD cache or not\n"
    "  --no-proxies        (with static LODs from a LOD cache) no cluster proxies: by default\n"
    "                      groups of far super-surface instances, across objects, are drawn as\n"
    "                      one merged mesh whose certified error is within the bound\n"
    "  --lod-colors        colour each surface by how it is drawn: static levels fine to coarse\n"
    "                      blue, teal, green, yellow, orange, pink; per-frame tessellation grey,\n"
    "                      violet where cut by exact trim edges; cluster proxies red\n"
    "  --static-force K    (with --static-lod; inspection of the joins) super-surface i at choice\n"
    "                      (i + K) mod (n + 1) of its n levels good enough for the view, the last\n"
    "                      choice meaning per-frame: neighbours at different levels\n"
    "  --no-occlusion      draw what the visible planar faces hide too (by default it is culled\n"
    "                      before it is tessellated, by a depth map of those faces on the\n"
    "                      visibility thread; the image is the same)\n"
    "  --no-exact-edges    trim textures only (Guthe et al. 2005 §4). By default a trimmed\n"
    "                      surface whose trim texture would show texels over a quarter pixel is\n"
    "                      cut per fragment against its trim loops, flattened to an eighth of a\n"
    "                      pixel, instead (exact edges in close-ups, no large textures)\n"
    "  --no-kept-grids     every patch grid evaluated in the frame from control points sent\n"
    "                      with it (Guthe et al. 2005 §4.2). By default a grid is evaluated\n"
    "                      once into GPU memory and drawn again while the view asks for its\n"
    "                      density or one up to twice as coarse (the same image, within\n"
    "                      rounding; a frame of `render` is the first, so nothing is reused)\n"
    "  --partial           import what is whole of a truncated file (see `import "
    "--help`)\n" SW_CLI_MEMORY_BUDGET_HELP "  -h, --help          this text\n";

typedef struct render_args {
    const char *scene, *out;
    sw_frame_desc frame;
    sw_view_preset view;
    int has_camera;
    uint32_t load_flags;
    sw_renderer_desc renderer;
} render_args;

static int parse_args(int argc, char **argv, render_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if (!strcmp(arg, "--partial")) {
            a->load_flags |= SW_LOAD_PARTIAL;
            continue;
        }
        if (!strcmp(arg, "--occlusion") || !strcmp(arg, "--no-occlusion")) {
            a->frame.occlusion_culling = !strcmp(arg, "--occlusion");
            continue;
        }
        if (!strcmp(arg, "--static-lod") || !strcmp(arg, "--no-static-lod")) {
            a->frame.static_lods = !strcmp(arg, "--static-lod");
            continue;
        }
        if (!strcmp(arg, "--no-proxies")) {
            a->frame.no_proxies = 1;
            continue;
        }
        if (!strcmp(arg, "--lod-colors")) {
            a->frame.lod_colors = 1;
            continue;
        }
        if (!strcmp(arg, "--no-kept-grids")) {
            a->frame.no_kept_grids = 1;
            continue;
        }
        if (!strcmp(arg, "--exact-edges") || !strcmp(arg, "--no-exact-edges")) {
            a->frame.trim_edges = !strcmp(arg, "--exact-edges");
            continue;
        }
        if (!strcmp(arg, "--static-force") && val) {
            bad = sw_cli_parse_count(val, 1, 1 << 20, &a->frame.static_force);
        } else if (!strcmp(arg, "--memory-budget") && val) {
            bad = sw_cli_parse_memory_budget(val, &a->renderer.memory_budget_host,
                                             &a->renderer.memory_budget_gpu);
        } else if ((!strcmp(arg, "-o") || !strcmp(arg, "--output")) && val) {
            a->out = val;
        } else if (!strcmp(arg, "--size") && val) {
            bad = sw_cli_parse_size(val, &a->frame.width, &a->frame.height);
        } else if (!strcmp(arg, "--view") && val) {
            bad = sw_rt_view_parse(val, &a->view);
        } else if (!strcmp(arg, "--camera") && val) {
            bad = sw_cli_parse_camera(val, &a->frame.camera);
            a->has_camera = 1;
        } else if (!strcmp(arg, "--eval") && val) {
            bad = strcmp(val, "hierarchy") != 0 && strcmp(val, "bezier") != 0 &&
                  strcmp(val, "exact") != 0;
            a->frame.eval_exact = strcmp(val, "exact") == 0;
            a->frame.no_hierarchy = strcmp(val, "bezier") == 0;
        } else if (!strcmp(arg, "--error") && val) {
            bad = sw_cli_parse_error_px(val, &a->frame.error_px);
        } else if (arg[0] != '-' && !a->scene) {
            a->scene = arg;
            continue;
        } else {
            fprintf(stderr, "splinewalk render: unexpected argument '%s'\n%s", arg, k_usage);
            return 2;
        }
        if (bad) {
            return sw_cli_bad_value("render", arg, val, k_usage);
        }
        i++;
    }
    if (!a->scene || !a->out) {
        fprintf(stderr, "splinewalk render: need SCENE and -o FRAME\n%s", k_usage);
        return 2;
    }
    return 0;
}

int sw_cli_render(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    render_args a = {0};
    a.view = SW_VIEW_ISO;
    a.frame.occlusion_culling = 1;
    a.frame.trim_edges = 1;
    a.frame.static_lods = -1; /* not given: from the scene's LOD cache when it has one */
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;

    if (sw_cli_check_output("render", a.out, 0))
        return 1;
    sw_status status = {0};
    double t0 = sw__clock_ms();
    sw_scene scene;
    if (sw_cli_load_scene(a.scene, a.load_flags, &scene, &status) != SW_OK)
        return sw_cli_report_load("render", &status);
    double t1 = sw__clock_ms();
    sw_scene_info load_info;
    int have_info = sw_scene_get_info(scene, &load_info, NULL) == SW_OK;
    if (have_info)
        sw_cli_print_import_notes(stdout, "render", &load_info);
    /* One converged frame: building the levels first would cost more than they save, so by
     * default they are used only when the file brings them. */
    if (a.frame.static_lods < 0)
        a.frame.static_lods = have_info && load_info.lod_cache_bytes > 0;
    sw_renderer renderer = {0};
    sw_frame_stats stats = {0};
    a.frame.scene = scene;
    a.frame.output_path = a.out;
    sw_result r = SW_OK;
    if (!a.has_camera)
        r = sw_camera_fit(scene, a.view, &a.frame.camera, &status);
    if (r == SW_OK)
        r = sw_renderer_create(&a.renderer, &renderer, &status);
    double t2 = sw__clock_ms();
    if (r == SW_OK)
        r = sw_renderer_draw(renderer, &a.frame, &stats, &status);
    /* which GL and EGL platform drew it: llvmpipe, or which GPU */
    char gl[256] = "";
    char budget[256] = "";
    if (renderer.id) {
        snprintf(gl, sizeof gl, "%s", sw_renderer_description_ptr(renderer));
        sw_cli_memory_budget_line(renderer, budget, sizeof budget);
    }
    if (renderer.id)
        sw_renderer_destroy(renderer);
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("render", &status);
    printf("%s -> %s (%dx%d, error %.3g px)\n", a.scene, a.out,
           a.frame.width ? a.frame.width : SW_DEFAULT_WIDTH,
           a.frame.height ? a.frame.height : SW_DEFAULT_HEIGHT,
           a.frame.error_px > 0 ? a.frame.error_px : SW_DEFAULT_ERROR_PX);
    printf("load %.0f ms, GL context %.0f ms (%s)\n", t1 - t0, t2 - t1, gl);
    printf("%s", budget);
    sw_cli_print_frame_stats("frame", &stats);
    return 0;
}

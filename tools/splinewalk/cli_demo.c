/* SPDX-License-Identifier: MIT */
/* splinewalk demo: the built-in default scene, imported, saved, reloaded and rendered headlessly.
 */
#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static const char k_usage[] =
    "usage: splinewalk demo [-o DIR] [--data DIR] [--size WxH] [--error PX]\n"
    "\n"
    "Builds the built-in default scene from OpenCASCADE's sample models (the MODERN_* kitchen\n"
    "furniture in Room.brep, a chair instanced twice, Motor-c.brep on the table), writes it as\n"
    "DIR/default.sws, maps it back, and renders four converged frames headlessly (iso, front, top\n"
    "and a view from inside the room) into DIR/*.png, printing what was drawn and how long each\n"
    "step took. A build without the import module (a bundle, scripts/bundle) renders the copy\n"
    "its bundle ships (share/splinewalk/default.sws) instead: the same frames.\n"
    "\n"
    "options:\n"
    "  -o, --output DIR   where the scene and frames go (default demo-out)\n"
    "  --data DIR         OpenCASCADE sample data (default /usr/share/opencascade/data)\n"
    "  --size WxH         frame size (default 1280x720)\n"
    "  --error PX         screen-space error bound in pixels, at least 0.01 (default 0.5)\n"
    "  -h, --help         this text\n";

typedef struct demo_args {
    const char *dir, *data;
    int32_t width, height;
    double error_px;
} demo_args;

static int parse_args(int argc, char **argv, demo_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) && val)
            a->dir = val;
        else if (!strcmp(argv[i], "--data") && val)
            a->data = val;
        else if (!strcmp(argv[i], "--size") && val)
            bad = sw_cli_parse_size(val, &a->width, &a->height);
        else if (!strcmp(argv[i], "--error") && val)
            bad = sw_cli_parse_error_px(val, &a->error_px);
        else {
            fprintf(stderr, "splinewalk demo: unexpected argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
        if (bad) {
            return sw_cli_bad_value("demo", argv[i], val, NULL);
        }
        i++;
    }
    return 0;
}

typedef struct demo_view {
    const char *name;
    int preset; /* sw_view_preset, or -1 for the fixed interior camera */
} demo_view;

static const demo_view k_views[] = {
    {"iso", SW_VIEW_ISO}, {"front", SW_VIEW_FRONT}, {"top", SW_VIEW_TOP}, {"inside", -1}};

/* Standing in the room's south-east corner at eye height, looking at the table. */
static const sw_camera k_inside = {{380.0, 20.0, 160.0}, {190.0, 230.0, 50.0}, {0, 0, 1}, 60.0};

static int render_views(sw_scene scene, const demo_args *a)
{
    sw_status status = {0};
    sw_renderer renderer;
    double t0 = sw__clock_ms();
    if (sw_renderer_create(NULL, &renderer, &status) != SW_OK)
        return sw_cli_report("demo", &status);
    printf("GL context: %s (%.0f ms)\n", sw_renderer_description_ptr(renderer),
           sw__clock_ms() - t0);
    int rc = 0;
    for (size_t i = 0; i < sizeof k_views / sizeof k_views[0] && !rc; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.png", a->dir, k_views[i].name);
        sw_frame_desc frame = {0};
        frame.scene = scene;
        frame.width = a->width;
        frame.height = a->height;
        frame.error_px = a->error_px;
        frame.output_path = path;
        frame.occlusion_culling = 1;
        frame.trim_edges = 1;
        frame.camera = k_inside;
        sw_result r = SW_OK;
        if (k_views[i].preset >= 0)
            r = sw_camera_fit(scene, (sw_view_preset)k_views[i].preset, &frame.camera, &status);
        sw_frame_stats stats = {0};
        if (r == SW_OK)
            r = sw_renderer_draw(renderer, &frame, &stats, &status);
        if (r != SW_OK) {
            rc = sw_cli_report("demo", &status);
            break;
        }
        sw_cli_print_frame_stats(path, &stats);
    }
    sw_renderer_destroy(renderer);
    return rc;
}

static int make_dir(const char *dir)
{
    if (mkdir(dir, 0777) == 0 || errno == EEXIST)
        return 0;
    fprintf(stderr, "splinewalk demo: cannot create %s: %s\n", dir, strerror(errno));
    return 1;
}

/* Maps the scene file, prints what it holds and renders the views. */
static int show(const char *sws, const demo_args *a, double t0)
{
    sw_status status = {0};
    sw_scene scene;
    sw_scene_info info;
    const double t2 = sw__clock_ms();
    if (sw_cli_load_scene(sws, 0, &scene, &status) != SW_OK ||
        sw_scene_get_info(scene, &info, &status) != SW_OK)
        return sw_cli_report("demo", &status);
    printf("map + verify %s %.0f ms\n", sws, sw__clock_ms() - t2);
    printf("scene: %u surfaces (%u trimmed, %u trim loops), %llu Bézier patches, %u instances, "
           "%llu surfaces drawn, %.1f MiB\n",
           info.faces, info.trimmed_faces, info.loops, (unsigned long long)info.bezier_patches,
           info.instances, (unsigned long long)info.face_occurrences,
           (double)info.memory_bytes / (1024.0 * 1024.0));
    const int rc = render_views(scene, a);
    sw_scene_destroy(scene);
    if (!rc)
        printf("frames in %s/ (total %.1f s)\n", a->dir, (sw__clock_ms() - t0) / 1e3);
    return rc;
}

int sw_cli_demo(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    demo_args a = {"demo-out", NULL, SW_DEFAULT_WIDTH, SW_DEFAULT_HEIGHT, SW_DEFAULT_ERROR_PX};
    int rc = parse_args(argc, argv, &a);
    if (rc || make_dir(a.dir))
        return rc ? rc : 1;
    const double t0 = sw__clock_ms();
#if !SW_CLI_IMPORT
    /* No importer to build it with: a bundle's prebuilt copy (with its LOD cache) */
    char bundled[4096];
    if (!a.data && sw_cli_bundle_path("default.sws", bundled, sizeof bundled)) {
        printf("the default scene as the bundle ships it\n");
        return show(bundled, &a, t0);
    }
#endif
    sw_status status = {0};
    sw_scene built;
    printf("building the default scene from %s\n", a.data ? a.data : "/usr/share/opencascade/data");
    sw_scene_load_desc desc = {NULL, sw_cli_progress, sw_cli_warning, NULL, NULL, 0};
    sw_result r = sw_scene_load_default(a.data, &desc, &built, &status);
    sw_cli_progress_end();
    if (r != SW_OK)
        return sw_cli_report("demo", &status);
    const double t1 = sw__clock_ms();
    char sws[4096];
    snprintf(sws, sizeof sws, "%s/default.sws", a.dir);
    r = sw_scene_save(built, sws, &status);
    sw_scene_destroy(built);
    if (r != SW_OK)
        return sw_cli_report("demo", &status);
    printf("import %.0f ms, write %s %.0f ms\n", t1 - t0, sws, sw__clock_ms() - t1);
    return show(sws, &a, t0);
}

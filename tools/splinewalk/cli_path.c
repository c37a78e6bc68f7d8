/* SPDX-License-Identifier: MIT */
/* splinewalk path orbit|fly|walk SCENE -o PATH: writes a stock camera path fitted to a scene. */
#include "cli.h"

#include "sw_camera_path.h"
#include "sw_safe_write.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk path orbit|fly|walk SCENE -o PATH [--frames N] [--seconds S]\n"
    "                                              [--eye-height H]\n"
    "\n"
    "Writes a camera path (docs/camera-path.md) fitted to SCENE's bounding box, for\n"
    "`splinewalk profile --path PATH`. +Z is up, as for the view presets.\n"
    "  orbit  16 keys on a closed circle around the box centre, 25 degrees above it, at the\n"
    "         distance of the iso preset, looking at the centre (fovy 40)\n"
    "  fly    a low pass through the box along its longer horizontal side: the eye at 30 %\n"
    "         of the box height, weaving sideways, looking a quarter of the run ahead (fovy 60)\n"
    "  walk   the same pass with the eye --eye-height above the box's bottom: through the\n"
    "         ground floor's rooms of a building\n"
    "\n"
    "options:\n"
    "  -o, --output PATH   the path file to write (replaced whole or not at all; - is standard\n"
    "                      output)\n"
    "  --frames N          frames a profiling run takes along the path by default (default 120)\n"
    "  --seconds S         duration of the path in seconds (default 10)\n"
    "  --eye-height H      walk: the eye's height above the scene's lowest point, in scene\n"
    "                      units (default 160: 1.6 m in the generated building's centimetres)\n"
    "  -h, --help          this text\n";

typedef struct path_args {
    const char *kind, *scene, *out;
    int frames;
    double seconds, eye_height;
} path_args;

static int parse_args(int argc, char **argv, path_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if ((!strcmp(arg, "-o") || !strcmp(arg, "--output")) && val) {
            a->out = val;
        } else if (!strcmp(arg, "--frames") && val) {
            bad = sw_cli_parse_count(val, 1, (int)SW_RT_PATH_MAX_FRAMES, &a->frames);
        } else if (!strcmp(arg, "--seconds") && val) {
            bad = sw_cli_parse_positive(val, &a->seconds);
        } else if (!strcmp(arg, "--eye-height") && val) {
            bad = sw_cli_parse_positive(val, &a->eye_height);
        } else if (arg[0] != '-' && (!a->kind || !a->scene)) {
            if (!a->kind)
                a->kind = arg;
            else
                a->scene = arg;
            continue;
        } else {
            fprintf(stderr, "splinewalk path: unexpected argument '%s'\n%s", arg, k_usage);
            return 2;
        }
        if (bad) {
            return sw_cli_bad_value("path", arg, val, k_usage);
        }
        i++;
    }
    if (!a->kind || !a->scene || !a->out) {
        fprintf(stderr, "splinewalk path: need orbit|fly|walk, SCENE and -o PATH\n%s", k_usage);
        return 2;
    }
    if (strcmp(a->kind, "orbit") != 0 && strcmp(a->kind, "fly") != 0 &&
        strcmp(a->kind, "walk") != 0) {
        fprintf(stderr, "splinewalk path: unknown path kind '%s' (orbit, fly or walk)\n%s", a->kind,
                k_usage);
        return 2;
    }
    return 0;
}

int sw_cli_path(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    path_args a = {0};
    a.frames = 120;
    a.seconds = 10.0;
    a.eye_height = 160.0;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;
    if (sw_cli_check_output("path", a.out, SW__OUT_DASH_STDOUT))
        return 1;

    sw_status status = {0};
    sw_scene scene;
    if (sw_cli_load_scene(a.scene, 0, &scene, &status) != SW_OK)
        return sw_cli_report("path", &status);
    sw_scene_info info;
    sw_result r = sw_scene_get_info(scene, &info, &status);
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("path", &status);
    const double box[6] = {info.bbox_min[0], info.bbox_min[1], info.bbox_min[2],
                           info.bbox_max[0], info.bbox_max[1], info.bbox_max[2]};
    sw_rt_camera_path path;
    if (!strcmp(a.kind, "orbit"))
        r = sw_rt_path_orbit(box, a.seconds, (uint32_t)a.frames, &path, &status);
    else if (!strcmp(a.kind, "fly"))
        r = sw_rt_path_fly(box, a.seconds, (uint32_t)a.frames, &path, &status);
    else
        r = sw_rt_path_walk(box, a.eye_height, a.seconds, (uint32_t)a.frames, &path, &status);
    if (r == SW_OK)
        r = sw_rt_path_save(&path, a.out, SW__OUT_DASH_STDOUT, &status);
    const uint32_t keys = path.n_keys;
    sw_rt_path_free(&path);
    if (r != SW_OK)
        return sw_cli_report("path", &status);
    /* with -o - the path itself is on standard output */
    fprintf(strcmp(a.out, "-") ? stdout : stderr, "%s: %s of %s, %u keys over %g s, %d frames\n",
            a.out, a.kind, a.scene, keys, a.seconds, a.frames);
    return 0;
}

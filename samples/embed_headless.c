/* SPDX-License-Identifier: MIT */
/* embed_headless: the smallest program that embeds splinewalk without a window. It loads a scene
 * (a .sws file, anything `splinewalk import` reads, or the built-in default scene), fits the iso
 * camera preset to it, renders one converged frame headlessly (EGL; Mesa's llvmpipe when there
 * is no GPU) and writes it as PNG. Written only against the installed public API: the core
 * (.sws and .tsm files, PNG frames) and the import module, which it installs so that it also reads
 * STEP, IGES and BREP files and builds the default scene:
 *
 *   cc embed_headless.c $(pkg-config --cflags --libs splinewalk splinewalk-import)
 *
 * or, with CMake, find_package(splinewalk COMPONENTS import) and link splinewalk::splinewalk and
 * splinewalk::import.
 * The image equals `splinewalk render SCENE --view iso --size WxH` (tests/consumer checks it).
 * Exit status: 0 success, 1 a failure (reported on stderr), 2 a usage error. */
#include <splinewalk/splinewalk.h>
#include <splinewalk/sw_import.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char k_usage[] =
    "usage: embed_headless [SCENE] [-o FRAME.png] [--size WxH]\n"
    "\n"
    "Renders SCENE (.sws, .step, .iges, .brep or .tsm; without it, the built-in default scene\n"
    "built from OpenCASCADE's sample data) in converged mode from the iso camera preset, "
    "headlessly,\n"
    "and writes FRAME.png. Prints the camera in `splinewalk render --camera` syntax.\n"
    "\n"
    "options:\n"
    "  -o FILE       image to write (default embed_headless.png)\n"
    "  --size WxH    frame size in pixels (default 1280x720)\n"
    "  -h, --help    this text\n";

typedef struct args {
    const char *scene; /* NULL: the default scene */
    const char *out;
    int width, height;
} args;

static int parse_size(const char *text, int *w, int *h)
{
    char x, rest;
    return sscanf(text, "%d%c%d%c", w, &x, h, &rest) == 3 && (x == 'x' || x == 'X') && *w > 0 &&
           *h > 0 && *w <= 16384 && *h <= 16384;
}

/* Returns -1 when the arguments are good, else the exit status. */
static int parse_args(int argc, char **argv, args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(k_usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "-o") && val) {
            a->out = argv[++i];
        } else if (!strcmp(argv[i], "--size") && val && parse_size(val, &a->width, &a->height)) {
            i++;
        } else if (argv[i][0] != '-' && !a->scene) {
            a->scene = argv[i];
        } else {
            fprintf(stderr, "embed_headless: bad argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    return -1;
}

static void progress(void *user_data, double fraction, const char *stage)
{
    (void)user_data;
    fprintf(stderr, "  %3d%% %s\n", (int)(fraction * 100.0), stage ? stage : "");
}

static void warning(void *user_data, const char *message)
{
    (void)user_data;
    fprintf(stderr, "warning: %s\n", message);
}

static int fail(const char *what, const sw_status *status)
{
    fprintf(stderr, "embed_headless: %s: %s (%s): %s\n", what, sw_result_str(status->result),
            sw_result_id_str(status->result), status->message);
    return 1;
}

/* Renders the loaded scene; the renderer's GL context lives on this thread only. */
static int render(sw_scene scene, const args *a)
{
    sw_status status = {0};
    sw_frame_desc frame = {0}; /* zero = default: error 0.5 px, Bézier evaluation path */
    frame.scene = scene;
    frame.width = a->width;
    frame.height = a->height;
    frame.output_path = a->out;
    if (sw_camera_fit(scene, SW_VIEW_ISO, &frame.camera, &status) != SW_OK)
        return fail("camera", &status);
    sw_renderer renderer;
    if (sw_renderer_create(NULL, &renderer, &status) != SW_OK)
        return fail("renderer", &status);
    sw_frame_stats stats;
    sw_result r = sw_renderer_draw(renderer, &frame, &stats, &status);
    printf("GL: %s\n", sw_renderer_description_ptr(renderer));
    sw_renderer_destroy(renderer);
    if (r != SW_OK)
        return fail("draw", &status);
    const sw_camera *c = &frame.camera;
    printf("camera: %.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", c->eye[0],
           c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2], c->up[0], c->up[1],
           c->up[2], c->fovy_deg);
    printf("%s: %dx%d, %llu faces, %llu triangles, %.1f ms\n", a->out, a->width, a->height,
           (unsigned long long)stats.faces_drawn, (unsigned long long)stats.triangles,
           stats.ms_total);
    return 0;
}

int main(int argc, char **argv)
{
    args a = {NULL, "embed_headless.png", 1280, 720};
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0)
        return rc;
    sw_status status = {0};
    (void)sw_import_install(); /* CAD files and the default scene */
    sw_scene_load_desc load = {a.scene, progress, warning, NULL, NULL, 0};
    sw_scene scene;
    sw_result r = a.scene ? sw_scene_load(&load, &scene, &status)
                          : sw_scene_load_default(NULL, &load, &scene, &status);
    if (r != SW_OK)
        return fail(a.scene ? a.scene : "default scene", &status);
    rc = render(scene, &a);
    sw_scene_destroy(scene);
    return rc;
}

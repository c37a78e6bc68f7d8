/* SPDX-License-Identifier: MIT */
/* splinewalk import IN -o OUT.sws */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk import IN -o OUT.sws\n"
    "\n"
    "Imports a STEP (.step/.stp), IGES (.iges/.igs) or OpenCASCADE BREP (.brep) file: every face\n"
    "becomes a NURBS surface with its trim loops, assemblies become instances, colours and face\n"
    "adjacency are kept. A T-spline (.tsm, docs/tspline-format.md) becomes its rational bicubic\n"
    "Bézier patches. Writes the native scene file OUT.sws (to a temporary name, then renamed).\n"
    "A face that cannot be converted is named in a warning and counted, never dropped silently.\n"
    "A progress bar is drawn on stderr.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   the .sws file to write (required)\n"
    "  -h, --help          this text\n";

int sw_cli_import(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (sw_cli_is_help(argv[i])) {
            fputs(k_usage, stdout);
            return 0;
        } else if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) && i + 1 < argc) {
            out = argv[++i];
        } else if (argv[i][0] != '-' && !in) {
            in = argv[i];
        } else {
            fprintf(stderr, "splinewalk import: unexpected argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    if (!in || !out) {
        fprintf(stderr, "splinewalk import: need IN and -o OUT.sws\n%s", k_usage);
        return 2;
    }
    if (sw_cli_check_output("import", out, 0))
        return 1;
    sw_status status = {0};
    sw_scene scene;
    double t0 = sw_cli_now_ms();
    if (sw_cli_load_scene(in, &scene, &status) != SW_OK)
        return sw_cli_report("import", &status);
    double t1 = sw_cli_now_ms();
    sw_scene_info info;
    sw_result r = sw_scene_get_info(scene, &info, &status);
    if (r == SW_OK)
        r = sw_scene_save(scene, out, &status);
    double t2 = sw_cli_now_ms();
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("import", &status);
    printf("%s -> %s: %u faces (%u trimmed), %llu Bézier patches, %u instances; "
           "import %.0f ms, write %.0f ms\n",
           in, out, info.faces, info.trimmed_faces, (unsigned long long)info.bezier_patches,
           info.instances, t1 - t0, t2 - t1);
    return 0;
}

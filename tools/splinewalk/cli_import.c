/* SPDX-License-Identifier: MIT */
/* splinewalk import IN -o OUT.sws */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk import IN -o OUT.sws [--partial]\n"
    "\n"
    "Imports a STEP (.step/.stp), IGES (.iges/.igs) or OpenCASCADE BREP (.brep) file: every face\n"
    "becomes a NURBS surface with its trim loops, assemblies become instances, colours and face\n"
    "adjacency are kept. A T-spline (.tsm, docs/tspline-format.md) becomes its rational bicubic\n"
    "Bézier patches. Writes the native scene file OUT.sws (to a temporary name, then renamed).\n"
    "A face that cannot be drawn exactly (a zero weight, weights too far apart, a trim loop that\n"
    "does not close, a face OCCT could not read) is repaired where an exact repair exists, else\n"
    "skipped: each is named in a warning with the file, the face and the reason, counted on the\n"
    "summary line, and the rest of the file is imported (exit 0). A truncated IGES file (its\n"
    "Terminate record missing or disagreeing with its records) is refused (exit 1,\n"
    "SW_ERR_TRUNCATED) unless --partial is given. A progress bar is drawn on stderr.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   the .sws file to write (required)\n"
    "  --partial           import what is whole of a truncated IGES file: the shapes whose\n"
    "                      data, and the data of every entity they point at, is present (a\n"
    "                      truncated STEP or BREP file cannot be read in part: refused still)\n"
    "  -h, --help          this text\n";

int sw_cli_import(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    uint32_t flags = 0;
    for (int i = 1; i < argc; i++) {
        if (sw_cli_is_help(argv[i])) {
            fputs(k_usage, stdout);
            return 0;
        } else if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(argv[i], "--partial")) {
            flags |= SW_LOAD_PARTIAL;
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
    double t0 = sw__clock_ms();
    if (sw_cli_load_scene(in, flags, &scene, &status) != SW_OK)
        return sw_cli_report_load("import", &status);
    double t1 = sw__clock_ms();
    sw_scene_info info;
    sw_result r = sw_scene_get_info(scene, &info, &status);
    if (r == SW_OK)
        r = sw_scene_save(scene, out, &status);
    double t2 = sw__clock_ms();
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("import", &status);
    printf("%s -> %s: %u faces (%u trimmed), %llu Bézier patches, %u instances; "
           "import %.0f ms, write %.0f ms\n",
           in, out, info.faces, info.trimmed_faces, (unsigned long long)info.bezier_patches,
           info.instances, t1 - t0, t2 - t1);
    sw_cli_print_import_notes(stdout, "import", &info);
    return 0;
}

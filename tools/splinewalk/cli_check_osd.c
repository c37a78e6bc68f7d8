/* SPDX-License-Identifier: MIT */
/* splinewalk check-osd [SCENE...] [--generated N] [--samples K] [--tolerance T] */
#include "cli.h"

#include "sw_lod_osd.h"
#include "sw_lod_osd_check.h"
#include "sw_rt.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk check-osd [SCENE...] [--generated N] [--samples K] [--tolerance T]\n"
    "\n"
    "Cross-checks the project's B-spline evaluation against OpenSubdiv. Every uniform,\n"
    "non-rational bicubic B-spline region (a knot span whose six surrounding knots are equally\n"
    "spaced in u and in v, on a face with equal weights) of each SCENE, and of N generated "
    "uniform\n"
    "test nets, is evaluated by the NURBS evaluator, by its Bézier form, and by OpenSubdiv's "
    "limit\n"
    "evaluation of the same control net (its regular patches are uniform bicubic B-splines).\n"
    "Prints the regions checked and the largest difference relative to each region's control-net\n"
    "diagonal; exits 1 when a difference exceeds the tolerance.\n"
    "\n"
    "options:\n"
    "  --generated N   generated test nets to check (default 3; 0 for none)\n"
    "  --samples K     points per region, the 4 corners first (default 16)\n"
    "  --tolerance T   largest relative difference accepted (default 1e-10)\n"
    "  -h, --help      this text\n";

typedef struct osd_args {
    int generated, samples;
    double tolerance;
} osd_args;

static int print_report(const char *what, const sw_lod_osd_report *r, double tolerance)
{
    printf("%s: %llu regions on %llu surfaces, %llu samples; max difference to OpenSubdiv "
           "%.3g (NURBS evaluator), %.3g (Bézier form), relative\n",
           what, (unsigned long long)r->regions, (unsigned long long)r->faces_checked,
           (unsigned long long)r->samples, r->max_rel_nurbs, r->max_rel_bezier);
    return r->max_rel_nurbs > tolerance || r->max_rel_bezier > tolerance;
}

static int check_scene(const char *path, const osd_args *a)
{
    sw_status status = {0};
    sw_scene handle;
    sw_rt_scene *scene;
    if (sw_cli_load_scene(path, 0, &handle, &status) != SW_OK)
        return sw_cli_report("check-osd", &status);
    sw_result r = sw_rt_scene_acquire(handle, &scene, &status);
    sw_lod_osd_report rep = {0};
    uint32_t n_faces = r == SW_OK ? sw_sg_scene_view_ptr(scene->sg)->n_faces : 0;
    for (uint32_t f = 0; f < n_faces && r == SW_OK; f++)
        r = sw_lod_osd_check_face(scene->sg, f, a->samples, 1000 + f, &rep, &status);
    if (scene)
        sw_rt_scene_release(scene);
    sw_scene_destroy(handle);
    if (r != SW_OK)
        return sw_cli_report("check-osd", &status);
    return print_report(path, &rep, a->tolerance);
}

static int check_generated(const osd_args *a)
{
    static const int32_t sizes[][2] = {{8, 8}, {13, 9}, {32, 24}, {5, 40}, {64, 64}};
    sw_lod_osd_report rep = {0};
    sw_status status = {0};
    for (int i = 0; i < a->generated; i++) {
        const int32_t *sz = sizes[i % 5];
        if (sw_lod_osd_check_generated(sz[0], sz[1], a->samples, 77 + (uint64_t)i, &rep, &status) !=
            SW_OK)
            return sw_cli_report("check-osd", &status);
    }
    char what[64];
    snprintf(what, sizeof what, "%d generated nets", a->generated);
    return print_report(what, &rep, a->tolerance);
}

int sw_cli_check_osd(int argc, char **argv)
{
    osd_args a = {3, 16, 1e-10};
    const char *scenes[64];
    int n_scenes = 0;
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        double d;
        if (sw_cli_is_help(argv[i])) {
            fputs(k_usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--generated") && val &&
                   sw_cli_parse_count(val, 0, 1000, &a.generated) == 0) {
            i++;
        } else if (!strcmp(argv[i], "--samples") && val &&
                   sw_cli_parse_count(val, 1, 4096, &a.samples) == 0) {
            i++;
        } else if (!strcmp(argv[i], "--tolerance") && val && sw_cli_parse_positive(val, &d) == 0) {
            a.tolerance = d;
            i++;
        } else if (argv[i][0] != '-' && n_scenes < 64) {
            scenes[n_scenes++] = argv[i];
        } else {
            fprintf(stderr, "splinewalk check-osd: bad argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    printf("OpenSubdiv %s\n", sw_lod_osd_version());
    int failed = 0;
    for (int i = 0; i < n_scenes; i++)
        failed |= check_scene(scenes[i], &a);
    if (a.generated)
        failed |= check_generated(&a);
    return failed ? 1 : 0;
}

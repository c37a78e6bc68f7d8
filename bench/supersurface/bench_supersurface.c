/* SPDX-License-Identifier: MIT */
/* bench/supersurface: clustering time per model (lod/static/sw_lod_supersurface.h).
 *
 * Usage: bench_supersurface [--runs N] [--alpha DEG] MODEL...
 * Prints per model: faces, patches, clusters, patches per cluster, and the median and minimum
 * wall time of N builds (import excluded), with patches per second at the median.
 */
#include "sw_lod_supersurface.h"
#include "sw_sg_import.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int bench_model(const char *path, int runs, const sw_lod_ss_desc *desc)
{
    sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL;
    sw_status st = {0};
    if (sw_sg_import_file(&d, &scene, NULL, &st) != SW_OK) {
        printf("%s: skipped (%s)\n", path, st.message);
        return 0;
    }
    double *t = malloc((size_t)runs * sizeof *t);
    uint32_t patches = 0, clusters = 0;
    int fail = 0;
    for (int r = 0; r < runs && !fail; ++r) {
        sw_lod_supersurfaces *ss = NULL;
        const double t0 = now_s();
        if (sw_lod_supersurfaces_build(scene, desc, &ss, &st) != SW_OK) {
            fprintf(stderr, "%s: %s\n", path, st.message);
            fail = 1;
            break;
        }
        t[r] = now_s() - t0;
        patches = ss->n_patches, clusters = ss->n_clusters;
        sw_lod_supersurfaces_free(ss);
    }
    if (!fail) {
        qsort(t, (size_t)runs, sizeof *t, cmp_double);
        const double med = t[runs / 2];
        printf("%s: %u faces, %u patches, %u clusters (%.2f patches each): build median %.2f ms, "
               "min %.2f ms over %d runs, %.0f patches/s\n",
               path, sw_sg_scene_view_ptr(scene)->n_faces, patches, clusters,
               (double)patches / (clusters ? clusters : 1), 1e3 * med, 1e3 * t[0], runs,
               med > 0.0 ? patches / med : 0.0);
    }
    free(t);
    sw_sg_scene_free(scene);
    return fail;
}

int main(int argc, char **argv)
{
    int runs = 5, fail = 0;
    sw_lod_ss_desc desc = {0};
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]) > 0 ? atoi(argv[i]) : 1;
        else if (!strcmp(argv[i], "--alpha") && i + 1 < argc)
            desc.alpha_deg = atof(argv[++i]);
        else
            fail |= bench_model(argv[i], runs, &desc);
    }
    return fail;
}

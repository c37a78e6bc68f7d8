/* SPDX-License-Identifier: MIT */
/* bench/: what the frame benchmarks share besides timing (header only): the scene and its orbit,
 * and the options every one of them takes. */
#ifndef SW_BENCH_SCENE_H
#define SW_BENCH_SCENE_H

#include <splinewalk/splinewalk.h>

#include "sw_camera_path.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Loads `path` (NULL: the built-in default scene) and an orbit of `frames` frames, 10 s, fitted to
 * the scene's box scaled by `distance` about its centre (1: the fitted distance). */
static inline sw_result bench_scene_orbit(const char *path, double distance, int frames,
                                          sw_scene *scene, sw_rt_camera_path *orbit,
                                          sw_status *st)
{
    sw_scene_load_desc ld = {path, NULL, NULL, NULL, NULL, 0};
    sw_result r = path ? sw_scene_load(&ld, scene, st) : sw_scene_load_default(NULL, NULL, scene, st);
    sw_scene_info info;
    if (r == SW_OK)
        r = sw_scene_get_info(*scene, &info, st);
    if (r != SW_OK)
        return r;
    double box[6];
    for (int k = 0; k < 3; ++k) {
        const double c = 0.5 * (info.bbox_min[k] + info.bbox_max[k]);
        const double h = 0.5 * (info.bbox_max[k] - info.bbox_min[k]) * distance;
        box[k] = c - h;
        box[3 + k] = c + h;
    }
    return sw_rt_path_orbit(box, 10.0, (uint32_t)frames, orbit, st);
}

/* --frames N, --passes P, --size WxH at argv[*i]: 1 when taken (and *i moved past its value). */
static inline int bench_common_option(int argc, char **argv, int *i, int *frames, int *passes,
                                      int *w, int *h)
{
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (!v)
        return 0;
    if (!strcmp(argv[*i], "--frames"))
        *frames = atoi(v);
    else if (!strcmp(argv[*i], "--passes"))
        *passes = atoi(v);
    else if (!strcmp(argv[*i], "--size")) {
        if (sscanf(v, "%dx%d", w, h) != 2)
            return 0;
    } else
        return 0;
    ++*i;
    return 1;
}

#endif

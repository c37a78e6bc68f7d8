/* SPDX-License-Identifier: MIT */
/* tests/gpu: what the "same scene, two render paths" tests share — the iso / front camera preset
 * of `splinewalk render` (fovy 40°, distance = diagonal / (2 tan 20°) × 1.1) and the pixel
 * comparison: a pixel differs when its coverage differs or a colour channel differs by more than
 * `color_tol` levels. */
#ifndef SW_TESTS_GPU_COMPARE_H
#define SW_TESTS_GPU_COMPARE_H

#include "sw_gpu.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static inline sw_gpu_camera sw_test_view_camera(const double b[6], int iso)
{
    static const double iso_from[3] = {1, 1, 1}, front_from[3] = {0, -1, 0}, up[3] = {0, 0, 1};
    sw_gpu_camera c;
    sw_gpu_camera_fit_box(b, iso ? iso_from : front_from, up, &c);
    return c;
}

/* The same preset with its eye moved to `scale` times the fitted distance from the target. */
static inline sw_gpu_camera sw_test_view_camera_at(const double b[6], int iso, double scale)
{
    sw_gpu_camera c = sw_test_view_camera(b, iso);
    for (int k = 0; k < 3; ++k)
        c.eye[k] = c.target[k] + scale * (c.eye[k] - c.target[k]);
    return c;
}

typedef struct sw_test_image_diff {
    long covered;      /* pixels covered by either image */
    long differ;       /* coverage or a channel beyond the tolerance */
    long cover_differ; /* coverage alone */
    long any;          /* any difference at all */
} sw_test_image_diff;

static inline sw_test_image_diff sw_test_compare_images(const sw_gpu_image *a,
                                                        const sw_gpu_image *b, int color_tol)
{
    sw_test_image_diff r = {0, 0, 0, 0};
    size_t n = (size_t)a->width * (size_t)a->height;
    for (size_t i = 0; i < n; ++i) {
        int ca = a->rgba[4 * i + 3] != 0, cb = b->rgba[4 * i + 3] != 0, dmax = 0;
        r.covered += ca || cb;
        for (int k = 0; k < 3; ++k) {
            int d = abs((int)a->rgba[4 * i + k] - (int)b->rgba[4 * i + k]);
            dmax = d > dmax ? d : dmax;
        }
        r.cover_differ += ca != cb;
        r.differ += ca != cb || dmax > color_tol;
        r.any += ca != cb || dmax > 0;
    }
    return r;
}

#endif

/* SPDX-License-Identifier: MIT */
/* Camera presets that fit a bounding box (issue 2: fovy 40°, target = box centre, distance =
 * diagonal / (2 tan(fovy/2)) × 1.1). */
#include "sw_rt.h"

#include <math.h>
#include <string.h>

void sw_rt_camera_fit_box(const double bbox[6], sw_view_preset view, sw_camera *out)
{
    static const double dirs[4][3] = {{1, 1, 1}, {0, -1, 0}, {0, 0, 1}, {1, 0, 0}};
    static const double ups[4][3] = {{0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 0, 1}};
    sw_gpu_camera c;
    sw_gpu_camera_fit_box(bbox, dirs[view], ups[view], &c);
    memset(out, 0, sizeof *out);
    memcpy(out->eye, c.eye, sizeof out->eye);
    memcpy(out->target, c.target, sizeof out->target);
    memcpy(out->up, c.up, sizeof out->up);
    out->fovy_deg = c.fovy_deg;
}

int sw_rt_view_parse(const char *text, sw_view_preset *out)
{
    static const char *const names[] = {"iso", "front", "top", "right"};
    for (int i = 0; i < 4; i++) {
        if (strcmp(text, names[i]) == 0) {
            *out = (sw_view_preset)i;
            return 0;
        }
    }
    return -1;
}

/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for camera paths (tools/splinewalk/camera_path.c): every input is parsed and
 * validated; a failure must leave no path and name the input with a line; an accepted path must
 * evaluate to cameras the renderer accepts (finite, fovy in (0, 180)) at every frame time when its
 * numbers are moderate. */
#include "sw_camera_path.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int moderate(const sw_rt_camera_path *p)
{
    for (uint32_t i = 0; i < p->n_keys; i++) {
        const sw_camera *c = &p->keys[i].camera;
        for (int k = 0; k < 3; k++)
            if (fabs(c->eye[k]) > 1e100 || fabs(c->target[k]) > 1e100 || fabs(c->up[k]) > 1e100)
                return 0;
        if (fabs(p->keys[i].t) > 1e100)
            return 0;
    }
    return 1;
}

static void exercise(const sw_rt_camera_path *p)
{
    const int check = moderate(p);
    for (uint32_t i = 0; i < 16; i++) {
        sw_camera c;
        sw_rt_path_eval(p, sw_rt_path_frame_time(p, i, 16), &c);
        if (!check)
            continue;
        for (int k = 0; k < 3; k++)
            if (!isfinite(c.eye[k]) || !isfinite(c.target[k]) || !isfinite(c.up[k]))
                abort();
        if (!(c.fovy_deg > 0.0 && c.fovy_deg < 180.0))
            abort();
    }
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sw_rt_camera_path p;
    sw_status st = {0};
    const sw_result r = sw_rt_path_parse((const char *)data, size, "fuzz", &p, &st);
    if (r != SW_OK) {
        if (p.keys || p.n_keys || st.result != r || strncmp(st.message, "fuzz:", 5) != 0)
            abort();
        return 0;
    }
    if (p.n_keys == 0 || !p.keys)
        abort();
    exercise(&p);
    sw_rt_path_free(&p);
    return 0;
}

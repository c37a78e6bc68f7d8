/* SPDX-License-Identifier: MIT */
/* Camera presets that fit a bounding box (fovy 40°, target = box centre, distance =
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

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Largest |component| of a 3-vector: vectors are scaled by it before their norms are taken, so
 * that no square overflows or underflows whatever the coordinates within the limit. */
static double max_abs3(const double a[3])
{
    return fmax(fabs(a[0]), fmax(fabs(a[1]), fabs(a[2])));
}

const char *sw_rt_camera_problem(const sw_camera *c)
{
    for (int k = 0; k < 3; k++) {
        if (!isfinite(c->eye[k]) || !isfinite(c->target[k]) || !isfinite(c->up[k]))
            return "a coordinate is not finite";
        if (fabs(c->eye[k]) > SW_CAMERA_COORD_MAX || fabs(c->target[k]) > SW_CAMERA_COORD_MAX ||
            fabs(c->up[k]) > SW_CAMERA_COORD_MAX)
            return "a coordinate is beyond SW_CAMERA_COORD_MAX (1e30) in magnitude";
    }
    if (!(c->fovy_deg >= SW_FOVY_MIN_DEG && c->fovy_deg < 180.0))
        return "the field of view is outside [0.01, 180) degrees (SW_FOVY_MIN_DEG)";
    double d[3], up[3];
    for (int k = 0; k < 3; k++)
        d[k] = c->target[k] - c->eye[k];
    const double dm = max_abs3(d), um = max_abs3(c->up);
    /* the view direction must survive the rounding of the eye's and the target's coordinates */
    const double scale = fmax(1.0, fmax(max_abs3(c->eye), max_abs3(c->target)));
    if (!(dm > 1e-9 * scale))
        return "the eye coincides with the target";
    if (!(um > 0.0))
        return "the up vector is zero";
    for (int k = 0; k < 3; k++) {
        d[k] /= dm;
        up[k] = c->up[k] / um;
    }
    const double cosang = dot3(d, up) / sqrt(dot3(d, d) * dot3(up, up));
    if (!(1.0 - fabs(cosang) > 1e-9)) /* sin² < 2e-9: the view basis is lost in rounding */
        return "the up vector points along the view direction";
    return NULL;
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

/* Camera presets that fit a bounding box (issue 2: fovy 40°, target = box centre, distance =
 * diagonal / (2 tan(fovy/2)) × 1.1). */
#include "sw_rt.h"

#include <math.h>
#include <string.h>

#define SW_RT_PRESET_FOVY 40.0

void sw_rt_camera_fit_box(const double bbox[6], sw_view_preset view, sw_camera *out)
{
    static const double dirs[4][3] = {{1, 1, 1}, {0, -1, 0}, {0, 0, 1}, {1, 0, 0}};
    static const double ups[4][3] = {{0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {0, 0, 1}};
    double diag2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double e = bbox[3 + k] - bbox[k];
        diag2 += e * e;
    }
    double diag = sqrt(diag2);
    if (!(diag > 0.0))
        diag = 1.0; /* a point-sized or empty scene still gets a usable camera */
    double fovy = SW_RT_PRESET_FOVY;
    double distance = diag / (2.0 * tan(fovy * M_PI / 360.0)) * 1.1;
    const double *d = dirs[view];
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    memset(out, 0, sizeof *out);
    for (int k = 0; k < 3; k++) {
        out->target[k] = 0.5 * (bbox[k] + bbox[3 + k]);
        out->eye[k] = out->target[k] + d[k] / len * distance;
        out->up[k] = ups[view][k];
    }
    out->fovy_deg = fovy;
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

/* SPDX-License-Identifier: MIT */
/* Small geometry the frame's stages share: homogeneous control points and boxes moved to
 * eye-relative world space (ARCHITECTURE's precision rule: positions in double, relative to the
 * camera), and bounds of an occurrence transform. */
#include "frame_stages.h"

#include <math.h>
#include <string.h>

void sw__fr_occurrence_init(occurrence *o, uint32_t face, const double world[12],
                            const float color[4])
{
    o->face = face;
    memcpy(o->world, world, sizeof o->world);
    static const float k_default[4] = {0.72f, 0.72f, 0.76f, 1.0f};
    memcpy(o->color, color && color[3] >= 0.0f ? color : k_default, sizeof o->color);
}

void sw__fr_xform_h(const double m[12], const double eye[3], const double in[4], double out[4])
{
    for (int r = 0; r < 3; ++r)
        out[r] = m[4 * r] * in[0] + m[4 * r + 1] * in[1] + m[4 * r + 2] * in[2] +
                 in[3] * (m[4 * r + 3] - eye[r]);
    out[3] = in[3];
}

void sw__fr_box_empty(double box[6])
{
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
}

void sw__fr_box_add(double box[6], const double h[4])
{
    for (int k = 0; k < 3; ++k) {
        double x = h[k] / h[3];
        box[k] = fmin(box[k], x);
        box[3 + k] = fmax(box[3 + k], x);
    }
}

void sw__fr_eye_box(const double eye[3], const double world[6], double out[6])
{
    for (int k = 0; k < 3; ++k) {
        out[k] = world[k] - eye[k];
        out[3 + k] = world[3 + k] - eye[k];
    }
}

void sw__fr_eye_box_of(const double eye[3], const double obj[6], const double m[12], double out[6])
{
    sw__fr_box_empty(out);
    for (int c = 0; c < 8; ++c) {
        const double h[4] = {obj[(c & 1) ? 3 : 0], obj[(c & 2) ? 4 : 1], obj[(c & 4) ? 5 : 2], 1.0};
        double w[4];
        sw__fr_xform_h(m, eye, h, w);
        sw__fr_box_add(out, w);
    }
}

void sw__fr_cofactor3(const double m[12], double out[9])
{
    for (int r = 0; r < 3; ++r) {
        const int r1 = (r + 1) % 3, r2 = (r + 2) % 3;
        for (int c = 0; c < 3; ++c) {
            const int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            out[3 * r + c] = m[4 * r1 + c1] * m[4 * r2 + c2] - m[4 * r1 + c2] * m[4 * r2 + c1];
        }
    }
}

double sw__fr_det3(const double m[12])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

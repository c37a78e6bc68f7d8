/* SPDX-License-Identifier: MIT */
/* bench/degrees: the animated trimmed surface, its camera and the screen tolerance. */
#include "animated.h"

#include <math.h>

static const double k_fovy_deg = 40.0;

void bd_clamped_knots(int d, double *k)
{
    for (int i = 0; i < BD_N + d + 1; ++i)
        k[i] = i <= d ? 0.0 : i >= BD_N ? 1.0 : (double)(i - d) / (BD_N - d);
}

/* A wavy sheet whose heights and weights move with a sine. */
void bd_animate(int f, int period, double *cpw)
{
    const double ph = 2.0 * M_PI * f / period;
    for (int j = 0; j < BD_N; ++j)
        for (int i = 0; i < BD_N; ++i) {
            double *c = cpw + (j * BD_N + i) * 4;
            const double w = 1.0 + 0.3 * sin(ph + 0.9 * i - 0.4 * j);
            const double z = 2.0 * sin(ph + 0.6 * i) * cos(0.5 * j - ph);
            c[0] = w * i, c[1] = w * j, c[2] = w * z, c[3] = w;
        }
}

void bd_trim_loop_init(int d, bd_trim_loop *l)
{
    const int base = BD_N, count = base + d;
    l->box[0] = l->box[2] = 1.0;
    l->box[1] = l->box[3] = 0.0;
    for (int i = 0; i < count; ++i) {
        const double a = 2.0 * M_PI * (i % base) / base, r = 0.3 + 0.05 * cos(3.0 * a);
        const double w = 1.0 + 0.2 * ((i % base) & 1);
        const double u = 0.5 + r * cos(a), v = 0.5 + r * sin(a);
        l->cpw[i * 3] = w * u, l->cpw[i * 3 + 1] = w * v, l->cpw[i * 3 + 2] = w;
        l->box[0] = fmin(l->box[0], u), l->box[1] = fmax(l->box[1], u);
        l->box[2] = fmin(l->box[2], v), l->box[3] = fmax(l->box[3], v);
    }
    for (int i = 0; i < count + d + 1; ++i) /* uniform, unclamped: a periodic curve */
        l->knots[i] = (double)i / (count + d);
    l->curve = (sw_sg_curve){d, count, 3, l->knots, l->cpw};
}

sw_gpu_camera bd_camera(void)
{
    static const double dir[3] = {0.3, -0.8, 1.0};
    const double dist = 9.0, n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    sw_gpu_camera c = {{0}, {4.5, 4.5, 0.0}, {0.0, 0.0, 1.0}, k_fovy_deg};
    for (int k = 0; k < 3; ++k)
        c.eye[k] = c.target[k] + dist * dir[k] / n;
    return c;
}

void bd_screen_init(bd_screen *s, const sw_gpu_camera *cam, int32_t width, int32_t height)
{
    double n = 0.0;
    for (int k = 0; k < 3; ++k) {
        s->eye[k] = cam->eye[k];
        s->fwd[k] = cam->target[k] - cam->eye[k];
        n += s->fwd[k] * s->fwd[k];
    }
    for (int k = 0; k < 3; ++k)
        s->fwd[k] /= sqrt(n);
    const double ty = tan(0.5 * cam->fovy_deg * M_PI / 180.0), tx = ty * width / height;
    s->k = 0.5 * height / ty * sqrt(1.0 + tx * tx + ty * ty);
}

double bd_screen_min_depth(const bd_screen *s, const double box[6])
{
    double z = 0.0;
    for (int k = 0; k < 3; ++k) /* the box corner nearest along fwd, coordinate by coordinate */
        z += s->fwd[k] * ((s->fwd[k] >= 0.0 ? box[k] : box[3 + k]) - s->eye[k]);
    return z;
}

/* SPDX-License-Identifier: MIT */
/* bench/tessellation: the benchmark's wavy rational bicubic patch and its fitted camera. */
#include "wavy_patch.h"
#include "sw_gpu_internal.h"

#include <math.h>
#include <string.h>

const double bt_wavy_knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};
static const double k_z[4][4] = {{0.0, 0.3, -0.2, 0.1},
                                 {0.25, -0.35, 0.4, -0.1},
                                 {-0.2, 0.45, -0.3, 0.2},
                                 {0.1, -0.15, 0.25, 0.0}};
static const double k_w[4][4] = {
    {1.0, 1.0, 1.0, 1.0}, {1.0, 2.0, 1.5, 1.0}, {1.0, 0.7, 0.5, 1.0}, {1.0, 1.0, 1.0, 1.0}};
static const double k_fovy = 40.0;

void bt_wavy_cpw(double cpw[64])
{
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            double w = k_w[j][i], *p = cpw + 4 * (4 * j + i);
            p[0] = w * (-1.0 + 2.0 * i / 3.0);
            p[1] = w * (-1.0 + 2.0 * j / 3.0);
            p[2] = w * k_z[j][i];
            p[3] = w;
        }
}

sw_sg_surface bt_wavy_surface(const double cpw[64])
{
    return (sw_sg_surface){3, 3, 4, 4, bt_wavy_knots, bt_wavy_knots, cpw};
}

sw_gpu_camera bt_wavy_camera_at(double dist)
{
    sw_gpu_camera c = {{0.3, -0.55, 1.0}, {0, 0, 0}, {0, 1, 0}, k_fovy};
    double n = sqrt(c.eye[0] * c.eye[0] + c.eye[1] * c.eye[1] + c.eye[2] * c.eye[2]);
    for (int k = 0; k < 3; ++k)
        c.eye[k] *= dist / n;
    return c;
}

/* Horizontal extent in pixels of the untrimmed patch, sampled on a 33 x 33 grid. */
static double width_px(const double cpw[64], const sw_gpu_camera *cam, int32_t width,
                       int32_t height)
{
    sw__gpu_view v;
    if (sw__gpu_view_init(&v, cam, width, height, 1e-3, NULL) != SW_OK)
        return 0.0;
    sw_sg_surface srf = bt_wavy_surface(cpw);
    double lo = INFINITY, hi = -INFINITY;
    for (int j = 0; j <= 32; ++j)
        for (int i = 0; i <= 32; ++i) {
            double p[3], x = 0.0, w = 0.0;
            sw_sg_surface_eval(&srf, i / 32.0, j / 32.0, p);
            for (int k = 0; k < 3; ++k) {
                x += v.right[k] * (p[k] - v.eye[k]);
                w += v.fwd[k] * (p[k] - v.eye[k]);
            }
            double px = (x / (w * v.tan_x) + 1.0) * 0.5 * width;
            lo = fmin(lo, px);
            hi = fmax(hi, px);
        }
    return hi - lo;
}

/* Fixed-point iteration: the width is nearly inversely proportional to the distance. */
double bt_wavy_fit_distance(const double cpw[64], double px, int32_t width, int32_t height,
                            double *got)
{
    double d = 10.0;
    for (int it = 0; it < 12; ++it) {
        sw_gpu_camera c = bt_wavy_camera_at(d);
        d *= width_px(cpw, &c, width, height) / px;
    }
    sw_gpu_camera c = bt_wavy_camera_at(d);
    *got = width_px(cpw, &c, width, height);
    return d;
}

sw_result bt_wavy_scene(const double cpw[64], sw_sg_scene **out, sw_status *status)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return SW_ERR_OUT_OF_MEMORY;
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 3;
    f.n_u = f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, bt_wavy_knots, 8);
    f.knots_v = sw_sg_builder_push_doubles(b, bt_wavy_knots, 8);
    f.cpw = sw_sg_builder_push_doubles(b, cpw, 64);
    f.kind = SW_SG_KIND_BSPLINE;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    f.tolerance = 1e-7;
    uint32_t face = sw_sg_builder_add_face(b, &f);
    static const float white[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, white, "patch");
    return sw_sg_builder_finish(b, out, status);
}

/* SPDX-License-Identifier: MIT */
/* The view shared by every draw path: camera basis, reversed-Z perspective with an infinite far
 * plane (glClipControl zero-to-one, depth = near / z, cleared to 0, GL_GREATER), frustum planes in
 * eye-relative world coordinates for box culling (Guthe et al. 2005 §7: view-frustum culling of
 * patch boxes), and the depth-buffer-to-distance conversion for readback.
 */
#include "sw_gpu_internal.h"
#include "sw_sg_bvh.h"
#include "sw_status_util.h"

#include <math.h>
#include <string.h>

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize3(double v[3])
{
    double n = sqrt(dot3(v, v));
    if (!(n > 0.0) || !isfinite(n))
        return 0;
    v[0] /= n;
    v[1] /= n;
    v[2] /= n;
    return 1;
}

static void set_plane(double plane[4], const double a[3], double sa, const double b[3], double sb,
                      double d)
{
    for (int k = 0; k < 3; ++k)
        plane[k] = sa * a[k] + sb * b[k];
    plane[3] = d;
}

sw_result sw__gpu_view_init(sw__gpu_view *v, const sw_gpu_camera *cam, int32_t w, int32_t h,
                            double near_plane, sw_status *status)
{
    memset(v, 0, sizeof *v);
    memcpy(v->eye, cam->eye, sizeof v->eye);
    for (int k = 0; k < 3; ++k) {
        v->fwd[k] = cam->target[k] - cam->eye[k];
        v->up[k] = cam->up[k];
    }
    cross3(v->fwd, v->up, v->right);
    if (!normalize3(v->fwd) || !normalize3(v->right) || !(cam->fovy_deg >= SW_FOVY_MIN_DEG) ||
        !(cam->fovy_deg < 180.0) || !(near_plane > 0.0))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "degenerate camera (eye = target, up parallel to the view, fovy %g "
                        "outside [%g, 180) or near plane %g)",
                        cam->fovy_deg, SW_FOVY_MIN_DEG, near_plane);
    cross3(v->right, v->fwd, v->up);
    v->width = w;
    v->height = h;
    v->tan_y = tan(cam->fovy_deg * M_PI / 360.0);
    v->tan_x = v->tan_y * (double)w / (double)h;
    v->focal_px = (double)h / (2.0 * v->tan_y);
    v->near_plane = near_plane;

    double fx = 1.0 / v->tan_x, fy = 1.0 / v->tan_y;
    float *m = v->view_proj; /* column-major: m[col * 4 + row] */
    memset(m, 0, sizeof v->view_proj);
    for (int c = 0; c < 3; ++c) {
        m[c * 4 + 0] = (float)(fx * v->right[c]);
        m[c * 4 + 1] = (float)(fy * v->up[c]);
        m[c * 4 + 3] = (float)v->fwd[c]; /* clip w = depth along the view axis */
    }
    m[3 * 4 + 2] = (float)near_plane; /* clip z = near: depth = near / w, 1 at the near plane */

    /* Inside: -w <= x <= w, -w <= y <= w, w >= near; written as dot(n, x) + d >= 0. */
    set_plane(v->planes[0], v->fwd, 1.0, v->right, fx, 0.0);
    set_plane(v->planes[1], v->fwd, 1.0, v->right, -fx, 0.0);
    set_plane(v->planes[2], v->fwd, 1.0, v->up, fy, 0.0);
    set_plane(v->planes[3], v->fwd, 1.0, v->up, -fy, 0.0);
    set_plane(v->planes[4], v->fwd, 1.0, v->fwd, 0.0, -near_plane);
    return SW_OK;
}

void sw__gpu_view_matrices(const sw__gpu_view *v, double view[16], double proj[16])
{
    memset(view, 0, 16 * sizeof *view);
    memset(proj, 0, 16 * sizeof *proj);
    for (int c = 0; c < 3; ++c) {
        view[c * 4 + 0] = v->right[c];
        view[c * 4 + 1] = v->up[c];
        view[c * 4 + 2] = -v->fwd[c];
    }
    view[12] = -dot3(v->right, v->eye);
    view[13] = -dot3(v->up, v->eye);
    view[14] = dot3(v->fwd, v->eye);
    view[15] = 1.0;
    proj[0] = 1.0 / v->tan_x;
    proj[5] = 1.0 / v->tan_y;
    proj[11] = -1.0;          /* clip w = -z_eye, the depth along the view axis */
    proj[14] = v->near_plane; /* clip z = near: zero-to-one depth = near / w, as view_proj */
}

/* The same box-against-planes test as the BVH's culling (one classification for both). */
#define N_PLANES(v) ((int32_t)(sizeof(v)->planes / sizeof(v)->planes[0]))

int sw__gpu_view_box_visible(const sw__gpu_view *v, const double box[6])
{
    return sw_sg_planes_classify((const double(*)[4])v->planes, N_PLANES(v), box) !=
           SW_SG_CULL_OUTSIDE;
}

int sw__gpu_view_box_inside(const sw__gpu_view *v, const double box[6])
{
    return sw_sg_planes_classify((const double(*)[4])v->planes, N_PLANES(v), box) ==
           SW_SG_CULL_INSIDE;
}

double sw__gpu_view_box_depth(const sw__gpu_view *v, const double box[6])
{
    double d = 0.0;
    for (int k = 0; k < 3; ++k)
        d += v->fwd[k] * (v->fwd[k] >= 0.0 ? box[k] : box[3 + k]);
    return d > v->near_plane ? d : v->near_plane;
}

double sw__gpu_box_distance(const double box[6])
{
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
        double d = box[k] > 0.0 ? box[k] : (box[3 + k] < 0.0 ? -box[3 + k] : 0.0);
        s += d * d;
    }
    return sqrt(s);
}

float sw__gpu_depth_to_eye(const sw__gpu_view *v, float d)
{
    if (!(d > 0.0f))
        return INFINITY;
    return (float)(v->near_plane / (double)d);
}

void sw_gpu_camera_fit_box(const double box[6], const double from[3], const double up[3],
                           sw_gpu_camera *out)
{
    double diag2 = 0.0;
    for (int k = 0; k < 3; k++)
        diag2 += (box[3 + k] - box[k]) * (box[3 + k] - box[k]);
    const double diag = diag2 > 0.0 ? sqrt(diag2) : 1.0;
    const double fovy = SW_DEFAULT_FOVY_DEG,
                 distance = diag / (2.0 * tan(fovy * M_PI / 360.0)) * 1.1;
    const double len = sqrt(dot3(from, from));
    memset(out, 0, sizeof *out);
    for (int k = 0; k < 3; k++) {
        out->target[k] = 0.5 * (box[k] + box[3 + k]);
        out->eye[k] = out->target[k] + from[k] / len * distance;
        out->up[k] = up[k];
    }
    out->fovy_deg = fovy;
}

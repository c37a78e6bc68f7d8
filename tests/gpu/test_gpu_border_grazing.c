/* SPDX-License-Identifier: MIT */
/* Fat borders seen at a grazing angle (gpu/crack_fill.c, Guthe et al. 2005 §7.1). A ribbon must
 * reach width_px across its loop's image whatever the view: between two faces, or two hierarchy
 * nodes of one face, each drawn within ε_img of the exact surface, a gap pixel lies up to ε_img
 * from the exact curve, and only the ribbons cover it.
 * Scene: a quarter cylinder (rational quadratic in u, its axis along v), seen from just above its
 * top looking along the axis: the loop's inward direction across its v edges runs almost along
 * the eye rays, foreshortened some 20 times, as Ball's inner race at its mid view. A rectangle in
 * (u, v), as the hierarchy draws a node's, gets a 1 px ribbon.
 * Checks, on screen, at every quad end whose inner step the loop did not cut: the inner vertex
 * lies 0.75 to 2.05 px from the outer one (outer 0.25 px beyond the loop, inner 1 px inside it;
 * the reach is bounded at 2 px); and it lies on the exact surface (its st is its (u, v)) pushed
 * back along its eye ray, never in front.
 * Planted fault: the inner step capped at 4 px' worth of object length facing the screen (as it
 * was) → 0.31 .. 0.62 px, the check fails. No GL needed. */
#include "sw_gpu_internal.h"
#include "test_check.h"

#include <math.h>
#include <stdlib.h>

enum { W = 640, H = 480, N_LOOP = 4 };

static double depth_of(const sw__gpu_view *v, const double p[3])
{
    return v->fwd[0] * p[0] + v->fwd[1] * p[1] + v->fwd[2] * p[2];
}

static int screen_of(const sw__gpu_view *v, const double p[3], double out[2])
{
    double z = depth_of(v, p);
    if (!(z > 0.0))
        return 0;
    out[0] = v->focal_px * (v->right[0] * p[0] + v->right[1] * p[1] + v->right[2] * p[2]) / z;
    out[1] = v->focal_px * (v->up[0] * p[0] + v->up[1] * p[1] + v->up[2] * p[2]) / z;
    return 1;
}

static void vertex_pos(const sw__gpu_vertex *o, double p[3])
{
    for (int k = 0; k < 3; ++k)
        p[k] = o->pos[k];
}

/* The inner vertex's exact surface point (its st is its (u, v): st_box is the unit square),
 * eye-relative. */
static void exact_point(const sw_sg_surface *srf, const sw__gpu_vertex *o, const double eye[3],
                        double p[3])
{
    sw_sg_surface_eval(srf, o->st[0], o->st[1], p);
    for (int k = 0; k < 3; ++k)
        p[k] -= eye[k];
}

int main(void)
{
    /* quarter cylinder of radius 1 about the y axis, from +x (u = 0) to +z (u = 1), y = 10 v */
    const double ku[6] = {0, 0, 0, 1, 1, 1}, kv[4] = {0, 0, 1, 1};
    const double r2 = sqrt(0.5);
    const double cpw[24] = {
        1, 0,  0, 1, r2, 0,  r2, r2, 0, 0,  1, 1, /* v = 0 (rows in u, homogeneous) */
        1, 10, 0, 1, r2, 10, r2, r2, 0, 10, 1, 1, /* v = 1 */
    };
    const sw_sg_surface srf = {2, 1, 3, 2, ku, kv, cpw};
    const double world[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const sw_gpu_camera cam = {{0.2, -4.0, 1.3}, {0.2, 10.0, 0.9}, {0, 0, 1}, 30.0};
    const double rect[4] = {0.65, 0.95, 0.3, 0.9};
    const double uv[2 * N_LOOP] = {rect[0], rect[2], rect[1], rect[2],
                                   rect[1], rect[3], rect[0], rect[3]};
    const double st_box[4] = {0, 1, 0, 1};
    sw__gpu_view v;
    sw_status st = {0};
    if (sw__gpu_view_init(&v, &cam, W, H, 0.01, &st) != SW_OK) {
        printf("view: %s\n", st.message);
        return 1;
    }
    sw__gpu_mesh m = {0};
    CHECK(sw__gpu_fat_border(&v, &srf, world, uv, N_LOOP, 1, 0.005, 0.005, 1.0, st_box, 0, NULL, &m,
                             &st) == SW_OK,
          "ribbon: %s", st.message);
    double narrow = INFINITY, wide = 0.0, dz_lo = INFINITY, dz_hi = -INFINITY;
    size_t checked = 0;
    for (size_t q = 0; q + 4 <= m.n_v; q += 4)
        for (int end = 0; end < 2; ++end) {
            const sw__gpu_vertex *out = &m.v[q + 2 * end], *in = &m.v[q + 2 * end + 1];
            const double su = in->st[0], sv = in->st[1];
            const int cut = fabs(su - rect[0]) < 1e-6 || fabs(su - rect[1]) < 1e-6 ||
                            fabs(sv - rect[2]) < 1e-6 || fabs(sv - rect[3]) < 1e-6;
            double po[3], pi[3], pe[3], so[2], si[2];
            vertex_pos(out, po);
            vertex_pos(in, pi);
            if (cut || !screen_of(&v, po, so) || !screen_of(&v, pi, si))
                continue;
            ++checked;
            const double across = hypot(si[0] - so[0], si[1] - so[1]);
            narrow = fmin(narrow, across);
            wide = fmax(wide, across);
            exact_point(&srf, in, v.eye, pe);
            const double dz = (depth_of(&v, pi) - depth_of(&v, pe)) / depth_of(&v, pe);
            dz_lo = fmin(dz_lo, dz);
            dz_hi = fmax(dz_hi, dz);
        }
    printf("%zu quad ends checked: inner to outer %.3f .. %.3f px; inner points behind the surface "
           "by %.2g .. %.2g of their depth\n",
           checked, narrow, wide, dz_lo, dz_hi);
    CHECK(checked >= 12, "only %zu quad ends checked", checked);
    CHECK(narrow >= 0.75 && wide <= 2.05, "ribbon %.3f .. %.3f px across, not 0.75 .. 2.05", narrow,
          wide);
    CHECK(dz_lo > 0.0 && dz_hi < 0.1, "inner points %.2g .. %.2g of their depth behind the surface",
          dz_lo, dz_hi);
    sw__gpu_mesh_free(&m);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}

/* SPDX-License-Identifier: MIT */
/* Fat borders of a loop reaching nearer than the near plane (gpu/crack_fill.c, Guthe et al. 2005
 * §7.1). A plane's long loop segment runs from far away to between the eye and the near plane: the
 * part beyond the near plane is on screen, and the ribbon must cover it up to the plane. A quad
 * end nearer than the near plane has no image, so it took no step into the face: the quad tapered
 * to nothing over the visible part of the segment (MODERN_Refrigerator_1's mid view showed a
 * crack pixel there once trim textures no longer grew faces by a texel).
 * Scene: the plane z = 0 (bilinear, 10 x 10 units over (u, v) in [0, 1]^2), a narrow rectangle loop
 * along y, seen from 0.5 above its near end looking along it; near plane at depth 2, the loop's
 * near end at depth 1. Checks: a quad with any point beyond the near plane has all of them beyond
 * it; every quad end on screen is 0.75 .. 2.05 px across (outer to inner point); quads reach the
 * near plane (a point within 6 % of its depth: the largest margin quad_ends_clipped tries is 5 %,
 * and the quad is pushed back), so the visible part is covered up to it.
 * Planted faults: the near end left where it was (no clipping) → a quad reaching from depth 11 to
 * 1.07, nearer than the plane; clipped just in front of the plane only (no larger margin tried) →
 * the step from there runs back behind the plane and is cut: 0.28 px across. Both fail. No GL
 * needed. */
#include "sw_gpu_internal.h"
#include "test_check.h"

#include <math.h>
#include <stdlib.h>

enum { W = 640, H = 480, N_LOOP = 4 };
static const double k_near = 2.0;

static double depth_of(const sw__gpu_view *v, const double p[3])
{
    return v->fwd[0] * p[0] + v->fwd[1] * p[1] + v->fwd[2] * p[2];
}

static void screen_of(const sw__gpu_view *v, const double p[3], double out[2])
{
    double z = depth_of(v, p);
    out[0] = v->focal_px * (v->right[0] * p[0] + v->right[1] * p[1] + v->right[2] * p[2]) / z;
    out[1] = v->focal_px * (v->up[0] * p[0] + v->up[1] * p[1] + v->up[2] * p[2]) / z;
}

static void vertex_pos(const sw__gpu_vertex *o, double p[3])
{
    for (int k = 0; k < 3; ++k)
        p[k] = o->pos[k];
}

int main(void)
{
    const double kn[4] = {0, 0, 1, 1};
    const double cpw[16] = {0, 0, 0, 1, 10, 0, 0, 1, 0, 10, 0, 1, 10, 10, 0, 1};
    const sw_sg_surface srf = {1, 1, 2, 2, kn, kn, cpw};
    const double world[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const sw_gpu_camera cam = {{5.0, -1.0, 0.5}, {5.0, 10.0, 0.0}, {0, 0, 1}, 30.0};
    const double rect[4] = {0.47, 0.53, 0.0, 1.0};
    const double uv[2 * N_LOOP] = {rect[0], rect[2], rect[1], rect[2],
                                   rect[1], rect[3], rect[0], rect[3]};
    const double st_box[4] = {0, 1, 0, 1};
    sw__gpu_view v;
    sw_status st = {0};
    if (sw__gpu_view_init(&v, &cam, W, H, k_near, &st) != SW_OK) {
        printf("view: %s\n", st.message);
        return 1;
    }
    sw__gpu_mesh m = {0};
    CHECK(sw__gpu_fat_border(&v, &srf, world, uv, N_LOOP, 1, 0.05, 0.05, 1.0, st_box, 1, NULL, &m,
                             &st) == SW_OK,
          "ribbon: %s", st.message);
    double nearest = INFINITY, narrow = INFINITY, wide = 0.0;
    size_t ends = 0;
    for (size_t q = 0; q + 4 <= m.n_v; q += 4) {
        /* a quad with a point beyond the near plane must have all its points beyond it (a quad
         * wholly nearer is not drawn and does not matter) */
        double zmin = INFINITY, zmax = -INFINITY, p[3];
        for (int k = 0; k < 4; ++k) {
            vertex_pos(&m.v[q + (size_t)k], p);
            zmin = fmin(zmin, depth_of(&v, p));
            zmax = fmax(zmax, depth_of(&v, p));
        }
        if (zmax > k_near)
            nearest = fmin(nearest, zmin);
        for (int end = 0; end < 2; ++end) {
            double po[3], pi[3], so[2], si[2];
            vertex_pos(&m.v[q + 2 * end], po);
            vertex_pos(&m.v[q + 2 * end + 1], pi);
            if (!(depth_of(&v, po) > k_near) || !(depth_of(&v, pi) > k_near))
                continue;
            screen_of(&v, po, so);
            screen_of(&v, pi, si);
            const double across = hypot(si[0] - so[0], si[1] - so[1]);
            if (fabs(si[0]) > W || fabs(si[1]) > H)
                continue; /* far off screen: the sides' far ends */
            ++ends;
            if (getenv("SW_TEST_VERBOSE"))
                printf("  end at depth %.4f: %.3f px across\n", depth_of(&v, po), across);
            narrow = fmin(narrow, across);
            wide = fmax(wide, across);
        }
    }
    printf("%zu quads, %zu ends on screen: %.3f .. %.3f px across; nearest quad point at depth "
           "%.4f (near plane %.1f)\n",
           m.n_v / 4, ends, narrow, wide, nearest, k_near);
    CHECK(ends >= 4, "only %zu quad ends on screen", ends);
    CHECK(nearest > k_near, "a quad point at depth %.4f, nearer than the near plane %.1f", nearest,
          k_near);
    CHECK(nearest < 1.06 * k_near, "the ribbon stops at depth %.4f, short of the near plane %.1f",
          nearest, k_near);
    CHECK(narrow >= 0.75 && wide <= 2.05, "ribbon %.3f .. %.3f px across, not 0.75 .. 2.05", narrow,
          wide);
    sw__gpu_mesh_free(&m);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}

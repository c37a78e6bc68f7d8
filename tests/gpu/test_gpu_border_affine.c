/* SPDX-License-Identifier: MIT */
/* Fat borders of affine faces (gpu/crack_fill.c, Guthe et al. 2005 §7.1): a plane's ribbon is taken
 * from its loop's vertices and straight inner steps, with no surface evaluation in between. It must
 * be the ribbon the general path draws (sampling the loop at the grid's cells and evaluating the
 * exact surface at every inner step), where both have a sample: on screen, every inner vertex of
 * the affine ribbon lies within 1e-3 px of an inner vertex of the general one (the push-back moves
 * vertices along their eye rays only, so screen positions compare). And it must be the cheap one:
 * one quad per loop segment.
 * The general path's inner step is the true derivative's: the same plane with every weight 0.5 (the
 * same surface, the same parametrisation) gives the same general ribbon within 1e-3 px. Before,
 * the step was taken along w^2 S_u, which put it 4x as far (1 px ribbons 4 px wide).
 * Scene: a plane placed by a rotation and a non-uniform scale, a non-convex hexagon (an L) in its
 * parameters, seen obliquely in perspective at 320 x 240 with a 1 px ribbon. Planted fault (the
 * world u-derivative of the affine path zeroed in ribbon_affine): an inner vertex 1.07 px off,
 * the check fails; with eval_point's division by w^2 removed, the reweighted plane's 3.24 px. No GL
 * needed. */
#include "sw_gpu_internal.h"
#include "test_check.h"

#include <math.h>
#include <stdlib.h>

enum { W = 320, H = 240, N_LOOP = 6 };

/* Farthest point of a (n of them) from its nearest point of b (m of them), in pixels. */
static double farthest(const double *a, size_t n, const double *b, size_t m)
{
    double worst = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double best = INFINITY;
        for (size_t j = 0; j < m; ++j)
            best = fmin(best, hypot(a[2 * i] - b[2 * j], a[2 * i + 1] - b[2 * j + 1]));
        worst = fmax(worst, best);
    }
    return worst;
}

static int screen_of(const sw__gpu_view *v, const float p[3], double out[2])
{
    double z = 0.0, x = 0.0, y = 0.0;
    for (int k = 0; k < 3; ++k) {
        z += v->fwd[k] * p[k];
        x += v->right[k] * p[k];
        y += v->up[k] * p[k];
    }
    if (!(z > 0.0))
        return 0;
    out[0] = v->focal_px * x / z;
    out[1] = v->focal_px * y / z;
    return 1;
}

/* Inner ribbon vertices (side 1 of each quad's two ends) on screen; returns their count. */
static size_t inner_points(const sw__gpu_view *v, const sw__gpu_mesh *m, double *out)
{
    size_t n = 0;
    for (size_t q = 0; q + 4 <= m->n_v; q += 4)
        for (int end = 0; end < 2; ++end)
            n += (size_t)screen_of(v, m->v[q + 2 * end + 1].pos, out + 2 * n);
    return n;
}

int main(void)
{
    const double knots[4] = {0, 0, 1, 1};
    const double cpw[16] = {0, 0, 0, 1, 10, 0, 0, 1, 0, 6, 0, 1, 10, 6, 0, 1};
    const sw_sg_surface srf = {1, 1, 2, 2, knots, knots, cpw};
    const double c = cos(0.4), s = sin(0.4);
    const double world[12] = {c, -s * 0.5, 0, 3, s, c * 0.5, 0.3, -1, 0, 0.2, 1.5, 2};
    const sw_gpu_camera cam = {{14.0, -9.0, 9.0}, {5.0, 2.0, 2.0}, {0, 0, 1}, 45.0};
    const double uv[2 * N_LOOP] = {0.1, 0.1, 0.9, 0.1, 0.9, 0.45, 0.45, 0.45, 0.45, 0.9, 0.1, 0.9};
    sw__gpu_view v;
    sw_status st = {0};
    if (sw__gpu_view_init(&v, &cam, W, H, 0.01, &st) != SW_OK) {
        printf("view: %s\n", st.message);
        return 1;
    }
    sw__gpu_mesh m[2] = {{0}, {0}}; /* affine path, general path */
    for (int k = 0; k < 2; ++k) {
        sw_result r = sw__gpu_fat_border(&v, &srf, world, uv, N_LOOP, 1, 0.01, 0.01, 1.0, NULL,
                                         k == 0, NULL, &m[k], &st);
        CHECK(r == SW_OK, "%s path: %s", k ? "general" : "affine", st.message);
    }
    printf("ribbon quads: affine path %zu, general path %zu (loop of %d segments)\n", m[0].n_v / 4,
           m[1].n_v / 4, N_LOOP);
    CHECK(m[0].n_v == 4 * N_LOOP, "affine path: %zu quads, not one per segment", m[0].n_v / 4);
    CHECK(m[1].n_v > m[0].n_v, "the general path should sample the loop more densely");
    double *a = malloc(2 * m[0].n_v * sizeof *a), *g = malloc(2 * m[1].n_v * sizeof *g);
    if (!a || !g)
        return 1;
    size_t na = inner_points(&v, &m[0], a), ng = inner_points(&v, &m[1], g);
    CHECK(na == m[0].n_v / 2, "affine ribbon: %zu of %zu inner vertices in front", na,
          m[0].n_v / 2);
    double worst = farthest(a, na, g, ng);
    printf("inner vertices: %zu affine, %zu general; farthest affine one from the general ribbon's "
           "%.3g px\n",
           na, ng, worst);
    CHECK(worst <= 1e-3, "affine ribbon's inner vertex %.3g px from the general ribbon's", worst);

    double cpw_half[16];
    for (int i = 0; i < 16; ++i)
        cpw_half[i] = 0.5 * cpw[i];
    const sw_sg_surface half = {1, 1, 2, 2, knots, knots, cpw_half};
    sw__gpu_mesh mh = {0};
    CHECK(sw__gpu_fat_border(&v, &half, world, uv, N_LOOP, 1, 0.01, 0.01, 1.0, NULL, 0, NULL, &mh,
                             &st) == SW_OK,
          "weights 0.5: %s", st.message);
    double *h = malloc(2 * (mh.n_v + 1) * sizeof *h);
    if (!h)
        return 1;
    size_t nh = inner_points(&v, &mh, h);
    double off = fmax(farthest(h, nh, g, ng), farthest(g, ng, h, nh));
    printf("weights 0.5, general path: %zu inner vertices, %.3g px from the weight-1 ribbon's\n",
           nh, off);
    CHECK(nh == ng && off <= 1e-3, "weights 0.5: %zu inner vertices, %.3g px off", nh, off);
    free(h);
    sw__gpu_mesh_free(&mh);
    free(a);
    free(g);
    sw__gpu_mesh_free(&m[0]);
    sw__gpu_mesh_free(&m[1]);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}

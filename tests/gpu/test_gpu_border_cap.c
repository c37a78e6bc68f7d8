/* The fat border's sampling is bounded by the view: a loop whose grid cells are
 * tiny (a face refined deep under a narrow field of view: fovy 1e-9 grew memory at ~600 MB/s in
 * sw__gpu_fat_border) takes at most max(2 n, 64 (width + height)) samples, the fallback counted
 * in mesh.border_capped; a loop at ordinary cells is sampled as before, uncounted.
 * Scene: the unit square z = 0 (bilinear), a circular loop of 10,000 vertices in it, seen from
 * above at 160 x 120. With cells of 1e-9 the loop asked for 10,000 x 4,096 = 4.1e7 samples
 * (~7 GB of samples and ribbon vertices). Planted fault (the budget check in
 * sw__gpu_fat_border removed): 1.6e8 ribbon vertices, and the vertex check fails (or the
 * allocation does). The loop's samples themselves are checked against the budget too, also with
 * cells degenerate in one direction (1e-15 in v: a sliver knot span of a scaled IGES part gave
 * 7e-16): every segment then asks for the per-segment cap of pieces, and a widening scaled by
 * the capped count left 4.1e7 samples (planted: widening by m / budget in
 * sw__gpu_border_loop_make: FAIL, 4.1e7 samples; the part itself ran out of memory). No GL
 * needed. */
#include "sw_gpu_internal.h"
#include "test_check.h"

#include <math.h>
#include <stdlib.h>

enum { N_LOOP = 10000, W = 160, H = 120 };

int main(void)
{
    const double knots[4] = {0, 0, 1, 1};
    const double cpw[16] = {0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 1, 1, 0, 1};
    const sw_sg_surface srf = {1, 1, 2, 2, knots, knots, cpw};
    const double world[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const sw_gpu_camera cam = {{0.5, 0.5, 2.0}, {0.5, 0.5, 0.0}, {0, 1, 0}, 40.0};
    sw__gpu_view v;
    sw_status st = {0};
    if (sw__gpu_view_init(&v, &cam, W, H, 0.01, &st) != SW_OK) {
        printf("view: %s\n", st.message);
        return 1;
    }
    double *uv = malloc(2 * N_LOOP * sizeof *uv);
    if (!uv)
        return 1;
    for (int i = 0; i < N_LOOP; ++i) {
        const double a = 2.0 * M_PI * i / N_LOOP;
        uv[2 * i] = 0.5 + 0.3 * cos(a);
        uv[2 * i + 1] = 0.5 + 0.3 * sin(a);
    }
    const size_t budget = 64u * (W + H) > 2u * N_LOOP ? 64u * (W + H) : 2u * N_LOOP;
    const double cells[2] = {0.01, 1e-9};
    /* affine 0: the plane sampled at its cells as a curved face is (its affine path would take
     * the loop's vertices only, and never reach the cap) */
    for (int k = 0; k < 2; ++k) {
        sw__gpu_mesh mesh = {0};
        sw_result r = sw__gpu_fat_border(&v, &srf, world, uv, N_LOOP, 1, cells[k], cells[k], 1.0,
                                         NULL, 0, NULL, &mesh, &st);
        printf("cells %g: %s, %zu ribbon vertices, border_capped %llu\n", cells[k],
               sw_result_str(r), mesh.n_v, (unsigned long long)mesh.border_capped);
        CHECK(r == SW_OK, "cells %g: %s", cells[k], st.message);
        /* each kept sample makes one quad (4 vertices); at most n + budget samples */
        CHECK(mesh.n_v <= 4 * (N_LOOP + budget), "cells %g: %zu vertices over the budget", cells[k],
              mesh.n_v);
        CHECK(mesh.n_v > 0, "cells %g: no ribbon", cells[k]);
        CHECK(mesh.border_capped == (k == 1), "cells %g: border_capped %llu", cells[k],
              (unsigned long long)mesh.border_capped);
        sw__gpu_mesh_free(&mesh);
    }
    const double degenerate[3][2] = {{0.01, 0.01}, {1e-9, 1e-9}, {0.01, 1e-15}};
    for (int k = 0; k < 3; ++k) {
        sw__gpu_border_loop *bl = NULL;
        sw_result r = sw__gpu_border_loop_make(&srf, uv, N_LOOP, 1, degenerate[k][0],
                                               degenerate[k][1], 0, budget, &bl, &st);
        CHECK(r == SW_OK, "cells %g x %g: %s", degenerate[k][0], degenerate[k][1], st.message);
        if (r != SW_OK)
            continue;
        const size_t m = sw__gpu_border_loop_samples(bl);
        printf("cells %g x %g: %zu samples (budget %zu)\n", degenerate[k][0], degenerate[k][1], m,
               budget);
        CHECK(m <= budget, "cells %g x %g: %zu samples over the budget %zu", degenerate[k][0],
              degenerate[k][1], m, budget);
        CHECK(m >= N_LOOP, "cells %g x %g: %zu samples for %d vertices", degenerate[k][0],
              degenerate[k][1], m, N_LOOP);
        sw__gpu_border_loop_free(bl);
    }
    free(uv);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}

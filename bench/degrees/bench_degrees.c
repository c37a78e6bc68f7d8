/* bench/degrees — Guthe et al. 2005 §9, Fig. 10: the cost of approximating an animated trimmed
 * surface as its degree grows. A 10 x 10 rational B-spline surface (degrees 3x3, 5x5, 7x7, uniform
 * clamped knots) whose control points move by a sine over 100 frames, trimmed by one closed loop
 * (a degree-d B-spline curve of 10 control points). Every frame rebuilds what the CPU must:
 * the bicubic hierarchy within the leaf tolerance over the trim region's box (lod/hierarchy.c:
 * extraction, G1 reduction, leaf subdivision, median-cut simplification, rigorous bounds,
 * derivative constants) and the rational cubic approximation of the trim loop.
 *
 * Prints per degree: median and maximum approximation time per frame (ms), of which the trim
 * loop, the median number of bicubic leaves and hierarchy nodes. Tessellation (GPU) time is not
 * measured here.
 *
 * Usage: bench_degrees [frames (100)] [relative leaf tolerance (1e-3 of the box diagonal)]
 */
#include "sw_lod_hierarchy.h"
#include "sw_lod_reduce.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

enum { N = 10 };

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void clamped_knots(int d, double *k)
{
    for (int i = 0; i < N + d + 1; ++i)
        k[i] = i <= d ? 0.0 : i >= N ? 1.0 : (double)(i - d) / (N - d);
}

/* Frame f of the animation: a wavy sheet whose heights and weights move with a sine. */
static void animate(int f, int frames, double *cpw)
{
    const double ph = 2.0 * M_PI * f / frames;
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            double *c = cpw + (j * N + i) * 4;
            const double w = 1.0 + 0.3 * sin(ph + 0.9 * i - 0.4 * j);
            const double z = 2.0 * sin(ph + 0.6 * i) * cos(0.5 * j - ph);
            c[0] = w * i, c[1] = w * j, c[2] = w * z, c[3] = w;
        }
}

/* A closed trim loop in (u, v): degree d, 10 control points, the first d repeated at the end
 * (periodic), on a wobbly circle around the domain's centre; box returned in box[4]. */
static void trim_loop(int d, double *knots, double *cpw, int *n, double box[4])
{
    const int base = N, count = base + d;
    box[0] = box[2] = 1.0;
    box[1] = box[3] = 0.0;
    for (int i = 0; i < count; ++i) {
        const double a = 2.0 * M_PI * (i % base) / base, r = 0.3 + 0.05 * cos(3.0 * a);
        const double w = 1.0 + 0.2 * ((i % base) & 1);
        const double u = 0.5 + r * cos(a), v = 0.5 + r * sin(a);
        cpw[i * 3] = w * u, cpw[i * 3 + 1] = w * v, cpw[i * 3 + 2] = w;
        box[0] = fmin(box[0], u), box[1] = fmax(box[1], u);
        box[2] = fmin(box[2], v), box[3] = fmax(box[3], v);
    }
    for (int i = 0; i < count + d + 1; ++i) /* uniform, unclamped: a periodic curve */
        knots[i] = (double)i / (count + d);
    *n = count;
}

int main(int argc, char **argv)
{
    const int frames = argc > 1 ? atoi(argv[1]) : 100;
    const double rel_tol = argc > 2 ? atof(argv[2]) : 1e-3;
    if (frames < 1 || !(rel_tol > 0.0)) {
        fprintf(stderr, "usage: bench_degrees [frames] [relative tolerance]\n");
        return 2;
    }
    double *t_all = malloc((size_t)frames * sizeof *t_all),
           *t_trim = malloc((size_t)frames * sizeof *t_trim);
    double *leaves = malloc((size_t)frames * sizeof *leaves),
           *nodes = malloc((size_t)frames * sizeof *nodes);
    if (!t_all || !t_trim || !leaves || !nodes)
        return 2;
    printf("bench/degrees: 10x10 control points, %d frames, leaf tolerance %.3g x box diagonal\n",
           frames, rel_tol);
    printf("degree  approx ms/frame (median, max)  of which trim loop  bicubic leaves  nodes\n");
    for (int d = 3; d <= 7; d += 2) {
        double ku[N + 8], kv[N + 8], cpw[N * N * 4], tk[40], tc[40 * 3], box[4];
        int tn;
        clamped_knots(d, ku);
        clamped_knots(d, kv);
        trim_loop(d, tk, tc, &tn, box);
        sw_sg_curve trim = {d, tn, 3, tk, tc};
        for (int f = 0; f < frames; ++f) {
            animate(f, frames, cpw);
            sw_sg_surface s = {d, d, N, N, ku, kv, cpw};
            /* the surface spans ~9 x 9 x 4 units */
            sw_lod_hierarchy_desc desc = {0};
            desc.leaf_tolerance = rel_tol * sqrt(81.0 + 81.0 + 16.0);
            desc.use_box = 1;
            for (int k = 0; k < 4; ++k)
                desc.uv_box[k] = box[k];
            const double t0 = now_ms();
            sw_lod_hierarchy *h = NULL;
            if (sw_lod_hierarchy_build(&s, &desc, &h, NULL) != SW_OK)
                return 1;
            const double t1 = now_ms();
            sw_lod_reduce_desc rd = {1e-4, 0, {0.0, 0}};
            sw_lod_cubic_set cs;
            if (sw_lod_trim_curve_to_cubics(&trim, &rd, &cs, NULL) != SW_OK)
                return 1;
            const double t2 = now_ms();
            t_all[f] = t2 - t0;
            t_trim[f] = t2 - t1;
            leaves[f] = h->n_leaves;
            nodes[f] = h->n_nodes;
            sw_lod_cubic_set_free(&cs);
            sw_lod_hierarchy_free(h);
        }
        qsort(t_all, (size_t)frames, sizeof *t_all, cmp_double);
        qsort(t_trim, (size_t)frames, sizeof *t_trim, cmp_double);
        qsort(leaves, (size_t)frames, sizeof *leaves, cmp_double);
        qsort(nodes, (size_t)frames, sizeof *nodes, cmp_double);
        printf("%dx%d     %8.3f %8.3f                %8.3f          %6.0f       %6.0f\n", d, d,
               t_all[frames / 2], t_all[frames - 1], t_trim[frames / 2], leaves[frames / 2],
               nodes[frames / 2]);
    }
    free(t_all);
    free(t_trim);
    free(leaves);
    free(nodes);
    return 0;
}

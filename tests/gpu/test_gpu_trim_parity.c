/* Trim-texture parity exactness (Guthe et al. 2005 §4; PLATFORM.md): a concave star with a hole
 * and an island inside the hole is rendered by gpu/trim_texture.c (fans toggling texels, then
 * crack-filling lines that set them) and compared with a CPU even-odd classification of every
 * texel centre written here. Texels farther than one texel from every loop segment must agree
 * exactly; texels on the boundary band may only be set (boundary texels count as inside).
 * Several resolutions and a box that is neither square nor at the origin.
 */
#include "sw_gpu_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STAR_POINTS 7
#define HOLE_N 96

typedef struct shape {
    double star[4 * STAR_POINTS], hole[2 * HOLE_N], island[8];
    sw_sg_polyline loops[3];
} shape;

static void make_shape(shape *s, const double box[4])
{
    double cu = 0.5 * (box[0] + box[1]), cv = 0.5 * (box[2] + box[3]);
    double su = box[1] - box[0], sv = box[3] - box[2];
    for (int k = 0; k < 2 * STAR_POINTS; ++k) { /* deep concavities: inner radius 0.18 */
        double r = (k % 2) ? 0.18 : 0.47, a = 0.3 + M_PI * k / STAR_POINTS;
        s->star[2 * k] = cu + su * r * cos(a);
        s->star[2 * k + 1] = cv + sv * r * sin(a);
    }
    for (int k = 0; k < HOLE_N; ++k) { /* hole inside the star's core */
        double a = 2.0 * M_PI * k / HOLE_N;
        s->hole[2 * k] = cu + su * 0.13 * cos(a);
        s->hole[2 * k + 1] = cv + sv * 0.13 * sin(a);
    }
    static const double isl[8] = {-0.05, -0.04, 0.06, -0.05, 0.045, 0.05, -0.055, 0.035};
    for (int k = 0; k < 4; ++k) { /* island inside the hole */
        s->island[2 * k] = cu + su * isl[2 * k];
        s->island[2 * k + 1] = cv + sv * isl[2 * k + 1];
    }
    s->loops[0] = (sw_sg_polyline){s->star, 2 * STAR_POINTS};
    s->loops[1] = (sw_sg_polyline){s->hole, HOLE_N};
    s->loops[2] = (sw_sg_polyline){s->island, 4};
}

/* Crossing-number (even-odd) test over all loops. */
static int cpu_inside(const sw_sg_polyline *loops, int n, double u, double v)
{
    int in = 0;
    for (int l = 0; l < n; ++l) {
        const double *p = loops[l].uv;
        uint32_t c = loops[l].count;
        for (uint32_t i = 0, j = c - 1; i < c; j = i++) {
            double ui = p[2 * i], vi = p[2 * i + 1], uj = p[2 * j], vj = p[2 * j + 1];
            if ((vi > v) != (vj > v) && u < (uj - ui) * (v - vi) / (vj - vi) + ui)
                in = !in;
        }
    }
    return in;
}

/* Distance in texel units from (x, y) (texel coordinates) to the nearest loop segment. */
static double texel_dist(const sw_sg_polyline *loops, int n, const double box[4], int w, int h,
                         double x, double y)
{
    double sx = w / (box[1] - box[0]), sy = h / (box[3] - box[2]), best = INFINITY;
    for (int l = 0; l < n; ++l) {
        const double *p = loops[l].uv;
        uint32_t c = loops[l].count;
        for (uint32_t i = 0, j = c - 1; i < c; j = i++) {
            double ax = (p[2 * j] - box[0]) * sx, ay = (p[2 * j + 1] - box[2]) * sy;
            double bx = (p[2 * i] - box[0]) * sx, by = (p[2 * i + 1] - box[2]) * sy;
            double dx = bx - ax, dy = by - ay, ex = x - ax, ey = y - ay;
            double t = (dx * ex + dy * ey) / (dx * dx + dy * dy);
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            best = fmin(best, hypot(ex - t * dx, ey - t * dy));
        }
    }
    return best;
}

static int run(sw_gpu_context *ctx, int w, int h, const double box[4])
{
    shape s;
    make_shape(&s, box);
    sw_status st = {0};
    GLuint tex = 0;
    uint8_t *texels = malloc((size_t)w * (size_t)h);
    if (!texels || sw__gpu_trim_texture_make(ctx, s.loops, 3, box, w, h, &tex, &st) != SW_OK ||
        sw__gpu_trim_texture_read(ctx, tex, w, h, texels, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        free(texels);
        return 0;
    }
    glDeleteTextures(1, &tex);
    long far_wrong = 0, far = 0, band = 0, band_unset_inside = 0, inside = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            double u = box[0] + (x + 0.5) * (box[1] - box[0]) / w;
            double v = box[2] + (y + 0.5) * (box[3] - box[2]) / h;
            int want = cpu_inside(s.loops, 3, u, v);
            int got = texels[(size_t)y * (size_t)w + (size_t)x] >= 128;
            inside += want;
            if (texel_dist(s.loops, 3, box, w, h, x + 0.5, y + 0.5) <= 1.0) {
                ++band;
                band_unset_inside += want && !got;
                continue;
            }
            ++far;
            if (got != want) {
                if (far_wrong < 5)
                    fprintf(stderr, "  texel (%d,%d): gpu %d cpu %d\n", x, y, got, want);
                ++far_wrong;
            }
        }
    }
    printf("trim parity %dx%d: %ld texels away from the loops (%ld inside), %ld wrong; %ld in "
           "the 1-texel band, %ld of them inside but not set\n",
           w, h, far, inside, far_wrong, band, band_unset_inside);
    free(texels);
    return far_wrong == 0 && band_unset_inside == 0 && inside > (long)w * h / 10;
}

int main(void)
{
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    static const double unit[4] = {0.0, 1.0, 0.0, 1.0};
    static const double offset[4] = {1234.5, 1240.25, -3.0, 0.5};
    int ok = run(ctx, 256, 256, unit);
    ok &= run(ctx, 1024, 1024, unit);
    ok &= run(ctx, 777, 301, offset);
    ok &= run(ctx, 1280, 960, offset);
    sw_gpu_context_free(ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

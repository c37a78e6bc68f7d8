/* SPDX-License-Identifier: MIT */
/* Trim loops restricted to a tile of a face's trim box (Guthe et al. 2005 §5.3, §7: a close-up
 * needs trim textures finer than one texture over the whole face can hold, so frame.c splits the
 * face's trim box into tiles, each with its own texture). Two pieces of geometry:
 *  - classification of a tile against the flattened loops: crossed by a loop, or entirely inside
 *    or outside the trimmed region (then one point decides: even-odd parity is constant on a
 *    connected set no loop crosses);
 *  - Sutherland–Hodgman clipping of each loop to a (slightly grown) tile: inside the rectangle the
 *    clipped polygon has the same even-odd parity as the original (the clip only replaces the
 *    parts outside by pieces of the rectangle's border), unlike clamping vertices to it, which
 *    can cut chords across the rectangle.
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int sw__gpu_segment_clip(const double a[2], const double b[2], const double r[4], double t[2])
{
    double t0 = 0.0, t1 = 1.0, d[2] = {b[0] - a[0], b[1] - a[1]};
    for (int k = 0; k < 2; ++k) {
        double lo = r[2 * k], hi = r[2 * k + 1];
        if (d[k] == 0.0) {
            if (a[k] < lo || a[k] > hi)
                return 0;
            continue;
        }
        double ta = (lo - a[k]) / d[k], tb = (hi - a[k]) / d[k];
        if (ta > tb) {
            double x = ta;
            ta = tb;
            tb = x;
        }
        t0 = fmax(t0, ta);
        t1 = fmin(t1, tb);
        if (t0 > t1)
            return 0;
    }
    t[0] = t0;
    t[1] = t1;
    return 1;
}

static int segment_meets_rect(const double a[2], const double b[2], const double r[4])
{
    double t[2];
    return sw__gpu_segment_clip(a, b, r, t);
}

static int loop_meets_rect(const sw_sg_polyline *l, const double r[4])
{
    for (uint32_t i = 0; i < l->count; ++i) {
        const double *a = l->uv + 2 * i, *b = l->uv + 2 * ((i + 1) % l->count);
        if (fmax(a[0], b[0]) < r[0] || fmin(a[0], b[0]) > r[1] || fmax(a[1], b[1]) < r[2] ||
            fmin(a[1], b[1]) > r[3])
            continue;
        if (segment_meets_rect(a, b, r))
            return 1;
    }
    return 0;
}

int sw__gpu_trim_rect_class(const sw_sg_polyline *loops, uint32_t n_loops, const double rect[4])
{
    for (uint32_t k = 0; k < n_loops; ++k)
        if (loop_meets_rect(&loops[k], rect))
            return 0;
    return sw_sg_trim_classify(loops, n_loops, 0.5 * (rect[0] + rect[1]), 0.5 * (rect[2] + rect[3]))
               ? 1
               : -1;
}

/* Clips polygon in[n] against one side of the rectangle: coordinate k >= bound (sign 1) or
 * <= bound (sign -1). Returns the output count (at most 2n). */
static size_t clip_side(const double *in, size_t n, int k, double bound, double sign, double *out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *a = in + 2 * i, *b = in + 2 * ((i + 1) % n);
        double da = sign * (a[k] - bound), db = sign * (b[k] - bound);
        if (da >= 0.0) {
            out[2 * m] = a[0];
            out[2 * m + 1] = a[1];
            ++m;
        }
        if ((da >= 0.0) != (db >= 0.0)) {
            double t = da / (da - db);
            out[2 * m + k] = bound;
            out[2 * m + (1 - k)] = a[1 - k] + t * (b[1 - k] - a[1 - k]);
            ++m;
        }
    }
    return m;
}

/* Clips one loop to rect; out->uv allocated (count may be 0). Each side at most doubles the
 * vertex count (a kept vertex and a crossing per edge), so every stage gets a fresh buffer. */
static sw_result clip_loop(const sw_sg_polyline *l, const double r[4], sw_sg_polyline *out,
                           sw_status *status)
{
    size_t n = l->count;
    double *a = sw__malloc((2 * n + 2) * sizeof *a);
    if (!a)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim tile: out of memory");
    memcpy(a, l->uv, 2 * n * sizeof *a);
    for (int side = 0; side < 4; ++side) {
        double *b = sw__malloc((4 * n + 2) * sizeof *b);
        if (!b) {
            sw__free(a);
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim tile: out of memory");
        }
        n = clip_side(a, n, side / 2, r[side], side % 2 ? -1.0 : 1.0, b);
        sw__free(a);
        a = b;
    }
    out->uv = a;
    out->count = (uint32_t)n;
    return SW_OK;
}

sw_result sw__gpu_trim_clip_loops(const sw_sg_polyline *loops, uint32_t n_loops,
                                  const double rect[4], sw_sg_polyline *out, sw_status *status)
{
    memset(out, 0, n_loops * sizeof *out);
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < n_loops && r == SW_OK; ++k)
        r = clip_loop(&loops[k], rect, &out[k], status);
    if (r != SW_OK)
        for (uint32_t k = 0; k < n_loops; ++k)
            sw_sg_polyline_free(&out[k]);
    return r;
}

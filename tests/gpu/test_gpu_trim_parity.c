/* SPDX-License-Identifier: MIT */
/* Trim-texture parity exactness through the trim atlas (Guthe et al. 2005 §4, §4.4; PLATFORM.md):
 * concave stars with a hole and an island inside the hole, each a different rotation and uv box,
 * are packed as entries into atlas pages (limited to 1024^2 so that pages hold several entries,
 * entries touch the pages' edges and a frame needs several pages), rendered by gpu/trim_atlas.c
 * (all fans of a page in one pass toggling texels, then crack-filling lines that set them), read
 * back page by page and compared, entry by entry, with a CPU even-odd classification of every
 * texel centre written here. Texels farther than one texel from every loop segment must agree
 * exactly; texels on the boundary band may only be set (boundary texels count as inside).
 *
 * Five frames exercise the cache: frame 2 finds every entry of frame 1 (nothing re-rendered)
 * and appends new ones into free space beside them (whose fans must not disturb the old entries);
 * frame 3 keeps some and adds one that needs a new page (the array texture grows, old layers
 * copied); frame 4, with a larger page size allowed, adds one larger than a page, forcing a
 * repack of every entry it uses into fresh pages; frame 5 adds a page whose first loop is empty,
 * as a loop clipped away by a trim tile is (llvmpipe skipped a whole multi-draw whose first draw
 * had no vertices: the page stayed blank).
 */
#include "sw_gpu_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STAR_POINTS 7
#define HOLE_N 96
#define MAX_ENTRIES 16

typedef struct shape {
    double star[4 * STAR_POINTS], hole[2 * HOLE_N], island[8];
    sw_sg_polyline all[4]; /* an empty loop, then the star, the hole and the island */
    const sw_sg_polyline *loops;
    uint32_t n_loops;
    double box[4];
    int w, h;
    int32_t id;
    sw__gpu_trim_key key;
} shape;

static void make_shape(shape *s, const double box[4], int w, int h, double phase, uint32_t face,
                       int leading_empty)
{
    memcpy(s->box, box, sizeof s->box);
    s->w = w;
    s->h = h;
    double cu = 0.5 * (box[0] + box[1]), cv = 0.5 * (box[2] + box[3]);
    double su = box[1] - box[0], sv = box[3] - box[2];
    for (int k = 0; k < 2 * STAR_POINTS; ++k) { /* deep concavities: inner radius 0.18 */
        double r = (k % 2) ? 0.18 : 0.47, a = phase + M_PI * k / STAR_POINTS;
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
    s->all[0] = (sw_sg_polyline){.uv = s->star, .count = 0};
    s->all[1] = (sw_sg_polyline){.uv = s->star, .count = 2 * STAR_POINTS};
    s->all[2] = (sw_sg_polyline){.uv = s->hole, .count = HOLE_N};
    s->all[3] = (sw_sg_polyline){.uv = s->island, .count = 4};
    s->loops = leading_empty ? s->all : s->all + 1;
    s->n_loops = leading_empty ? 4 : 3;
    s->key = (sw__gpu_trim_key){1u, face, 4 * face, s->n_loops, {box[0], box[1], box[2], box[3]}};
    s->id = -1;
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

/* Checks one entry against the CPU classification, reading its rectangle from `page`. */
static int check_entry(sw_gpu_context *ctx, const shape *s, const uint8_t *page, int side)
{
    sw__gpu_trim_rect rc;
    sw__gpu_atlas_rect(ctx, s->id, &rc);
    int w = s->w, h = s->h;
    if (rc.w != w || rc.h != h || rc.x0 < 0 || rc.y0 < 0 || rc.x0 + w > side || rc.y0 + h > side) {
        fprintf(stderr,
                "entry %u: rectangle (%d,%d %dx%d) does not fit its %dx%d texture in a "
                "%d^2 page\n",
                s->key.face, rc.x0, rc.y0, rc.w, rc.h, w, h, side);
        return 0;
    }
    const double *box = s->box;
    long far_wrong = 0, far = 0, band = 0, band_unset_inside = 0, inside = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            double u = box[0] + (x + 0.5) * (box[1] - box[0]) / w;
            double v = box[2] + (y + 0.5) * (box[3] - box[2]) / h;
            int want = cpu_inside(s->loops, (int)s->n_loops, u, v);
            int got = page[(size_t)(rc.y0 + y) * (size_t)side + (size_t)(rc.x0 + x)] >= 128;
            inside += want;
            if (texel_dist(s->loops, (int)s->n_loops, box, w, h, x + 0.5, y + 0.5) <= 1.0) {
                ++band;
                band_unset_inside += want && !got;
                continue;
            }
            ++far;
            if (got != want) {
                if (far_wrong < 5)
                    fprintf(stderr, "  entry %u texel (%d,%d): gpu %d cpu %d\n", s->key.face, x, y,
                            got, want);
                ++far_wrong;
            }
        }
    }
    printf("  entry %2u %4dx%-4d page %d at (%4d,%4d): %7ld texels away from the loops (%ld "
           "inside), %ld wrong; %ld in the 1-texel band, %ld of them inside but not set\n",
           s->key.face, w, h, rc.layer, rc.x0, rc.y0, far, inside, far_wrong, band,
           band_unset_inside);
    return far_wrong == 0 && band_unset_inside == 0 && inside > (long)w * h / 20;
}

/* Reads every page and checks the listed entries. */
static int check_all(sw_gpu_context *ctx, shape *const *list, int n)
{
    uint8_t *page = malloc(4096u * 4096u);
    int ok = page != NULL;
    for (int layer = 0; ok && layer < 64; ++layer) {
        int any = 0;
        for (int i = 0; i < n; ++i) {
            sw__gpu_trim_rect rc;
            sw__gpu_atlas_rect(ctx, list[i]->id, &rc);
            any |= rc.layer == layer;
        }
        if (!any)
            continue;
        sw_status st = {0};
        int32_t side = 0;
        if (sw__gpu_atlas_read_page(ctx, layer, page, 4096u * 4096u, &side, &st) != SW_OK) {
            fprintf(stderr, "FAIL: %s\n", st.message);
            ok = 0;
            break;
        }
        for (int i = 0; i < n; ++i) {
            sw__gpu_trim_rect rc;
            sw__gpu_atlas_rect(ctx, list[i]->id, &rc);
            if (rc.layer == layer)
                ok &= check_entry(ctx, list[i], page, side);
        }
    }
    free(page);
    return ok;
}

/* One frame: find or add every shape of `list`, commit, check. */
static int frame(sw_gpu_context *ctx, shape *const *list, int n, sw__gpu_atlas_stats *as,
                 const char *what)
{
    sw_status st = {0};
    if (sw__gpu_atlas_begin(ctx, &st) != SW_OK)
        return fprintf(stderr, "FAIL: %s\n", st.message), 0;
    for (int i = 0; i < n; ++i) {
        shape *s = list[i];
        s->id = sw__gpu_atlas_find(ctx, &s->key, s->w, s->h);
        if (s->id < 0 &&
            sw__gpu_atlas_add(ctx, &s->key, s->w, s->h, s->loops, s->n_loops, &s->id, &st) != SW_OK)
            return fprintf(stderr, "FAIL: add: %s\n", st.message), 0;
    }
    if (sw__gpu_atlas_commit(ctx, as, &st) != SW_OK)
        return fprintf(stderr, "FAIL: commit: %s\n", st.message), 0;
    printf("%s: %u entries (%u reused, %u rendered), %u pages of %d^2, %u render-target "
           "switches, %u repacks\n",
           what, as->entries, as->reused, as->rendered, as->pages, (int)as->side, as->switches,
           as->repacks);
    return check_all(ctx, list, n);
}

int main(void)
{
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    sw__gpu_atlas_set_max_side(ctx, 1024);
    int cap = sw__gpu_atlas_max_entry(ctx);
    static const double unit[4] = {0.0, 1.0, 0.0, 1.0};
    static const double offset[4] = {1234.5, 1240.25, -3.0, 0.5};
    static const double thin[4] = {-0.25, 0.75, 10.0, 10.125};
    shape s[MAX_ENTRIES];
    /* Frame 1: a full-width entry and a full-height one (page edges), and several per page. */
    make_shape(&s[0], unit, cap, 100, 0.3, 0, 0);
    make_shape(&s[1], offset, 300, cap, 0.9, 1, 0);
    make_shape(&s[2], unit, 256, 256, 1.7, 2, 0);
    make_shape(&s[3], offset, 777, 301, 2.2, 3, 0);
    make_shape(&s[4], thin, 400, 60, 0.1, 4, 0);
    make_shape(&s[5], unit, 128, 512, 2.9, 5, 0);
    make_shape(&s[6], offset, 60, 60, 0.5, 6, 0);
    /* Frame 2 adds, frame 3 adds one that forces a repack. */
    make_shape(&s[7], unit, 200, 90, 1.1, 7, 0);
    make_shape(&s[8], thin, 90, 200, 2.5, 8, 0);
    make_shape(&s[9], offset, cap, cap, 0.7, 9, 0);
    make_shape(&s[10], unit, 1500, 1100, 1.3, 10, 0);
    shape *f1[] = {&s[0], &s[1], &s[2], &s[3], &s[4], &s[5], &s[6]};
    shape *f2[] = {&s[0], &s[1], &s[2], &s[3], &s[4], &s[5], &s[6], &s[7], &s[8]};
    shape *f3[] = {&s[2], &s[3], &s[7], &s[9], &s[5]};
    shape *f4[] = {&s[9], &s[10], &s[0], &s[3]};
    /* Frame 5: one that fills a page of its own, its first loop empty, and one beside old ones. */
    make_shape(&s[11], offset, 2048 - 2 * SW__GPU_ATLAS_GUTTER, 1100, 2.0, 11, 1);
    make_shape(&s[12], thin, 64, 64, 0.4, 12, 1);
    shape *f5[] = {&s[9], &s[10], &s[11], &s[12]};
    sw__gpu_atlas_stats a1, a2, a3, a4, a5;
    int ok = frame(ctx, f1, 7, &a1, "frame 1");
    ok &= a1.rendered == 7 && a1.pages >= 2 && a1.switches == a1.pages;
    ok &= frame(ctx, f2, 9, &a2, "frame 2");
    ok &= a2.reused == 7 && a2.rendered == 2 && a2.repacks == 0 && a2.switches <= 2;
    ok &= frame(ctx, f3, 5, &a3, "frame 3");
    ok &= a3.reused == 4 && a3.rendered == 1 && a3.repacks == 0 && a3.pages > a2.pages;
    sw__gpu_atlas_set_max_side(ctx, 2048);
    ok &= frame(ctx, f4, 4, &a4, "frame 4");
    ok &= a4.repacks == 1 && a4.rendered == 4 && a4.side == 2048 && a4.switches == a4.pages;
    ok &= frame(ctx, f5, 4, &a5, "frame 5");
    ok &= a5.repacks == 0 && a5.rendered == 2 && a5.pages > a4.pages;
    sw_gpu_context_free(ctx);
    puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

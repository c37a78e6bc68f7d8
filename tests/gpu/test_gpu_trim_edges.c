/* SPDX-License-Identifier: MIT */
/* Exact trim edges' grids (gpu/trim_edges.c): the fragment shader's classification, run on the CPU
 * in float exactly as the shader does it (sw__gpu_edge_grid_inside), against the even-odd
 * classification in double of the same loops (sw_sg_trim_classify, the trim textures' rule).
 * Loops: a plate with a round hole and a slot; axis-aligned loops on the grid's cell lines and
 * on the lines through the cells' centres (where a careless reference point would lie on a
 * segment); a 61-point star whose spikes cross many cells; a loop whose vertices sit on the
 * horizontal lines through the reference points (the scanline's vertex cases). Rectangles: the
 * whole box, tiles of it (some crossed by no loop, inside or outside), one reaching past it.
 * Check: at 20,000 random points per case and on a lattice through the cells' corners, the two
 * agree wherever the point is farther than 1e-5 of the rectangle from every segment (closer, the
 * two arithmetics may round either way: that is an edge displacement of ~1e-5 texel).
 * Planted faults, each seen failing: the scanline not half-open in y (a vertex on it counted
 * twice or not at all) → "vertex rows" fails; the CPU test reading every cell's reference point
 * as the first candidate's → the cells that took another fail; the crossing test without its
 * second condition (the path's ends on either side of the segment's line) → every case fails; no
 * margin around the reference points (k_ref_margin 0) → the "blocked" cells keep a reference
 * point on a segment: 5,131 points wrong.
 * No GL needed. */
#include "sw_gpu_internal.h"
#include "test_check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_LOOPS = 4, SAMPLES = 20000 };

typedef struct loops {
    sw_sg_polyline l[MAX_LOOPS];
    uint32_t n;
} loops;

static void add_loop(loops *s, const double *uv, uint32_t count)
{
    sw_sg_polyline *p = &s->l[s->n++];
    memset(p, 0, sizeof *p);
    p->uv = malloc(2 * count * sizeof *p->uv);
    memcpy(p->uv, uv, 2 * count * sizeof *p->uv);
    p->count = count;
}

static void add_circle(loops *s, double cx, double cy, double r, uint32_t n, int clockwise)
{
    double *uv = malloc(2 * n * sizeof *uv);
    for (uint32_t i = 0; i < n; ++i) {
        double a = (clockwise ? -1.0 : 1.0) * 2.0 * M_PI * i / n;
        uv[2 * i] = cx + r * cos(a);
        uv[2 * i + 1] = cy + r * sin(a);
    }
    add_loop(s, uv, n);
    free(uv);
}

static void add_rect(loops *s, double u0, double u1, double v0, double v1)
{
    const double uv[8] = {u0, v0, u1, v0, u1, v1, u0, v1};
    add_loop(s, uv, 4);
}

static void free_loops(loops *s)
{
    for (uint32_t k = 0; k < s->n; ++k)
        free(s->l[k].uv);
    s->n = 0;
}

static double segment_distance(const double p[2], const double *a, const double *b)
{
    double e[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {p[0] - a[0], p[1] - a[1]};
    double ee = e[0] * e[0] + e[1] * e[1];
    double t = ee > 0.0 ? (w[0] * e[0] + w[1] * e[1]) / ee : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return hypot(w[0] - t * e[0], w[1] - t * e[1]);
}

static double loops_distance(const loops *s, const double p[2])
{
    double d = INFINITY;
    for (uint32_t k = 0; k < s->n; ++k)
        for (uint32_t i = 0; i < s->l[k].count; ++i)
            d = fmin(d, segment_distance(p, s->l[k].uv + 2 * i,
                                         s->l[k].uv + 2 * ((i + 1) % s->l[k].count)));
    return d;
}

/* One point: 1 when it disagrees away from the loops. */
static int disagrees(const loops *s, const sw__gpu_edge_grids *g, int32_t grid, const double r[4],
                     float st0, float st1)
{
    /* the point the shader classifies: st as float, mapped back in double */
    const double p[2] = {r[0] + (double)st0 * (r[1] - r[0]), r[2] + (double)st1 * (r[3] - r[2])};
    const double scale = fmax(r[1] - r[0], r[3] - r[2]);
    if (loops_distance(s, p) < 1e-5 * scale)
        return 0;
    return sw__gpu_edge_grid_inside(g, grid, st0, st1) !=
           sw_sg_trim_classify(s->l, s->n, p[0], p[1]);
}

static void check_rect(const char *name, const loops *s, const double r[4], unsigned seed)
{
    sw__gpu_edge_grids g;
    memset(&g, 0, sizeof g);
    int32_t grid = -1;
    sw_status st = {0};
    CHECK(sw__gpu_edge_grid_add(&g, s->l, s->n, r, &grid, &st) == SW_OK, "%s: add failed: %s", name,
          st.message);
    CHECK(grid == 0, "%s: no grid made", name);
    if (grid < 0) {
        sw__gpu_edge_grids_free(&g);
        return;
    }
    const sw__gpu_edge_grid *h = &g.grids[grid];
    size_t bad = 0, tried = 0, max_cell = 0;
    for (uint32_t c = 0; c < h->n[0] * h->n[1]; ++c) {
        size_t n = g.cells[2 * (h->first_cell + c) + 1] >> 4;
        max_cell = n > max_cell ? n : max_cell;
    }
    srand(seed);
    for (int i = 0; i < SAMPLES; ++i, ++tried)
        bad += (size_t)disagrees(s, &g, grid, r, (float)rand() / (float)RAND_MAX,
                                 (float)rand() / (float)RAND_MAX);
    /* the lattice through the cells' corners and sides: points on cell sides */
    for (uint32_t j = 0; j <= 4 * h->n[1]; ++j)
        for (uint32_t i = 0; i <= 4 * h->n[0]; ++i, ++tried)
            bad += (size_t)disagrees(s, &g, grid, r, (float)i / (float)(4 * h->n[0]),
                                     (float)j / (float)(4 * h->n[1]));
    printf("  %-28s %ux%u cells, %zu entries, max %zu per cell: %zu of %zu points disagree\n", name,
           h->n[0], h->n[1], g.n_segs, max_cell, bad, tried);
    CHECK(bad == 0, "%s: %zu points classified unlike the loops", name, bad);
    sw__gpu_edge_grids_free(&g);
}

/* The whole box, its 4 x 4 tiles and a rectangle reaching beyond the box. */
static void check_loops(const char *name, const loops *s, const double box[4], unsigned seed)
{
    char label[64];
    snprintf(label, sizeof label, "%s whole", name);
    check_rect(label, s, box, seed);
    const double w = (box[1] - box[0]) / 4.0, h = (box[3] - box[2]) / 4.0;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const double r[4] = {box[0] + i * w, box[0] + (i + 1) * w, box[2] + j * h,
                                 box[2] + (j + 1) * h};
            snprintf(label, sizeof label, "%s tile %d,%d", name, i, j);
            check_rect(label, s, r, seed + 1u + (unsigned)(4 * j + i));
        }
    const double past[4] = {box[0] - w, box[1] - 2.5 * w, box[2] + 0.5 * h, box[3] + h};
    snprintf(label, sizeof label, "%s past the box", name);
    check_rect(label, s, past, seed + 99u);
}

static void star(loops *s, uint32_t spikes, double cx, double cy, double r0, double r1)
{
    double *uv = malloc(4 * spikes * sizeof *uv);
    for (uint32_t i = 0; i < 2 * spikes; ++i) {
        double a = M_PI * i / spikes, r = (i & 1) ? r0 : r1;
        uv[2 * i] = cx + r * cos(a);
        uv[2 * i + 1] = cy + r * sin(a);
    }
    add_loop(s, uv, 2 * spikes);
    free(uv);
}

int main(void)
{
    loops s = {0};
    /* a plate 40 x 30 mm with a bolt hole and a slot, loops as CAD files orient them */
    add_rect(&s, 0.0, 40.0, 0.0, 30.0);
    add_circle(&s, 12.0, 15.0, 5.0, 240, 1);
    add_rect(&s, 25.0, 35.0, 10.0, 12.5);
    check_loops("plate", &s, (const double[4]){0.0, 40.0, 0.0, 30.0}, 1);
    free_loops(&s);

    /* axis-aligned loops on cell lines and through the cells' middles, at several grid sizes */
    add_rect(&s, 0.0, 1.0, 0.0, 1.0);
    add_rect(&s, 0.25, 0.5, 0.25, 0.75);
    add_rect(&s, 0.5 + 1.0 / 128.0, 0.75, 0.5, 0.5 + 1.0 / 64.0);
    check_loops("aligned", &s, (const double[4]){0.0, 1.0, 0.0, 1.0}, 2);
    free_loops(&s);

    star(&s, 61, 0.5, 0.5, 0.1, 0.49);
    check_loops("star", &s, (const double[4]){0.0, 1.0, 0.0, 1.0}, 3);
    free_loops(&s);

    /* vertices exactly on the scanlines of the cells' first reference point (0.47265625 of a
     * cell up): 16 segments make an 8 x 8 grid, so (j + 0.47265625) / 8 is a scanline's height
     * in the unit box, exactly; the scanline must count such a vertex once (half-open) */
    {
        double uv[2 * 16];
        for (int i = 0; i < 8; ++i) { /* a zigzag along the bottom, left to right */
            uv[2 * i] = (i + 0.25) / 8.0;
            uv[2 * i + 1] = ((i & 1 ? 3 : 2) + 0.47265625) / 8.0;
        }
        for (int i = 0; i < 8; ++i) { /* and back along the top, vertices on scanlines too */
            uv[2 * (8 + i)] = (7 - i + 0.75) / 8.0;
            uv[2 * (8 + i) + 1] = ((i & 1 ? 6 : 5) + 0.47265625) / 8.0;
        }
        add_loop(&s, uv, 16);
        check_rect("vertex rows", &s, (const double[4]){0.0, 1.0, 0.0, 1.0}, 4);
        free_loops(&s);
    }

    /* segments through the first reference candidate of every cell they cross: a rectangle of 4
     * segments gets a 4 x 4 grid, and its horizontal sides at heights (j + 0.47265625) / 4 pass
     * exactly through candidate 0 of rows 1 and 2 (their vertices at x = 0.05 and 0.95 leave every
     * cell of those rows crossed). Those 8 cells must take another candidate, and classify right */
    {
        sw__gpu_edge_grids g;
        memset(&g, 0, sizeof g);
        int32_t grid = -1;
        sw_status st = {0};
        const double r[4] = {0.0, 1.0, 0.0, 1.0};
        add_rect(&s, 0.05, 0.95, (1 + 0.47265625) / 4.0, (2 + 0.47265625) / 4.0);
        CHECK(sw__gpu_edge_grid_add(&g, s.l, s.n, r, &grid, &st) == SW_OK && grid == 0,
              "blocked: no grid");
        uint32_t moved = 0;
        if (grid == 0 && g.grids[0].n[0] == 4 && g.grids[0].n[1] == 4)
            for (uint32_t c = 4; c < 12; ++c)
                moved += ((g.cells[2 * c + 1] >> 1) & 7u) != 0;
        printf("  blocked reference points: %u of the 8 cells on the sides took another\n", moved);
        CHECK(moved == 8, "blocked: %u of 8 cells moved off candidate 0", moved);
        sw__gpu_edge_grids_free(&g);
        check_rect("blocked", &s, r, 5);
        free_loops(&s);
    }
    printf(g_failures ? "FAILED (%d)\n" : "ok\n", g_failures);
    return g_failures != 0;
}

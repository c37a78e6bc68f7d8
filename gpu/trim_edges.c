/* SPDX-License-Identifier: MIT */
/* Exact trim edges: a draw's fragments classified against its face's trim loops in the face's
 * parameter domain, instead of a trim texture (Guthe et al. 2005 §4), whose texel is a staircase in
 * a close-up. Santana's curves are classified per fragment by their implicit form; trim loops
 * arrive here already flattened by sw_sg_trim_flatten_loop at a tolerance the caller sets from
 * the view (an eighth of a pixel), so each piece is a line segment and its implicit form is the
 * line's: the classification is exact for the flattened loop, whose distance from the true trim
 * curve the flattening bounds.
 *
 * A fragment cannot test every segment of a loop, so each draw gets a grid of cells over its
 * rectangle (its st in [0, 1]^2); a cell lists the segments that meet it and carries the
 * even-odd parity of one reference point inside it. A fragment's parity is its cell's XOR the
 * number of segments the straight path from the reference point to the fragment crosses: the path
 * stays inside the (convex) cell, so only the cell's segments can cross it. The parities are
 * computed here in double by scanlines through the reference points over all segments (those
 * outside the rectangle included: a loop around it counts). A cell's reference point is the
 * first of a few fixed candidates that no segment passes within k_ref_margin of, so the shader's
 * float arithmetic agrees with the double parity there; a segment through a vertex on the path is
 * counted once by the half-open side test, as a ray cast counts it. A cell's segments are stored
 * clipped to it (grown by k_cell_grow): the same crossings inside it, and short, so float keeps
 * ~1e-7 of a cell however long the loop's segment is.
 *
 * The shader's side (glsl/surface_trim.frag.glsl, whose sw_edge_refs must equal k_ref_candidates)
 * and sw__gpu_edge_grid_inside (its mirror on the CPU, for tests) read the same arrays: segment
 * ends relative to the cell's reference point, in cells, in float. */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_EDGE_CELLS = 64,          /* cells per direction */
    MAX_EDGE_ENTRIES = 1u << 20,  /* a grid's (cell, segment) entries */
    MAX_GRID_SEGMENTS = 1u << 22, /* segments of a draw's loops */
};
/* Least distance, in cells, of any segment of a cell from its reference point: float's rounding
 * of a clipped segment relative to it (~1e-7 cells) stays far below it. */
static const double k_ref_margin = 1e-4;
/* A segment belongs to the cells it meets grown by this much (in cells): one that touches a
 * cell's side in double still counts if float moves the fragment onto it. */
static const double k_cell_grow = 1e-4;

/* Reference points a cell may take, as fractions of it (exact in float), tried in order: away
 * from the centre and the quarter lines that axis-aligned loops often follow. */
static const float k_ref_candidates[SW__GPU_EDGE_REFS][2] = {{0.53125f, 0.47265625f},
                                                             {0.318359375f, 0.693359375f},
                                                             {0.70703125f, 0.271484375f},
                                                             {0.141601562f, 0.88671875f},
                                                             {0.618164062f, 0.577148438f}};

/* One segment of the loops, in cells of the grid. */
typedef struct grid_seg {
    double a[2], b[2];
} grid_seg;

typedef struct grid_build {
    grid_seg *segs; /* all segments of the loops */
    size_t n_segs;
    int32_t n[2];      /* cells per direction */
    uint32_t *count;   /* entries per cell, then (prefix) first entry */
    uint32_t *entries; /* segment index per (cell, segment) entry, cells in row order */
    size_t n_entries;
    uint8_t *ref; /* per cell: its reference point, of k_ref_candidates */
} grid_build;

static int32_t cells_for(size_t segments_in_rect)
{
    /* a loop of m segments crosses ~2 sqrt(m) of 4m cells: a few segments per crossed cell */
    double n = ceil(2.0 * sqrt((double)segments_in_rect));
    return n < 1.0 ? 1 : n > MAX_EDGE_CELLS ? MAX_EDGE_CELLS : (int32_t)n;
}

/* The loops' segments in cells of an n[0] x n[1] grid over rect; counts those meeting rect. */
static size_t segments_in_cells(const sw_sg_polyline *loops, uint32_t n_loops, const double r[4],
                                grid_seg *out, size_t *in_rect)
{
    const double su = 1.0 / (r[1] - r[0]), sv = 1.0 / (r[3] - r[2]);
    size_t n = 0;
    *in_rect = 0;
    for (uint32_t k = 0; k < n_loops; ++k) {
        const sw_sg_polyline *l = &loops[k];
        for (uint32_t i = 0; i < l->count; ++i) {
            const double *a = l->uv + 2 * i, *b = l->uv + 2 * ((i + 1) % l->count);
            double t[2];
            *in_rect += sw__gpu_segment_clip(a, b, r, t);
            out[n++] = (grid_seg){{(a[0] - r[0]) * su, (a[1] - r[2]) * sv},
                                  {(b[0] - r[0]) * su, (b[1] - r[2]) * sv}};
        }
    }
    return n;
}

/* Calls visit(g, cell, seg) for every cell of the grid that segment s meets (grown by
 * k_cell_grow). */
static void for_cells_of(grid_build *g, const grid_seg *s, uint32_t seg,
                         void (*visit)(grid_build *, size_t, uint32_t))
{
    const double lo[2] = {fmin(s->a[0], s->b[0]) - k_cell_grow,
                          fmin(s->a[1], s->b[1]) - k_cell_grow};
    const double hi[2] = {fmax(s->a[0], s->b[0]) + k_cell_grow,
                          fmax(s->a[1], s->b[1]) + k_cell_grow};
    if (hi[0] < 0.0 || hi[1] < 0.0 || lo[0] > g->n[0] || lo[1] > g->n[1])
        return;
    const int32_t i0 = lo[0] < 0.0 ? 0 : (int32_t)lo[0], j0 = lo[1] < 0.0 ? 0 : (int32_t)lo[1];
    const int32_t i1 = hi[0] >= g->n[0] ? g->n[0] - 1 : (int32_t)hi[0];
    const int32_t j1 = hi[1] >= g->n[1] ? g->n[1] - 1 : (int32_t)hi[1];
    for (int32_t j = j0; j <= j1; ++j)
        for (int32_t i = i0; i <= i1; ++i) {
            const double box[4] = {i - k_cell_grow, i + 1 + k_cell_grow, j - k_cell_grow,
                                   j + 1 + k_cell_grow};
            double t[2];
            if (sw__gpu_segment_clip(s->a, s->b, box, t))
                visit(g, (size_t)j * (size_t)g->n[0] + (size_t)i, seg);
        }
}

static void count_entry(grid_build *g, size_t cell, uint32_t seg)
{
    (void)seg;
    g->count[cell]++;
    g->n_entries++;
}

static void fill_entry(grid_build *g, size_t cell, uint32_t seg)
{
    g->entries[g->count[cell]++] = seg;
}

/* The cells' segment lists: count[c] .. count[c + 1] - 1 in entries (count becomes the prefix). */
static int list_cells(grid_build *g)
{
    const size_t n_cells = (size_t)g->n[0] * (size_t)g->n[1];
    g->count = sw__calloc(n_cells + 1, sizeof *g->count);
    if (!g->count)
        return 0;
    for (size_t s = 0; s < g->n_segs && g->n_entries <= MAX_EDGE_ENTRIES; ++s)
        for_cells_of(g, &g->segs[s], (uint32_t)s, count_entry);
    if (g->n_entries > MAX_EDGE_ENTRIES)
        return -1;
    uint32_t at = 0;
    for (size_t c = 0; c <= n_cells; ++c) {
        const uint32_t k = g->count[c];
        g->count[c] = at;
        at += k;
    }
    g->entries = sw__malloc((g->n_entries ? g->n_entries : 1) * sizeof *g->entries);
    if (!g->entries)
        return 0;
    for (size_t s = 0; s < g->n_segs; ++s)
        for_cells_of(g, &g->segs[s], (uint32_t)s, fill_entry);
    /* fill advanced each start to the next cell's: shift back */
    for (size_t c = n_cells; c > 0; --c)
        g->count[c] = g->count[c - 1];
    g->count[0] = 0;
    return 1;
}

static double point_segment_distance(const double p[2], const grid_seg *s)
{
    const double e[2] = {s->b[0] - s->a[0], s->b[1] - s->a[1]};
    const double w[2] = {p[0] - s->a[0], p[1] - s->a[1]};
    const double ee = e[0] * e[0] + e[1] * e[1];
    double t = ee > 0.0 ? (w[0] * e[0] + w[1] * e[1]) / ee : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return hypot(w[0] - t * e[0], w[1] - t * e[1]);
}

static void ref_point(int32_t i, int32_t j, int k, double p[2])
{
    p[0] = i + (double)k_ref_candidates[k][0];
    p[1] = j + (double)k_ref_candidates[k][1];
}

/* Each cell's reference point: the first candidate k_ref_margin clear of its segments; 0 when a
 * cell has none. */
static int choose_refs(grid_build *g)
{
    for (int32_t j = 0; j < g->n[1]; ++j)
        for (int32_t i = 0; i < g->n[0]; ++i) {
            const size_t c = (size_t)j * (size_t)g->n[0] + (size_t)i;
            int k = 0;
            for (; k < SW__GPU_EDGE_REFS; ++k) {
                double p[2];
                ref_point(i, j, k, p);
                uint32_t e = g->count[c];
                while (e < g->count[c + 1] &&
                       point_segment_distance(p, &g->segs[g->entries[e]]) >= k_ref_margin)
                    ++e;
                if (e == g->count[c + 1])
                    break;
            }
            if (k == SW__GPU_EDGE_REFS)
                return 0;
            g->ref[c] = (uint8_t)k;
        }
    return 1;
}

static int compare_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Even-odd parity of the reference points of row j's cells that take candidate k: the crossings
 * of the horizontal line through them with all segments (half-open in y, as sw_sg_trim_classify
 * counts), sorted; a point's parity is the number of crossings left of it. xs holds n_segs
 * doubles. */
static void row_parities(const grid_build *g, int32_t j, int k, double *xs, uint8_t *parity)
{
    double p[2];
    ref_point(0, j, k, p);
    const double y = p[1];
    size_t n = 0;
    for (size_t s = 0; s < g->n_segs; ++s) {
        const grid_seg *q = &g->segs[s];
        if ((q->a[1] > y) != (q->b[1] > y))
            xs[n++] = q->a[0] + (y - q->a[1]) / (q->b[1] - q->a[1]) * (q->b[0] - q->a[0]);
    }
    qsort(xs, n, sizeof *xs, compare_double);
    size_t left = 0;
    for (int32_t i = 0; i < g->n[0]; ++i) {
        if (g->ref[(size_t)j * (size_t)g->n[0] + (size_t)i] != k)
            continue;
        ref_point(i, j, k, p);
        while (left < n && xs[left] < p[0])
            ++left;
        parity[i] = (uint8_t)(left & 1u);
    }
}

/* The parities of row j's reference points, one scanline per candidate the row uses. */
static void row_all_parities(const grid_build *g, int32_t j, double *xs, uint8_t *parity)
{
    for (int k = 0; k < SW__GPU_EDGE_REFS; ++k) {
        int32_t i = 0;
        while (i < g->n[0] && g->ref[(size_t)j * (size_t)g->n[0] + (size_t)i] != k)
            ++i;
        if (i < g->n[0])
            row_parities(g, j, k, xs, parity);
    }
}

/* Segment s clipped to cell (i, j) grown by k_cell_grow, relative to reference point o, in float
 * (the part the cell listed it for: it meets the grown cell). */
static void clipped_entry(const grid_seg *s, int32_t i, int32_t j, const double o[2], float e[4])
{
    const double box[4] = {i - k_cell_grow, i + 1 + k_cell_grow, j - k_cell_grow,
                           j + 1 + k_cell_grow};
    double t[2] = {0.0, 1.0};
    (void)sw__gpu_segment_clip(s->a, s->b, box, t);
    const double d[2] = {s->b[0] - s->a[0], s->b[1] - s->a[1]};
    e[0] = (float)(s->a[0] + t[0] * d[0] - o[0]);
    e[1] = (float)(s->a[1] + t[0] * d[1] - o[1]);
    e[2] = (float)(s->a[0] + t[1] * d[0] - o[0]);
    e[3] = (float)(s->a[1] + t[1] * d[1] - o[1]);
}

static sw_result grow_arrays(sw__gpu_edge_grids *out, size_t n_cells, size_t n_entries,
                             sw_status *status)
{
    if (!sw__grow((void **)&out->grids, &out->cap_grids, out->n_grids + 1, sizeof *out->grids) ||
        !sw__grow((void **)&out->cells, &out->cap_cells, 2 * (out->n_cells + n_cells),
                  sizeof *out->cells) ||
        !sw__grow((void **)&out->segs, &out->cap_segs, 4 * (out->n_segs + n_entries),
                  sizeof *out->segs))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim edges: out of memory");
    return SW_OK;
}

/* Appends the built grid: its header, cells (first entry, entries << 4 | reference point << 1 |
 * its parity) and entries (clipped segment ends relative to the reference point, in cells). */
static sw_result emit_grid(const grid_build *g, sw__gpu_edge_grids *out, int32_t *index,
                           sw_status *status)
{
    const size_t n_cells = (size_t)g->n[0] * (size_t)g->n[1];
    sw_result r = grow_arrays(out, n_cells, g->n_entries, status);
    double *xs = r == SW_OK ? sw__malloc((g->n_segs ? g->n_segs : 1) * sizeof *xs) : NULL;
    uint8_t *parity = xs ? sw__malloc((size_t)g->n[0]) : NULL;
    if (r == SW_OK && !parity) {
        sw__free(xs);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim edges: out of memory");
    }
    if (r != SW_OK)
        return r;
    out->grids[out->n_grids] =
        (sw__gpu_edge_grid){{(uint32_t)g->n[0], (uint32_t)g->n[1]}, (uint32_t)out->n_cells, 0};
    for (int32_t j = 0; j < g->n[1]; ++j) {
        row_all_parities(g, j, xs, parity);
        for (int32_t i = 0; i < g->n[0]; ++i) {
            const size_t c = (size_t)j * (size_t)g->n[0] + (size_t)i;
            const uint32_t first = g->count[c], n = g->count[c + 1] - first;
            uint32_t *cell = &out->cells[2 * (out->n_cells + c)];
            cell[0] = (uint32_t)out->n_segs + first;
            cell[1] = n << 4 | (uint32_t)g->ref[c] << 1 | parity[i];
            double o[2];
            ref_point(i, j, g->ref[c], o);
            for (uint32_t k = 0; k < n; ++k)
                clipped_entry(&g->segs[g->entries[first + k]], i, j, o,
                              &out->segs[4 * (out->n_segs + first + k)]);
        }
    }
    sw__free(parity);
    sw__free(xs);
    out->n_cells += n_cells;
    out->n_segs += g->n_entries;
    *index = (int32_t)out->n_grids++;
    return SW_OK;
}

static void build_free(grid_build *g)
{
    sw__free(g->segs);
    sw__free(g->count);
    sw__free(g->entries);
    sw__free(g->ref);
}

sw_result sw__gpu_edge_grid_add(sw__gpu_edge_grids *out, const sw_sg_polyline *loops,
                                uint32_t n_loops, const double rect[4], int32_t *index,
                                sw_status *status)
{
    *index = -1;
    size_t total = 0;
    for (uint32_t k = 0; k < n_loops; ++k)
        total += loops[k].count;
    if (total > MAX_GRID_SEGMENTS || !(rect[1] > rect[0]) || !(rect[3] > rect[2]) ||
        out->n_grids >= ((size_t)1 << 24)) /* the shader takes its number as a float */
        return SW_OK;
    grid_build g;
    memset(&g, 0, sizeof g);
    g.segs = sw__malloc((total ? total : 1) * sizeof *g.segs);
    if (!g.segs)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim edges: out of memory");
    size_t in_rect = 0;
    g.n_segs = segments_in_cells(loops, n_loops, rect, g.segs, &in_rect);
    g.n[0] = g.n[1] = cells_for(in_rect);
    for (size_t s = 0; s < g.n_segs; ++s) /* the unit square to cells */
        for (int e = 0; e < 2; ++e) {
            g.segs[s].a[e] *= g.n[e];
            g.segs[s].b[e] *= g.n[e];
        }
    const int listed = list_cells(&g);
    g.ref = listed > 0 ? sw__malloc((size_t)g.n[0] * (size_t)g.n[1]) : NULL;
    sw_result r = listed && (listed < 0 || g.ref)
                      ? SW_OK
                      : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim edges: out of memory");
    if (r == SW_OK && listed > 0 && choose_refs(&g))
        r = emit_grid(&g, out, index, status);
    build_free(&g);
    return r;
}

int sw__gpu_edge_grid_inside(const sw__gpu_edge_grids *g, int32_t index, float s, float t)
{
    const sw__gpu_edge_grid *h = &g->grids[index];
    const float n[2] = {(float)h->n[0], (float)h->n[1]};
    const float p[2] = {fminf(fmaxf(s, 0.0f), 1.0f) * n[0], fminf(fmaxf(t, 0.0f), 1.0f) * n[1]};
    int32_t c[2];
    for (int e = 0; e < 2; ++e) {
        c[e] = (int32_t)p[e];
        c[e] = c[e] > (int32_t)h->n[e] - 1 ? (int32_t)h->n[e] - 1 : c[e];
    }
    const uint32_t *cell =
        &g->cells[2 * (h->first_cell + (uint32_t)c[1] * h->n[0] + (uint32_t)c[0])];
    const float *ref = k_ref_candidates[(cell[1] >> 1) & 7u];
    const float d[2] = {p[0] - ((float)c[0] + ref[0]), p[1] - ((float)c[1] + ref[1])};
    uint32_t inside = cell[1] & 1u;
    for (uint32_t k = cell[0]; k < cell[0] + (cell[1] >> 4); ++k) {
        const float *e = &g->segs[4 * k];
        inside ^= (uint32_t)sw__gpu_edge_crosses(d, e);
    }
    return (int)inside;
}

void sw__gpu_edge_grids_empty(sw__gpu_edge_grids *g)
{
    g->n_grids = g->n_cells = g->n_segs = 0;
}

void sw__gpu_edge_grids_free(sw__gpu_edge_grids *g)
{
    sw__free(g->grids);
    sw__free(g->cells);
    sw__free(g->segs);
    memset(g, 0, sizeof *g);
}

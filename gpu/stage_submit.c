/* SPDX-License-Identifier: MIT */
/* The submit stage, on the GL thread: the vertex-shader records sorted by grid class into one
 * batch (their colour and trim rectangle filled from their draws, whose atlas entries the trim
 * stage set), and the frame drawn (draw.c: upload, one program per path, reversed-Z depth) with
 * the static levels kept on the GPU (resident.c), then the outlines over it (stage_shapes.c).
 * Presenting and reading back follow it in sw_gpu_frame_submit. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <string.h>

static int trim_variant(const sw__gpu_draw *d)
{
    return sw__gpu_draw_trimmed(d) ? SW__GPU_TRIMMED : SW__GPU_UNTRIMMED;
}

/* Whether record i is drawn from the kept grids (a geometry made without placements has none). */
static int kept(const sw__fr_geometry *g, size_t i)
{
    return g->places && g->places[i].resident;
}

/* The records drawn from the kept grids, by trim variant (untrimmed first) into
 * ctx->grid_recs_sorted. A frame under a host's shading has none (its prepare evaluates every
 * grid: the host's programs include none for kept grids). */
static sw_result grid_batch(sw_gpu_context *ctx, sw__fr_geometry *g, sw__gpu_patch_batch *b,
                            sw_status *status)
{
    size_t count[SW__GPU_TRIM_VARIANTS] = {0, 0};
    for (size_t i = 0; i < g->n_recs; ++i)
        if (kept(g, i))
            count[trim_variant(&g->draws[g->recs[i].draw])]++;
    const size_t n = count[0] + count[1];
    if (n == 0)
        return SW_OK;
    if (!ctx->surf.grid[SW__GPU_TRIMMED].prog || !ctx->surf.grid[SW__GPU_UNTRIMMED].prog)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "frame: kept grids under a shading without their programs (a host's "
                        "shading: prepare the frame with no_kept_grids)");
    if (!sw__grow((void **)&ctx->grid_recs_sorted, &ctx->cap_grid_recs_sorted, n,
                  sizeof *ctx->grid_recs_sorted) ||
        !sw__grow((void **)&ctx->grid_places_sorted, &ctx->cap_grid_places_sorted, n,
                  sizeof *ctx->grid_places_sorted))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    b->grid_first[SW__GPU_UNTRIMMED] = 0;
    b->grid_count[SW__GPU_UNTRIMMED] = count[SW__GPU_UNTRIMMED];
    b->grid_first[SW__GPU_TRIMMED] = count[SW__GPU_UNTRIMMED];
    b->grid_count[SW__GPU_TRIMMED] = count[SW__GPU_TRIMMED];
    size_t next[SW__GPU_TRIM_VARIANTS] = {b->grid_first[0], b->grid_first[1]};
    for (size_t i = 0; i < g->n_recs; ++i) {
        if (!kept(g, i))
            continue;
        const size_t at = next[trim_variant(&g->draws[g->recs[i].draw])]++;
        ctx->grid_recs_sorted[at] = g->recs[i];
        ctx->grid_places_sorted[at] = g->places[i];
    }
    b->grid_recs = ctx->grid_recs_sorted;
    b->grid_places = ctx->grid_places_sorted;
    b->n_grid_recs = n;
    return SW_OK;
}

/* Fills the records' colour and trim rectangle from their draws (trim entries are known after the
 * atlas commit) and sorts them by trim variant and grid class into ctx->recs_sorted (counting
 * sort), the untrimmed first. */
static sw_result build_batch(sw_gpu_context *ctx, sw__fr_geometry *g, sw__gpu_patch_batch *b,
                             sw_status *status)
{
    memset(b, 0, sizeof *b);
    if (g->n_recs == 0)
        return SW_OK;
    if (!sw__grow((void **)&ctx->recs_sorted, &ctx->cap_recs_sorted, g->n_recs,
                  sizeof *ctx->recs_sorted))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    for (size_t i = 0; i < g->n_recs; ++i) {
        sw__gpu_patch_rec *rec = &g->recs[i];
        const sw__gpu_draw *d = &g->draws[rec->draw];
        memcpy(rec->color, d->color, sizeof rec->color);
        if (sw__gpu_draw_trimmed(d))
            sw__gpu_draw_trim_lookup(ctx, d, rec->trim_rect, &rec->layer);
    }
    sw_result r = grid_batch(ctx, g, b, status);
    if (r != SW_OK)
        return r;
    size_t n_rest = 0;
    for (size_t i = 0; i < g->n_recs; ++i)
        if (!kept(g, i)) {
            const sw__gpu_patch_rec *rec = &g->recs[i];
            b->count[trim_variant(&g->draws[rec->draw])][rec->level_v][rec->level_u]++;
            n_rest++;
        }
    static const int k_order[SW__GPU_TRIM_VARIANTS] = {SW__GPU_UNTRIMMED, SW__GPU_TRIMMED};
    uint32_t at = 0, next[SW__GPU_TRIM_VARIANTS][SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    for (int k = 0; k < SW__GPU_TRIM_VARIANTS; ++k)
        for (int v = 0; v < SW__GPU_GRID_CLASSES; ++v)
            for (int u = 0; u < SW__GPU_GRID_CLASSES; ++u) {
                int t = k_order[k];
                b->first[t][v][u] = next[t][v][u] = at;
                at += b->count[t][v][u];
            }
    int keep = ctx->capture_max > 0;
    if (keep && !sw__grow((void **)&ctx->rec_source, &ctx->cap_rec_source, g->n_recs,
                          sizeof *ctx->rec_source))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "patch records: out of memory");
    for (size_t i = 0; i < g->n_recs; ++i) {
        const sw__gpu_patch_rec *rec = &g->recs[i];
        if (kept(g, i))
            continue;
        uint32_t slot = next[trim_variant(&g->draws[rec->draw])][rec->level_v][rec->level_u]++;
        ctx->recs_sorted[slot] = *rec;
        if (keep)
            ctx->rec_source[slot] = (uint32_t)i;
    }
    b->recs = ctx->recs_sorted;
    b->n_recs = n_rest;
    b->cps = g->cps;
    b->n_cps = g->n_cps;
    b->exact = g->n_pieces > 0;
    b->pieces = g->pieces;
    b->n_pieces = g->n_pieces;
    b->knots = g->knots;
    b->n_knots = g->n_knots;
    b->dcps = g->dcps;
    b->n_dcps = g->n_dcps;
    return SW_OK;
}

sw_result sw__fr_submit(sw_gpu_context *ctx, const sw__gpu_view *view,
                        const sw_gpu_frame_desc *desc, sw__fr_geometry *geo, sw_status *status)
{
    sw__gpu_patch_batch batch;
    sw_result r = build_batch(ctx, geo, &batch, status);
    const sw__gpu_resident_list resident = {
        geo->resident, geo->n_resident,
        desc->static_lods ? sw_lod_static_set_serial(desc->static_lods) : 0};
    sw__gpu_resident_begin(ctx, resident.set);
    sw__gpu_grid_cache_begin(ctx);
    if (r == SW_OK)
        r = sw__gpu_draw_frame(ctx, view, desc, &geo->mesh, geo->draws, geo->n_draws, &batch,
                               &geo->edges, &resident, status);
    return r == SW_OK ? sw__fr_draw_shapes(ctx, view, geo, status) : r;
}

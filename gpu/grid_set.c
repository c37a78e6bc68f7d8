/* SPDX-License-Identifier: MIT */
/* Predefined grids resident on the GPU (Guthe et al. 2005 §4.2): base grids of 1 and 3 segments
 * subdivided by powers of two in u and v independently (1, 2, 3, 4, 6, ..., 48, 64 segments per
 * direction: 12 x 12 classes, one index buffer). Rounding a Filip density up to the next class
 * costs at most 1.5x per direction instead of 2x with one base (the paper's 17 x 350 becomes
 * 24 x 384, its own example). Vertices carry no attributes: the vertex shader derives
 * the grid position from gl_VertexID (row-major, (2^a + 1) per row) and evaluates the patch there,
 * so a grid is only connectivity. Triangles split each cell like patch_grid.c's CPU grids.
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <stdlib.h>
#include <string.h>

const int32_t sw__gpu_grid_segments[SW__GPU_GRID_CLASSES] = {1,  2,  3,  4,  6,  8,
                                                             12, 16, 24, 32, 48, 64};

static uint32_t *fill_class(uint32_t *o, uint32_t nu, uint32_t nv)
{
    for (uint32_t l = 0; l < nv; ++l) {
        for (uint32_t k = 0; k < nu; ++k) {
            uint32_t a = l * (nu + 1) + k, b = a + 1, d = a + nu + 1, e = d + 1;
            o[0] = a, o[1] = b, o[2] = e, o[3] = a, o[4] = e, o[5] = d;
            o += 6;
        }
    }
    return o;
}

sw_result sw__gpu_grids_create(sw_gpu_context *ctx, sw_status *status)
{
    size_t total = 0;
    for (int b = 0; b < SW__GPU_GRID_CLASSES; ++b)
        for (int a = 0; a < SW__GPU_GRID_CLASSES; ++a)
            total +=
                (size_t)6 * (size_t)sw__gpu_grid_segments[a] * (size_t)sw__gpu_grid_segments[b];
    uint32_t *idx = sw__malloc(total * sizeof *idx);
    if (!idx)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "grid set: out of memory");
    uint32_t *o = idx;
    for (int b = 0; b < SW__GPU_GRID_CLASSES; ++b) {
        for (int a = 0; a < SW__GPU_GRID_CLASSES; ++a) {
            ctx->grid_first[b][a] = (uint32_t)(o - idx);
            o = fill_class(o, (uint32_t)sw__gpu_grid_segments[a],
                           (uint32_t)sw__gpu_grid_segments[b]);
            ctx->grid_count[b][a] = (uint32_t)(o - idx) - ctx->grid_first[b][a];
        }
    }
    glGenBuffers(1, &ctx->grid_ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ctx->grid_ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(total * sizeof *idx), idx, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
    sw__free(idx);
    glGenBuffers(1, &ctx->patch_ssbo);
    glGenBuffers(1, &ctx->cp_ssbo);
    glGenBuffers(1, &ctx->piece_ssbo);
    glGenBuffers(1, &ctx->knot_ssbo);
    glGenBuffers(1, &ctx->dcp_ssbo);
    glGenBuffers(3, ctx->edge_ssbo);
    return sw__gpu_check(status, "grid set");
}

void sw__gpu_grids_free(sw_gpu_context *ctx)
{
    glDeleteBuffers(1, &ctx->grid_ibo);
    glDeleteBuffers(1, &ctx->patch_ssbo);
    glDeleteBuffers(1, &ctx->cp_ssbo);
    glDeleteBuffers(1, &ctx->piece_ssbo);
    glDeleteBuffers(1, &ctx->knot_ssbo);
    glDeleteBuffers(1, &ctx->dcp_ssbo);
    ctx->piece_ssbo = ctx->knot_ssbo = ctx->dcp_ssbo = 0;
    glDeleteBuffers(3, ctx->edge_ssbo);
    memset(ctx->edge_ssbo, 0, sizeof ctx->edge_ssbo);
    memset(ctx->edge_ssbo_cap, 0, sizeof ctx->edge_ssbo_cap);
    ctx->patch_ssbo_cap = ctx->cp_ssbo_cap = 0;
    ctx->piece_ssbo_cap = ctx->knot_ssbo_cap = ctx->dcp_ssbo_cap = 0;
    glDeleteBuffers(1, &ctx->capture_ssbo);
    ctx->capture_ssbo = 0;
    sw__free(ctx->rec_source);
    ctx->rec_source = NULL;
    ctx->cap_rec_source = 0;
    ctx->grid_ibo = ctx->patch_ssbo = ctx->cp_ssbo = 0;
    sw__free(ctx->recs_sorted);
    ctx->recs_sorted = NULL;
    ctx->cap_recs_sorted = 0;
    sw__free(ctx->grid_recs_sorted);
    sw__free(ctx->grid_places_sorted);
    ctx->grid_recs_sorted = NULL;
    ctx->grid_places_sorted = NULL;
    ctx->cap_grid_recs_sorted = ctx->cap_grid_places_sorted = 0;
}

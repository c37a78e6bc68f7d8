/* SPDX-License-Identifier: MIT */
/* The renderer's memory budget and its shares. One budget in two numbers, host and GPU bytes;
 * each cache the frame keeps between frames gets a fixed share and, over it, keeps only what the
 * last frame used (resident.c, border_cache.c) or stops growing (the hierarchies stop refining,
 * stage_hierarchy.c; the frame's trim textures are scaled down, stage_trim.c): the picture
 * coarsens, it does not fail, and each coarsening is counted (budget_coarsened, bound_exceeded).
 *
 * GPU: three eighths to static levels resident in buffers, half to the trim atlas (R8: a byte per
 * texel, at most 512 M texels; one frame's textures are scaled to half of it, so that the atlas
 * can keep the last frames' textures beside them and pack them), the last eighth to the per-frame
 * streams and render targets, which follow the screen. Host: half to the bicubic
 * hierarchies, a sixteenth (at most 64 MiB) to the fat borders' cache; the rest is the scene, the
 * BVH and per-frame lists, which follow the scene and the screen. At the default (llvmpipe: 1 GiB
 * GPU) the atlas and the fat borders keep the sizes they had before they were shares of one
 * budget; resident levels had 512 MiB. */
#include "frame_stages.h"
#include "sw_gpu_internal.h"

#include <math.h>
#include <unistd.h>

enum { k_gpu_default = 1 << 30 };
static const double k_atlas_texels_max = 512e6;
static const size_t k_border_cache_max = (size_t)64 << 20;

/* Half of physical memory. */
static uint64_t default_host_budget(void)
{
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return (uint64_t)4 << 30; /* unknown: what a small machine has */
    return (uint64_t)pages * (uint64_t)page / 2;
}

void sw_gpu_set_memory_budget(sw_gpu_context *ctx, uint64_t host, uint64_t gpu)
{
    if (host == 0)
        host = default_host_budget();
    if (gpu == 0)
        gpu = ctx->gpu_reported_bytes ? ctx->gpu_reported_bytes / 2 : (uint64_t)k_gpu_default;
    ctx->budget_host = host;
    ctx->budget_gpu = gpu;
    ctx->atlas_max_texels = fmin(k_atlas_texels_max, (double)gpu / 2.0);
    ctx->atlas_frame_texels = ctx->atlas_max_texels / 2.0;
    ctx->hierarchy_bytes = (size_t)(host / 2);
    sw__gpu_resident_set_budget(ctx, (size_t)(gpu / 8 * 3));
    sw__gpu_grid_cache_set_budget(ctx, (size_t)(gpu / 16));
    sw__fr_border_cache_set_budget(ctx->borders,
                                   (size_t)fmin((double)k_border_cache_max, (double)(host / 16)));
}

void sw_gpu_memory_budget(const sw_gpu_context *ctx, uint64_t *host, uint64_t *gpu,
                          uint64_t *gpu_reported)
{
    *host = ctx->budget_host;
    *gpu = ctx->budget_gpu;
    *gpu_reported = ctx->gpu_reported_bytes;
}

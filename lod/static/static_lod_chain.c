/* SPDX-License-Identifier: MIT */
/* Static LOD chains in the core: freeing and sizing a chain, the level settings' defaults, the
 * order of a unit's patches, and the installed builder (sw_lod_static.h). What builds a chain
 * (static_lod.c and its CGAL and OpenMesh shims) is a module above the core, so that the core
 * draws chains read from a LOD cache without linking either library. */
#include "sw_lod_static_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

static _Atomic(sw_lod_static_build_fn) g_builder;

void sw_lod_static_builder_install(sw_lod_static_build_fn build)
{
    atomic_store_explicit(&g_builder, build, memory_order_release);
}

sw_lod_static_build_fn sw_lod_static_builder(void)
{
    return atomic_load_explicit(&g_builder, memory_order_acquire);
}

void sw__sl_level_free(sw_lod_static_level *l)
{
    sw__free(l->positions), sw__free(l->normals), sw__free(l->uv), sw__free(l->face),
        sw__free(l->triangles);
    memset(l, 0, sizeof *l);
}

void sw_lod_static_free(sw_lod_static_chain *chain)
{
    if (!chain)
        return;
    for (int32_t k = 0; k < chain->n_levels; ++k)
        sw__sl_level_free(&chain->levels[k]);
    sw__free(chain->levels);
    sw__free(chain);
}

/* A level's arrays' bytes, in memory and in a LOD cache alike. */
static size_t level_bytes(const sw_lod_static_level *l)
{
    return (size_t)l->n_vertices * SW_LOD_STATIC_VERTEX_BYTES +
           (size_t)l->n_triangles * SW_LOD_STATIC_TRIANGLE_BYTES;
}

size_t sw_lod_static_memory(const sw_lod_static_chain *chain)
{
    if (!chain)
        return 0;
    size_t b = sizeof *chain + (size_t)chain->n_levels * sizeof *chain->levels;
    for (int32_t k = 0; k < chain->n_levels; ++k) {
        const sw_lod_static_level *l = &chain->levels[k];
        b += level_bytes(l);
    }
    return b;
}

int sw_lod_static_level_drawable(const sw_lod_static_chain *c, int32_t k)
{
    const uint32_t n = c->levels[k].n_triangles;
    return n > 0 && n <= SW_LOD_STATIC_MAX_DRAWN_TRIANGLES_PER_PATCH * c->n_patches;
}

/* Whether two levels hold the same mesh, bit for bit (a decimation that found nothing to
 * collapse: the borders are locked, and a plane's two triangles stay two). */
static int same_mesh(const sw_lod_static_level *a, const sw_lod_static_level *b)
{
    const size_t nv = a->n_vertices;
    return a->n_vertices == b->n_vertices && a->n_triangles == b->n_triangles && nv > 0 &&
           memcmp(a->positions, b->positions, 3 * nv * sizeof *a->positions) == 0 &&
           memcmp(a->normals, b->normals, 3 * nv * sizeof *a->normals) == 0 &&
           memcmp(a->uv, b->uv, 2 * nv * sizeof *a->uv) == 0 &&
           memcmp(a->face, b->face, nv * sizeof *a->face) == 0 &&
           memcmp(a->triangles, b->triangles, 3 * (size_t)a->n_triangles * sizeof *a->triangles) ==
               0;
}

/* Level l's arrays freed, its ε and bounds kept. */
static size_t drop_level(sw_lod_static_level *l)
{
    const size_t freed = level_bytes(l);
    const sw_lod_static_level kept = {.eps = l->eps,
                                      .eps_target = l->eps_target,
                                      .bound = {l->bound[0], l->bound[1]},
                                      .n_triangles_dropped = l->n_triangles};
    sw__sl_level_free(l);
    *l = kept;
    return freed;
}

size_t sw_lod_static_drop_undrawn(sw_lod_static_chain *c)
{
    size_t freed = 0;
    for (int32_t k = c->n_levels - 1; k >= 1; --k) {
        sw_lod_static_level *l = &c->levels[k], *finer = &c->levels[k - 1];
        if (same_mesh(l, finer)) {
            /* both ε bound the one mesh: the finer level keeps the smaller, so that every
             * tolerance that took level k takes the same mesh as level k - 1 */
            finer->eps = fmin(finer->eps, l->eps);
            freed += drop_level(l);
        }
    }
    /* the coarsest mesh stays even when too fine to draw: cluster proxies are made from it */
    int32_t coarsest = c->n_levels - 1;
    while (coarsest > 0 && c->levels[coarsest].n_triangles == 0)
        --coarsest;
    for (int32_t k = 0; k < coarsest; ++k)
        if (c->levels[k].n_triangles > 0 && !sw_lod_static_level_drawable(c, k))
            freed += drop_level(&c->levels[k]);
    return freed;
}

double sw_lod_static_default_delta(const double box[6])
{
    const double d = SW_LOD_STATIC_DELTA_REL * sqrt((box[3] - box[0]) * (box[3] - box[0]) +
                                                    (box[4] - box[1]) * (box[4] - box[1]) +
                                                    (box[5] - box[2]) * (box[5] - box[2]));
    return d > 0.0 ? d : 1e-12; /* a super-surface collapsed to a point */
}

sw_result sw_lod_static_desc_resolve(const sw_lod_static_desc *in, sw_lod_static_desc *d,
                                     sw_status *status)
{
    *d = in ? *in : (sw_lod_static_desc){0};
    if (d->n_levels == 0)
        d->n_levels = 4;
    else if (d->n_levels == -1)
        d->n_levels = 0;
    if (d->eps_first == 0.0)
        d->eps_first = 2.0;
    if (d->eps_growth == 0.0)
        d->eps_growth = 4.0;
    if (d->max_vertices == 0)
        d->max_vertices = 4000000;
    if (d->max_vertices_per_patch == 0)
        d->max_vertices_per_patch = 4096;
    if (!(d->delta >= 0.0 && isfinite(d->delta)) || d->n_levels < 0 || d->n_levels > 8 ||
        !(d->eps_first > 1.0) || !(d->eps_growth > 1.0))
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                        "static lod: delta %g, %d levels, eps_first %g, growth %g", d->delta,
                        (int)d->n_levels, d->eps_first, d->eps_growth);
    return SW_OK;
}

int sw__sl_patch_cmp(const void *a, const void *b)
{
    const sw_lod_static_patch *x = a, *y = b;
    if (x->face != y->face)
        return x->face < y->face ? -1 : 1;
    if (x->iv != y->iv)
        return x->iv < y->iv ? -1 : 1;
    return (x->iu > y->iu) - (x->iu < y->iu);
}

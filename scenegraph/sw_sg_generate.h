/* splinewalk scenegraph/: test-scene generators (`splinewalk generate`). A grid: N instances of a
 * real model on a nearly cubic (or square) lattice, for the culling tests of Kumar et al. 1997
 * §4.4. The instances share the model's geometry: its faces, loops, curves and node tree are
 * copied once (a prototype), and each instance is one SW_SG_NODE_INSTANCE node with a translation.
 */
#ifndef SW_SG_GENERATE_H
#define SW_SG_GENERATE_H

#include "sw_sg_import.h"
#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 10^7 instance nodes are ~1.4 GB of node records in memory and in the file. */
enum { SW_SG_GRID_MAX_COUNT = 10000000 };

typedef struct sw_sg_grid_desc {
    uint32_t count;             /* instances, 1..SW_SG_GRID_MAX_COUNT */
    int32_t dims;               /* 3: nx x ny x nz nearly cubic; 2: nx x ny nearly square, in XY */
    double spacing;             /* centre-to-centre distance on every axis; 0: per axis the model's
                                   box extent plus a gap of a quarter of its largest extent */
    sw_sg_progress_fn progress; /* may be NULL */
    void *user_data;
} sw_sg_grid_desc;

typedef struct sw_sg_grid_report {
    uint32_t nx, ny, nz;  /* lattice; cells filled x fastest, then y, then z */
    double spacing[3];    /* used, per axis */
    double model_box[6];  /* the model's control-net box (min xyz, max xyz) */
    uint64_t occurrences; /* face occurrences of the grid: count x the model's */
} sw_sg_grid_report;

/* Builds the grid scene of `model` (NODES, FACES, POOL, LOOPS, CURVES, ADJACENCY and STRINGS
 * required and validated). Errors: SW_ERR_INVALID_ARGUMENT (count 0 or above the limit, dims not
 * 2 or 3, spacing negative or not finite, a model with no faces or an empty box), SW_ERR_LIMIT
 * (more than 2^31 - 1 face occurrences: what the BVH holds), SW_ERR_OUT_OF_MEMORY, and the
 * builder's validation errors. `report` may be NULL. */
sw_result sw_sg_generate_grid(const sw_sg_scene *model, const sw_sg_grid_desc *desc,
                              sw_sg_scene **out, sw_sg_grid_report *report, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

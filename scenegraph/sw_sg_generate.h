/* SPDX-License-Identifier: MIT */
/* splinewalk scenegraph/: test-scene generators (`splinewalk generate`). A grid: N instances of a
 * real model on a nearly cubic (or square) lattice, for the culling tests of Kumar et al. 1997
 * §4.4. The instances share the model's geometry: its faces, loops, curves and node tree are
 * copied once (a prototype), and each instance is one SW_SG_NODE_INSTANCE node with a translation.
 * A building (generate_building.c): a procedural architectural scene of a requested number of
 * trimmed surfaces, furnished with instances of real models.
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

/* Appends the geometry of `model` (faces, loops, curves, pool, adjacency, nodes; every index
 * shifted) to `b`, its node tree as detached nodes; *proto = the model root's builder index.
 * `node_base` must be the number of nodes `b` holds (the builder does not say; callers count).
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_FORMAT (a model whose node tree is not a forest). */
sw_result sw__sg_append_model(sw_sg_builder *b, const sw_sg_scene_view *model, uint32_t node_base,
                              uint32_t *proto, sw_status *status);

/* ---- building ------------------------------------------------------------------------------- */

/* 10^7 surfaces are ~2.5 10^6 unique faces, ~4 GB while building; 100 is one furnished room. */
enum { SW_SG_BUILDING_MIN_SURFACES = 100, SW_SG_BUILDING_MAX_SURFACES = 10000000 };

/* The furniture models, as files under the OCCT sample-data folder (Debian's occt-misc:
 * /usr/share/opencascade/data): desc.models[i] is the scene of sw_sg_building_model_files[i]. */
enum { SW_SG_BUILDING_N_MODELS = 10 };
extern const char *const sw_sg_building_model_files[SW_SG_BUILDING_N_MODELS];

typedef struct sw_sg_building_desc {
    uint64_t surfaces; /* face occurrences wanted, SW_SG_BUILDING_MIN..MAX_SURFACES: met exactly */
    uint64_t seed;     /* same seed, same scene (byte for byte) */
    const sw_sg_scene *const *models; /* SW_SG_BUILDING_N_MODELS validated scenes */
    sw_sg_progress_fn progress;       /* may be NULL */
    void *user_data;
} sw_sg_building_desc;

typedef struct sw_sg_building_report {
    uint32_t nx, ny, floors;   /* rooms per floor nx x ny; floors (the top one may be partial) */
    uint32_t rooms, furnished; /* rooms built, rooms holding furniture */
    uint64_t occurrences;      /* face occurrences, instances expanded (= desc.surfaces) */
    uint64_t unique_faces;     /* faces stored (the scene's face records) */
    uint64_t instances;        /* instance nodes (furniture and stairs) */
    uint32_t domes, vaults, columns, windows, doors, arches, stairs, bollards;
} sw_sg_building_report;

/* Builds the building. Units are centimetres (the MODERN_* models' unit), z up. Errors:
 * SW_ERR_INVALID_ARGUMENT (surfaces out of range, a model missing or empty),
 * SW_ERR_OUT_OF_MEMORY, and the builder's validation errors. `report` may be NULL. */
sw_result sw_sg_generate_building(const sw_sg_building_desc *desc, sw_sg_scene **out,
                                  sw_sg_building_report *report, sw_status *status);

/* ---- vehicle ----------------------------------------------------------------------------------
 */

/* A parking lot of generated cars, 100..10^7 surfaces like the building. */
enum { SW_SG_VEHICLE_N_MODELS = 3 };
extern const char *const sw_sg_vehicle_model_files[SW_SG_VEHICLE_N_MODELS];

typedef struct sw_sg_vehicle_desc {
    uint64_t surfaces;                /* SW_SG_BUILDING_MIN..MAX_SURFACES, met exactly */
    uint64_t seed;                    /* same seed, same scene (byte for byte) */
    const sw_sg_scene *const *models; /* SW_SG_VEHICLE_N_MODELS: sw_sg_vehicle_model_files */
    sw_sg_progress_fn progress;       /* may be NULL */
    void *user_data;
} sw_sg_vehicle_desc;

typedef struct sw_sg_vehicle_report {
    uint32_t vehicles, with_engine; /* cars; cars with the instanced engine parts */
    uint64_t occurrences, unique_faces, instances;
    uint32_t panels, arches, windows, gaps, bollards;
} sw_sg_vehicle_report;

/* Builds the lot. Units are millimetres (Motor-c's), z up, cars along x. Errors as for
 * sw_sg_generate_building. `report` may be NULL. */
sw_result sw_sg_generate_vehicle(const sw_sg_vehicle_desc *desc, sw_sg_scene **out,
                                 sw_sg_vehicle_report *report, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

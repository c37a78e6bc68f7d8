/* SPDX-License-Identifier: MIT */
/* Node scenes, inside the runtime (never installed): the mutable node tree (api_nodes.c) and its
 * compilation into published immutable versions (api_nodes_compile.c). sw_nodes.h says what the
 * host sees. */
#ifndef SW_RT_NODES_INTERNAL_H
#define SW_RT_NODES_INTERNAL_H

#include "sw_rt.h"

#include "sw_th_pool.h"

typedef struct rt_node rt_node;
struct rt_node {
    uint32_t id; /* handle id in the model's node pool; 0 for the two sentinels */
    sw_node_kind kind;
    rt_node *parent, *first_child, *last_child, *prev, *next;
    int32_t hidden;
    uint32_t n_children;
    float color[4];         /* color[3] < 0: inherit (the scene graph's convention) */
    double xform[12];       /* identity where the kind has none */
    rt_node *target;        /* INSTANCE */
    uint32_t instance_refs; /* INSTANCE nodes whose target this is */
    sw_sg_scene *geom;      /* NURBS, TSPLINE, IMPORT, MESH: a private immutable scene, its root
                               drawn */
    uint32_t geom_faces, geom_triangles;
    sw_camera camera; /* CAMERA */
    char *name;
    /* scratch of one operation under the edit lock (compile, remove, cycle test) */
    uint32_t compiled;
    uint32_t mark;
};

typedef struct sw_rt_model {
    /* Protects the tree (every rt_node), the node pool's contents, `revision` and
     * `compile_queued`. Taken by every API call on the scene and by the compile task while it
     * copies the tree into a builder; never by a frame. Order: edit_lock, then nodes.lock. */
    pthread_mutex_t edit_lock;
    sw_rt_pool nodes;
    rt_node root;     /* the implicit root group (the builder's node 0) */
    rt_node detached; /* sentinel parent of detached subtrees (prototypes) */
    uint64_t serial;  /* unique per model in the process: its versions' lineage */
    char *name;       /* sw_scene_desc.name, or NULL: prefixes compile failures */
    uint64_t revision;
    int compile_queued; /* a compile task is queued or running and will look at `revision` */
    sw_th_pool *pool;   /* one worker: compilations, in order */

    /* Publication (api_nodes_compile.c): one pointer exchange, then a grace period over the
     * readers counted in readers[epoch & 1] (they only retain the version inside it). */
    _Atomic(sw_rt_scene *) published;
    atomic_uint epoch;
    atomic_uint readers[2];
    atomic_uint_fast64_t published_revision, compiles;

    /* Protects compiled_revision, compile_result and compile_status; pub_cond is signalled
     * when compiled_revision moves. Taken after edit_lock when both are held. */
    pthread_mutex_t pub_lock;
    pthread_cond_t pub_cond;
    uint64_t compiled_revision; /* the last revision a compilation finished (or failed) */
    sw_result compile_result;
    sw_status compile_status;
} sw_rt_model;

/* Limits of the geometry descs. */
#define SW__NODES_MAX_POINTS (1u << 20)
#define SW__NODES_MAX_LOOPS 65536u
#define SW__NODES_MAX_LABEL 1024u     /* bytes of a label's text */
#define SW__NODES_MAX_MESH (1u << 24) /* vertices, and triangles, of one mesh */

/* A private one-face scene of a checked NURBS desc (api_nodes_geom.c): the one check and conversion
 * of sw_nurbs_desc, shared by NURBS nodes and immediate objects (api_immediate.c). Errors:
 * SW_ERR_INVALID_ARGUMENT, SW_ERR_INVALID_GEOMETRY, SW_ERR_LIMIT, SW_ERR_OUT_OF_MEMORY. */
sw_result sw__rt_nurbs_geom(const sw_nurbs_desc *d, sw_sg_scene **out, sw_status *status);
/* The private scene of a geometry node's desc (NURBS, TSPLINE, IMPORT, MESH, SHAPE, LABEL; *out
 * NULL for the other kinds), and the same per kind for the set_* edits (api_nodes_geom.c).
 * Errors: sw_nodes.h's for sw_node_add and each sw_node_set_*. */
sw_result sw__rt_make_geom(const sw_node_desc *d, sw_sg_scene **out, sw_status *status);
sw_result sw__rt_tspline_geom(const sw_tspline_desc *d, sw_sg_scene **out, sw_status *status);
sw_result sw__rt_mesh_geom(const sw_mesh_desc *d, sw_sg_scene **out, sw_status *status);
sw_result sw__rt_shape_geom(const sw_shape_desc *d, sw_sg_scene **out, sw_status *status);
sw_result sw__rt_label_geom(const sw_label_desc *d, sw_sg_scene **out, sw_status *status);
/* Mesh triangles a geometry scene holds (each mesh once), saturated at UINT32_MAX. */
uint32_t sw__rt_geom_triangles(const sw_sg_scene *geom);
/* Whether all n values are finite. */
int sw__rt_all_finite(const double *v, size_t n);

/* The node API's checks of a desc's transform (all zero: identity; else finite, invertible) and
 * colour (finite, >= 0; color[3] == 0: inherit, stored as -1), for the immediate draws. Errors:
 * SW_ERR_INVALID_ARGUMENT naming fn. */
sw_result sw__rt_read_transform(const double in[12], const char *fn, double out[12],
                                sw_status *status);
sw_result sw__rt_read_color(const float in[4], const char *fn, float out[4], sw_status *status);

/* Compiles the tree as it is now into a version (the edit lock held by the caller for the copy
 * only: it is released before the builder is finished when `unlock` is set). */
sw_result sw__rt_model_compile(sw_rt_model *m, int unlock, sw_rt_scene **out, uint64_t *revision,
                               sw_status *status);
/* Publishes v (the model takes the caller's reference) and reclaims the version before it once
 * no reader can still be taking it. */
void sw__rt_model_publish(sw_rt_model *m, sw_rt_scene *v);
/* After an edit, under the edit lock: revision + 1 and a compile task unless one is queued. */
void sw__rt_model_edited(sw_rt_model *m);

#endif

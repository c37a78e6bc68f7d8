/* SPDX-License-Identifier: MIT */
/* splinewalk scenegraph/: a bounding-volume hierarchy (Kumar et al. 1997 §4.4). Its leaves are a
 * scene's face occurrences (sw_sg_bvh_build: frames without static LODs), or items a caller made
 * (sw_sg_bvh_build_items: lod/'s super-surface instances, the leaves §4.4 names, for frames with
 * static LODs; sw_sg_bvh_build_boxes: pieces of one face). Built once per scene (instances
 * expanded), median split along the longest axis of the centroids' box, at most SW_SG_BVH_LEAF
 * items per leaf. A face occurrence's box is its face's control-net box (computed once per face,
 * shared by instances) mapped through the occurrence transform: eight corners, so it bounds the
 * surface however the transform rotates. Stored lean (32 bytes an item, 36 a node, a shared
 * place per run of items with one transform and colour): boxes in float, rounded outward, relative
 * to a point near them, read back in double by sw_sg_bvh_item_box / sw_sg_bvh_node_box. A finished
 * BVH is immutable and may be read from any thread.
 */
#ifndef SW_SG_BVH_H
#define SW_SG_BVH_H

#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <float.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { SW_SG_BVH_LEAF = 4 };

/* What a caller builds a hierarchy from (sw_sg_bvh_build_items): one item, whole. */
typedef struct sw_sg_bvh_input {
    double world[12]; /* occurrence transform, row-major 3 x 4 */
    double box[6];    /* world box: min xyz, max xyz */
    float color[4];
    uint32_t face; /* the caller's id of the item */
} sw_sg_bvh_input;

/* What items share: a transform and a colour (the occurrences of one scene node share one), and the
 * point their boxes are stored relative to (near them, so that a float box keeps the precision of
 * its own size wherever the scene lies). */
typedef struct sw_sg_bvh_place {
    double world[12]; /* row-major 3 x 4 */
    double origin[3];
    float color[4];
} sw_sg_bvh_place;

/* An item as stored: 32 bytes, so that a BVH over 10^6 occurrences costs tens of MiB. Its box is
 * float, relative to its place's origin and rounded outward: origin + (double)box[k] bounds the
 * world box exactly as computed in double (sw_sg_bvh_item_box). */
typedef struct sw_sg_bvh_item {
    float box[6];
    uint32_t face;  /* the face (sw_sg_bvh_build), else the caller's id of the item */
    uint32_t place; /* index into places */
} sw_sg_bvh_item;

/* A node, its box stored like an item's relative to the BVH's origin (sw_sg_bvh_node_box). An
 * inner node's first child is the node after it (built depth first), its second `second`. */
typedef struct sw_sg_bvh_node {
    float box[6];
    int32_t second;        /* -1 at a leaf */
    uint32_t first, count; /* the subtree's items, contiguous in `items` */
} sw_sg_bvh_node;

typedef struct sw_sg_bvh {
    sw_sg_bvh_item *items; /* in leaf order */
    uint32_t n_items;
    sw_sg_bvh_node *nodes; /* nodes[0] is the root (none when n_items == 0) */
    uint32_t n_nodes;
    sw_sg_bvh_place *places;
    uint32_t n_places;
    double origin[3]; /* what node boxes are relative to */
    double box[6];    /* the union of the items' boxes in double, exact (empty: min > max) */
} sw_sg_bvh;

/* An item whole: its transform and colour (its place's) and its world box in double. */
typedef struct sw_sg_bvh_item_view {
    const double *world; /* 12 */
    const float *color;  /* 4; colour[3] < 0: unset */
    double box[6];
    uint32_t face;
} sw_sg_bvh_item_view;

/* A stored box back in double: origin + offset; an offset beyond float's range (a coordinate past
 * 3e38 from the origin) reads as +-DBL_MAX, still bounding, and finite so that plane tests never
 * meet 0 x inf. */
static inline void sw_sg_bvh_box_at(const double origin[3], const float b[6], double out[6])
{
    for (int k = 0; k < 6; ++k) {
        const double x = origin[k % 3] + (double)b[k];
        out[k] = x > DBL_MAX ? DBL_MAX : x < -DBL_MAX ? -DBL_MAX : x;
    }
}

static inline void sw_sg_bvh_item_box(const sw_sg_bvh *bvh, uint32_t item, double out[6])
{
    const sw_sg_bvh_item *it = &bvh->items[item];
    sw_sg_bvh_box_at(bvh->places[it->place].origin, it->box, out);
}

static inline void sw_sg_bvh_node_box(const sw_sg_bvh *bvh, uint32_t node, double out[6])
{
    sw_sg_bvh_box_at(bvh->origin, bvh->nodes[node].box, out);
}

/* Child k (0, 1) of a node, -1 at a leaf. */
static inline int32_t sw_sg_bvh_child(const sw_sg_bvh *bvh, uint32_t node, int k)
{
    const int32_t second = bvh->nodes[node].second;
    return second < 0 ? -1 : k ? second : (int32_t)node + 1;
}

static inline const double *sw_sg_bvh_item_world(const sw_sg_bvh *bvh, uint32_t item)
{
    return bvh->places[bvh->items[item].place].world;
}

static inline void sw_sg_bvh_item_at(const sw_sg_bvh *bvh, uint32_t item, sw_sg_bvh_item_view *out)
{
    const sw_sg_bvh_place *p = &bvh->places[bvh->items[item].place];
    out->world = p->world;
    out->color = p->color;
    sw_sg_bvh_item_box(bvh, item, out->box);
    out->face = bvh->items[item].face;
}

/* Builds the BVH of a scene whose NODES, FACES and POOL sections are required and validated.
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (more than 2^31 occurrences). *out owned by the
 * caller (sw_sg_bvh_free). */
sw_result sw_sg_bvh_build(const sw_sg_scene *scene, sw_sg_bvh **out, sw_status *status);
/* The same hierarchy over n arbitrary boxes (6 doubles each: min xyz, max xyz): item i has the box
 * boxes[6 i..], face = i, an identity transform and no colour — a finer granularity than faces
 * (e.g. one face's Bézier patches) for callers that cull their own pieces. Errors as above. */
sw_result sw_sg_bvh_build_boxes(const double *boxes, uint32_t n, sw_sg_bvh **out,
                                sw_status *status);
/* The same hierarchy over n items the caller made (world, box, colour, face = its own id); reads
 * `items` (consecutive items with the same transform and colour share a place). Errors as above. */
sw_result sw_sg_bvh_build_items(const sw_sg_bvh_input *items, uint32_t n, sw_sg_bvh **out,
                                sw_status *status);
void sw_sg_bvh_free(sw_sg_bvh *bvh); /* NULL allowed */
/* The number of a scene's face occurrences and the union of their boxes in double, each boxed as
 * sw_sg_bvh_build boxes it (an empty box, min > max, when there are none), without building the
 * hierarchy. Preconditions as sw_sg_bvh_build. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_occurrences_box(const sw_sg_scene *scene, uint64_t *n, double box[6],
                                sw_status *status);

/* The object-space box of a face as its occurrences are boxed: its whole control net (Euclidean
 * points), min xyz, max xyz. Precondition: FACES and POOL required. */
void sw_sg_bvh_face_box(const sw_sg_scene *scene, uint32_t face, double box[6]);
/* The world box of an object box under a row-major 3 x 4 transform (its eight corners), as
 * sw_sg_bvh_build boxes an occurrence: a caller that boxes occurrences itself gets the same
 * doubles. */
void sw_sg_box_transform(const double m[12], const double box[6], double out[6]);
/* sqrt(|M|_1 |M|_inf) of the linear part of a row-major 3 x 4 transform: a bound of its spectral
 * norm, so of how far it stretches any distance (1 for the identity and for rotations by quarter
 * turns, up to sqrt(2) for other rotations; the Frobenius norm would give sqrt(3) even for the
 * identity and make every tolerance 1.7x tighter). */
double sw_sg_stretch_bound(const double m[12]);
/* A world point p and direction d (either may be NULL) in the frame of the row-major 3 x 4
 * transform m (world = M x + T): M^-1 (p - T) into lp, M^-1 d into ld. 0 (outputs untouched or
 * partly written) when M is singular (|det| <= 1e-300) or a result is not finite. */
int sw_sg_to_local(const double m[12], const double p[3], const double d[3], double lp[3],
                   double ld[3]);
size_t sw_sg_bvh_memory(const sw_sg_bvh *bvh);

/* ---- view-frustum culling (Kumar §4.4) --------------------------------------------------------
 * A convex region bounded by up to six planes. Boxes are tested relative to `origin` (the frame
 * passes the eye: world coordinates far from the origin keep their precision), a point x being
 * inside where dot(n, x - origin) + d >= 0 for every plane (n = planes[p][0..2], d = planes[p][3];
 * n need not be unit length). */
enum { SW_SG_FRUSTUM_MAX_PLANES = 6 };

typedef struct sw_sg_frustum {
    double origin[3];
    double planes[SW_SG_FRUSTUM_MAX_PLANES][4];
    int32_t n_planes; /* 0..SW_SG_FRUSTUM_MAX_PLANES */
} sw_sg_frustum;

typedef enum sw_sg_cull_class {
    SW_SG_CULL_OUTSIDE = 0, /* wholly outside one plane: nothing in the box can be seen */
    SW_SG_CULL_PARTLY = 1,  /* may meet the region (conservative: a box near a corner of the
                               region can be outside it without being outside any one plane) */
    SW_SG_CULL_INSIDE = 2,  /* wholly inside every plane */
} sw_sg_cull_class;

/* Classifies an origin-relative box (min xyz, max xyz) by its nearest and farthest corners along
 * each plane's normal. */
sw_sg_cull_class sw_sg_planes_classify(const double (*planes)[4], int32_t n_planes,
                                       const double box[6]);
/* Classifies a world box against the frustum (relative to fr->origin). */
sw_sg_cull_class sw_sg_frustum_classify(const sw_sg_frustum *fr, const double world_box[6]);

typedef struct sw_sg_bvh_cull_stats {
    uint64_t nodes_visited; /* nodes classified: nodes_inside + nodes_partly + nodes_outside */
    uint64_t nodes_inside, nodes_partly, nodes_outside;
    uint64_t items_tested;  /* items classified one by one (those of partly-visible leaves) */
    uint64_t items_visible; /* items reported */
    uint64_t items_inside;  /* of those, reported as SW_SG_CULL_INSIDE */
} sw_sg_bvh_cull_stats;

/* Receives the index (into bvh->items) of an item whose box may meet the frustum and the item's
 * own class: SW_SG_CULL_INSIDE (under a node inside, or tested inside) or SW_SG_CULL_PARTLY;
 * non-zero stops the traversal. */
typedef int (*sw_sg_bvh_cull_fn)(void *ctx, uint32_t item, sw_sg_cull_class cls);

/* Reports every item whose box is not outside the frustum, in increasing index order, with its
 * class: a node outside is dropped with its subtree, a node inside reports its subtree untested
 * (as inside), a partly
 * visible node is opened (its leaf items classified one by one). The reported set is exactly the
 * items whose own box classifies as not outside (a box inside its parent's box classifies at
 * least as inside, in floating point too: every step of the test is monotone). `stats` may be
 * NULL; it is overwritten. Returns 0, or the callback's non-zero value when it stopped. */
int sw_sg_bvh_cull(const sw_sg_bvh *bvh, const sw_sg_frustum *fr, sw_sg_bvh_cull_fn fn, void *ctx,
                   sw_sg_bvh_cull_stats *stats);

#ifdef __cplusplus
}
#endif
#endif

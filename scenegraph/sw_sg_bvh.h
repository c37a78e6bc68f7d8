/* splinewalk scenegraph/: a bounding-volume hierarchy over a scene's face occurrences (Kumar et
 * al. 1997 §4.4; its leaves will be super-surface instances once issue 4's clustering exists, face
 * occurrences until then). Built once per scene (instances expanded), median split along the
 * longest axis of the centroids' box, at most SW_SG_BVH_LEAF items per leaf. Each item's box is its
 * face's control-net box (computed once per face, shared by instances) mapped through the
 * occurrence transform: eight corners, so it bounds the surface however the transform rotates.
 * A finished BVH is immutable and may be read from any thread.
 */
#ifndef SW_SG_BVH_H
#define SW_SG_BVH_H

#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { SW_SG_BVH_LEAF = 4 };

typedef struct sw_sg_bvh_item {
    double world[12]; /* occurrence transform, row-major 3 x 4 */
    double box[6];    /* world box: min xyz, max xyz */
    float color[4];
    uint32_t face;
} sw_sg_bvh_item;

typedef struct sw_sg_bvh_node {
    double box[6];
    int32_t child[2];      /* -1 at a leaf */
    uint32_t first, count; /* the subtree's items, contiguous in `items` */
} sw_sg_bvh_node;

typedef struct sw_sg_bvh {
    sw_sg_bvh_item *items; /* in leaf order */
    uint32_t n_items;
    sw_sg_bvh_node *nodes; /* nodes[0] is the root (none when n_items == 0) */
    uint32_t n_nodes;
} sw_sg_bvh;

/* Builds the BVH of a scene whose NODES, FACES and POOL sections are required and validated.
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (more than 2^31 occurrences). *out owned by the
 * caller (sw_sg_bvh_free). */
sw_result sw_sg_bvh_build(const sw_sg_scene *scene, sw_sg_bvh **out, sw_status *status);
void sw_sg_bvh_free(sw_sg_bvh *bvh); /* NULL allowed */
size_t sw_sg_bvh_memory(const sw_sg_bvh *bvh);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: per-face outward normal cones for back-patch culling (Kumar et al. 1997 §4.4).
 *
 * Where the cones live. A cone costs a Gauss-map pass over every patch of its face (gauss_map.c),
 * far too much per frame, and it depends only on the scene, so it is built once per scene, like
 * the BVH, and handed to each frame (sw_gpu_frame_desc.face_cones). It is not in the BVH itself
 * (scenegraph/ cannot call lod/), nor in the hierarchy cache (frames without hierarchies cull too,
 * and the cache builds lazily in its pool while this is needed whole at the first frame). Cones are
 * in each face's object space; sw_lod_cone_to_world maps one through an occurrence's transform.
 *
 * Only faces flagged SW_SG_FACE_CLOSED_SHELL get a cone: an open sheet is seen from both sides
 * (Kumar §4.4), so the others keep the full cone and are never culled.
 */
#ifndef SW_LOD_FACE_CONES_H
#define SW_LOD_FACE_CONES_H

#include "sw_lod_supersurface.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_face_cones {
    sw_lod_cone *cones; /* n_faces: outward cone (full for faces that may not be culled) */
    uint32_t n_faces;
    uint32_t n_bounded; /* faces whose cone is a bound (half-angle < pi) */
} sw_lod_face_cones;

/* Each CLOSED_SHELL face's cone: sw_lod_cone_enclose of its patches' outward cones
 * (sw_lod_face_patches, sw_lod_gauss_cone, negated for SW_SG_FACE_REVERSED). Precondition:
 * SW_SG_SEC_FACES and SW_SG_SEC_POOL required. Errors: SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INVALID_ARGUMENT (a face whose uv_box misses its domain). *out owned by the caller. */
sw_result sw_lod_face_cones_build(const sw_sg_scene *scene, sw_lod_face_cones **out,
                                  sw_status *status);
void sw_lod_face_cones_free(sw_lod_face_cones *fc); /* NULL allowed */

/* The object-space outward cone c mapped through the row-major 3x4 transform m. The outward
 * normal of a solid maps by the cofactor of m's linear part; for a similarity (rotation, uniform
 * scale, reflection) that is m's direction map itself — a reflection does not flip it: the
 * mirrored solid's outside is still outside (only Su x Sv flips). Other transforms (shear,
 * non-uniform scale) give the full cone. Returns 1 when the result is a bound. */
int sw_lod_cone_to_world(const sw_lod_cone *c, const double m[12], sw_lod_cone *out);

/* Whether every point of the box (eye-relative: min xyz, max xyz) on a surface whose outward
 * normals lie in the world cone c faces away from the eye at the origin: for every view direction
 * v from the eye into the box (the cone about the direction d to the box's centre, half-angle
 * phi = asin(r / |centre|), r the half-diagonal) and every normal n in c, n . v > 0, i.e.
 * angle(axis, d) + theta + phi < 90 degrees (Kumar §4.4 after Shirman & Abi-Ezzi 1993). An eye
 * within the box's sphere, or a cone of 90 degrees or more, is never back-facing. */
int sw_lod_cone_back_facing(const sw_lod_cone *c, const double box[6]);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* splinewalk scenegraph/: picking — the nearest point where a ray meets the scene's trimmed
 * surfaces ("picking by ray through the BVH, returning node, surface and (u,v)").
 *
 * The BVH (sw_sg_bvh.h) gives the face occurrences whose boxes the ray crosses, nearest box
 * first; each occurrence's face is intersected in its own frame (the ray mapped by the inverse
 * occurrence transform, so t is the world ray's parameter). Per face: the ray is written as two
 * planes (Kajiya 1982; Nishita et al. 1990's Bézier clipping uses the same form), the face's
 * rational Bézier patches are subdivided while the convex hull of their control points straddles
 * both planes (positive weights: the patch lies in the hull), and a leaf's centre starts Newton's
 * method on the exact NURBS surface. A root inside the trim loops (even-odd, the rule the GPU's
 * trim textures follow) with 0 < t < the best so far wins.
 *
 * Triangle meshes (SW_SG_NODE_MESH) are not in the BVH: each mesh occurrence whose world box the
 * ray crosses before the best hit so far is tested triangle by triangle in the mesh's frame
 * (Möller & Trumbore 1997, both sides), after the faces, so a nearer face prunes them.
 *
 * The result is exact to the solver's tolerance wherever the ray crosses the surface
 * transversally; a grazing ray (tangent to the surface) may be reported as a miss. Any thread;
 * the scene and BVH are only read.
 */
#ifndef SW_SG_PICK_H
#define SW_SG_PICK_H

#include "sw_sg_bvh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_sg_pick_hit {
    double t;                /* hit = origin + t * dir */
    double point[3];         /* world */
    double uv[2];            /* the face's parameters */
    uint32_t face;           /* SW_SG_NONE: no face hit */
    uint32_t item;           /* the BVH item (face occurrence); a mesh hit: its occurrence, in
                                sw_sg_scene_traverse_meshes order */
    uint32_t mesh;           /* SW_SG_NONE: no mesh hit (face and mesh are never both set) */
    uint32_t triangle, node; /* a mesh hit: the triangle in the mesh, the MESH node */
    double bary[3];          /* a mesh hit: the weights of the triangle's three vertices */
} sw_sg_pick_hit;

/* The nearest hit with t in (0, t_max] (t_max <= 0: unbounded) of the ray origin + t * dir
 * (dir need not be unit, not zero). Errors: SW_ERR_INVALID_ARGUMENT (zero or non-finite ray),
 * SW_ERR_OUT_OF_MEMORY, and errors of reading a face's trim loops. hit->face = hit->mesh =
 * SW_SG_NONE and SW_OK when nothing is hit. */
sw_result sw_sg_pick(const sw_sg_scene *scene, const sw_sg_bvh *bvh, const double origin[3],
                     const double dir[3], double t_max, sw_sg_pick_hit *hit, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

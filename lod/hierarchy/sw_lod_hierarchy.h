/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: the per-surface binary hierarchy of rational bicubic patches, Guthe et al. 2005
 * §6 (Fig. 7): the surface's Bézier patches (optionally cut to the trim region's box, §4.4), each
 * reduced to bicubics and subdivided until a leaf tolerance is met (§6.1, the blue subtrees),
 * joined pairwise by median cut along the longer parameter direction and simplified bottom-up
 * (§6.2, the green tree). Every node carries a rigorous error bound against the exact surface and
 * the derivative-bound constants (§5.1-§5.3) from which the renderer gets its sampling density and
 * trim-texture resolution with one multiply per frame:
 *
 *     segments along dir = ceil(seg_c[dir] / sqrt(eps_s))     (Filip bound, §5.2, eps_s/2 per dir)
 *     texels along dir   = ceil(tex_c[dir] / eps_t)           (§5.3: a texel step moves <= eps_t)
 *
 * where eps_s is the object-space tolerance given to sampling (the paper splits ε equally between
 * approximation and sampling, §7) and eps_t the one given to trimming. With the node's bicubic S
 * over its local [0,1]^2 and M_ss, M_st, M_tt, G_s, G_t bounds of |S_ss|, |S_st|, |S_tt|, |S_s|,
 * |S_t| (sw_lod_rational_bezier_bounds, lod/bezier/sampling.c): seg_c[0] = sqrt(M_ss + M_st) / 2,
 * seg_c[1] = sqrt(M_tt + M_st) / 2 (from n = ceil(sqrt((M_dir + M_st) / (4 eps_s))), i.e.
 * (ds^2 (M_ss + M_st) + dt^2 (M_tt + M_st)) / 8 <= eps_s), tex_c = (G_s, G_t) for a texture
 * spanning the node's whole rectangle (scale by the covered fraction otherwise).
 *
 * A finished hierarchy is immutable and may be read from any thread.
 */
#ifndef SW_LOD_HIERARCHY_H
#define SW_LOD_HIERARCHY_H

#include "sw_lod_error.h"
#include "sw_sg_geom.h"

#include <math.h>
#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum sw_lod_hnode_flags {
    SW_LOD_HNODE_REPRESENTABLE = 1u << 0, /* cpw holds a bicubic; else draw the children */
    SW_LOD_HNODE_IN_PATCH = 1u << 1,      /* inside one Bézier patch's subdivision (blue) */
};

typedef struct sw_lod_hnode {
    double rect[4];  /* u0, u1, v0, v1 in the surface's parameters */
    double cpw[64];  /* the bicubic over rect (local [0,1]^2), homogeneous, u fastest */
    double error;    /* >= max distance surface - bicubic over rect; +INF if not representable;
                        >= each child's error (+ the simplification error for joined pairs) */
    double box[6];   /* min xyz, max xyz of the control points (of the children's boxes when not
                        representable); the surface is within `error` of it */
    double seg_c[2]; /* see the top of the file; 0 when not representable */
    double tex_c[2];
    int32_t child[2];  /* -1 at a leaf; child[0] covers the lower parameters along split_dir */
    int32_t parent;    /* -1 at the root */
    int32_t split_dir; /* 0 = u, 1 = v */
    uint32_t flags;
} sw_lod_hnode;

typedef struct sw_lod_hierarchy {
    sw_lod_hnode *nodes;
    int32_t n_nodes, root;
    int32_t n_patches; /* Bézier patches the leaves came from */
    int32_t n_leaves;
    int32_t leaves_over_tolerance; /* stopped by max_depth above the leaf tolerance */
    double leaf_tolerance;         /* the one used */
} sw_lod_hierarchy;

/* Zero-initialise for the defaults. */
typedef struct sw_lod_hierarchy_desc {
    double leaf_tolerance; /* object space; 0 = 1e-3 x the diagonal of the control net's box */
    int32_t max_depth;     /* splits below one Bézier patch at most; 0 = 8 */
    double crease_angle;   /* children meeting at a larger angle (radians) are not joined into one
                              bicubic; 0 = 0.35 (20 degrees) */
    int32_t use_box;       /* 1: only the part inside uv_box (the trim region's box, §4.4) */
    double uv_box[4];      /* u0, u1, v0, v1 */
    sw_lod_error_desc error;
} sw_lod_hierarchy_desc;

/* Builds the hierarchy of a validated surface (sw_sg_surface_validate). desc may be NULL.
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_INVALID_ARGUMENT (uv_box misses the domain). On success
 * *out is owned by the caller (sw_lod_hierarchy_free). */
sw_result sw_lod_hierarchy_build(const sw_sg_surface *s, const sw_lod_hierarchy_desc *desc,
                                 sw_lod_hierarchy **out, sw_status *status);
void sw_lod_hierarchy_free(sw_lod_hierarchy *h); /* NULL allowed */

/* The box cut of §4.4 on an extracted set (sw_sg_surface_extract_bezier_in over the same box):
 * every patch's net is cut in place to its rectangle intersected with uv_box (u0, u1, v0, v1) and
 * its u0, u1, v0, v1 set to that rectangle. Errors: SW_ERR_INVALID_ARGUMENT when the box misses a
 * patch (the set is then partly cut). Shared by the hierarchy and super-surfaces, so both see the
 * same patches. */
sw_result sw_lod_bezier_set_cut(sw_sg_bezier_set *set, const double uv_box[4], sw_status *status);

/* The node's bicubic, or NULL when the node is not representable by one. */
static inline const double *sw_lod_hnode_cpw_ptr(const sw_lod_hnode *n)
{
    return (n->flags & SW_LOD_HNODE_REPRESENTABLE) ? n->cpw : (const double *)0;
}

/* Grid segments along dir for a sampling tolerance eps_s, given inv_sqrt_eps = 1 / sqrt(eps_s)
 * (computed once per frame or per distance class), clamped to [1, max_segments]. */
static inline int32_t sw_lod_hnode_segments(const sw_lod_hnode *n, int dir, double inv_sqrt_eps,
                                            int32_t max_segments)
{
    const double s = ceil(n->seg_c[dir] * inv_sqrt_eps);
    return !(s >= 1.0) ? 1 : s >= (double)max_segments ? max_segments : (int32_t)s;
}

/* Trim-texture texels along dir over the node's rectangle for tolerance eps_t, given
 * inv_eps = 1 / eps_t, clamped to [1, max_texels]. */
static inline int32_t sw_lod_hnode_texels(const sw_lod_hnode *n, int dir, double inv_eps,
                                          int32_t max_texels)
{
    const double t = ceil(n->tex_c[dir] * inv_eps);
    return !(t >= 1.0) ? 1 : t >= (double)max_texels ? max_texels : (int32_t)t;
}

#ifdef __cplusplus
}
#endif
#endif

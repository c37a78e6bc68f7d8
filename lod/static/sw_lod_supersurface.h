/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: super-surfaces, Kumar et al. 1997 §3 — a partition of a scene's rational Bézier
 * patches into connected clusters whose Gauss map fits a cone of half-angle alpha, for static LODs
 * (§4.1-§4.3) and back-patch culling (§4.4).
 *
 * The pseudo-Gauss map (gauss_map.c). For a rational patch S = P / W of degrees (m, n), with
 * P = (w x, w y, w z) and W = w the homogeneous net,
 *
 *     N = W^3 (S_u x S_v) = W (P_u x P_v) - W_v (P_u x P) - W_u (P x P_v)          (Kumar eq. 1)
 *
 * is a polynomial; every term is a product of nets of degrees m, m-1, m in u (and n, n, n-1 in v),
 * so we form it in the Bernstein basis of degrees (3m-1, 3n-1). (Its true degree is at most
 * (3m-2, 3n-2): the leading coefficients cancel. Kumar's "3m x 3n" is a further elevation. Elevated
 * control rays are convex combinations of the lower-degree ones, so the (3m-1, 3n-1) form is no
 * looser than the exact-degree one and needs no reduction.) W > 0, so N points along S_u x S_v,
 * and every value of N is a non-negative combination of its coefficients, the "control rays":
 * every normal direction of the patch lies in the cone they span.
 *
 * Patches. Face f's patches are those of sw_lod_face_patches(): sw_sg_surface_extract_bezier_in()
 * over the face's uv_box, each net then cut (exactly, by de Casteljau) to the intersection of its
 * knot rectangle with uv_box; patch (iu, iv) is set.patches[iv * set.n_u + iu] of that set. These
 * are the patches lod/hierarchy/hierarchy.c builds its trees from (use_box = 1), so a static LOD
 * built from a cluster covers exactly the patches the dynamic path draws for the same faces.
 *
 * Orientation. Cones are of the B-rep's outward normal: S_u x S_v, negated for faces with
 * SW_SG_FACE_REVERSED. Boxes and cones are in the face's object space (the frame of its control
 * points), not the world: a face drawn under several instances has one cluster, transformed by the
 * caller (a rigid transform maps the cone's axis, a reflection also flips it).
 */
#ifndef SW_LOD_SUPERSURFACE_H
#define SW_LOD_SUPERSURFACE_H

#include "sw_module_abi.h"

#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- normal cones (gauss_map.c) -------------------------------------------------------------- */

/* A cone of directions around a unit axis. half_angle in [0, pi]; half_angle == pi (cos == -1) is
 * the full sphere (no bound: the axis is then meaningless). half_angle > pi/2 means the directions
 * do not lie in one open half-space, so nothing bounded by it can be back-culled. */
typedef struct sw_lod_cone {
    double axis[3];
    double half_angle;
    double cos_half_angle;
} sw_lod_cone;

/* The rounding bound of a control ray: SW_LOD_GAUSS_ROUNDING_ULPS * (2 (m+1)(n+1) + 16) *
 * DBL_EPSILON times its magnitude bound (the same products taken in absolute value) — the products
 * are summed in two stages of at most (m+1)(n+1) terms each, and the factor 4 is headroom. Rays
 * within their bound are rounding noise of a zero ray — the degenerate edges at poles of spheres
 * and apexes of cones, where S_u x S_v vanishes — and carry no direction. */
#define SW_LOD_GAUSS_ROUNDING_ULPS 4.0
/* The cone bounds the direction of N(s, t) wherever |N(s, t)| >= SW_LOD_GAUSS_VALID_REL * (largest
 * control ray's length); nearer a degenerate point N has no reliable direction (it is the noise of
 * the dropped rays). The dropped rays and the rounding of the kept ones widen the cone by
 * asin(E / that floor), E = the largest dropped ray + the largest rounding bound (about 1e-8 rad
 * for a bicubic patch without heavy cancellation). */
#define SW_LOD_GAUSS_VALID_REL 1e-6

/* Largest patch degree the Bézier form is computed for: 3 * 23 - 1 stays within
 * SW_LOD_BEZ_MAX_DEGREE. Patches of higher degree get the full cone. */
#define SW_LOD_GAUSS_MAX_DEGREE 23

/* Degrees (3m-1, 3n-1) of the pseudo-normal net of a patch of degrees (m, n) >= 1. */
void sw_lod_pseudo_normal_degrees(int32_t deg_u, int32_t deg_v, int32_t *nu, int32_t *nv);
/* Doubles of scratch sw_lod_pseudo_normal_net and sw_lod_gauss_cone need. */
size_t sw_lod_gauss_scratch_bound(int32_t deg_u, int32_t deg_v);

/* The pseudo-normal net N = W^3 (S_u x S_v) of the rational Bézier patch cpw (homogeneous,
 * (deg_u+1)*(deg_v+1)*4 doubles, u fastest), over its local [0,1]^2: out[3 * k] for coefficient
 * k = j * (3 deg_u) + i, i.e. u fastest with 3*deg_u columns. mag (may be NULL) receives per
 * coefficient the same sum with every product taken in absolute value, a bound on the size of the
 * terms that cancelled. Preconditions (asserts): 1 <= degrees <= SW_LOD_GAUSS_MAX_DEGREE, scratch
 * of sw_lod_gauss_scratch_bound doubles; out, mag and scratch do not overlap. */
void sw_lod_pseudo_normal_net(int32_t deg_u, int32_t deg_v, const double *cpw, double *scratch,
                              double *out, double *mag);

/* The normal cone of the patch from its control rays (as sw_lod_pseudo_normal_net, zero rays
 * dropped as described above), for the un-negated S_u x S_v. Rays that need a cone of 90 degrees
 * or more (a cone wider than a half-space is not convex, so it need not hold their non-negative
 * combinations), degrees above SW_LOD_GAUSS_MAX_DEGREE, or rays all zero or non-finite give the
 * full cone. Returns 1 when the cone is a bound (not the full cone), else 0. */
int sw_lod_gauss_cone(int32_t deg_u, int32_t deg_v, const double *cpw, double *scratch,
                      sw_lod_cone *out);

/* Small enclosing cone of n cones (caps; half-angle 0 for plain unit directions): an axis found by
 * a few steps toward the farthest cap from the mean direction, and the half-angle that axis needs
 * (so the result always contains every input, however far from minimal the axis is). A full input
 * or a needed half-angle >= pi gives the full cone. n >= 1. */
void sw_lod_cone_enclose(const sw_lod_cone *cones, size_t n, sw_lod_cone *out);
/* The smallest cone containing the cones a and b (exact for two caps). */
void sw_lod_cone_merge(const sw_lod_cone *a, const sw_lod_cone *b, sw_lod_cone *out);
/* Whether outer contains inner, with `slack` radians of tolerance. */
int sw_lod_cone_contains(const sw_lod_cone *outer, const sw_lod_cone *inner, double slack);
/* Sets c's half-angle (clamped to [0, pi]) and its cosine. */
void sw_lod_cone_set_angle(sw_lod_cone *c, double half_angle);

/* ---- a face's patches ------------------------------------------------------------------------ */

/* Extracts face `face`'s Bézier patches over its uv_box and cuts each net in place to its knot
 * rectangle intersected with uv_box; the patch's u0, u1, v0, v1 are set to that cut rectangle.
 * Free with sw_sg_bezier_set_free. Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_INVALID_ARGUMENT (a uv_box
 * that misses the domain). Precondition: SW_SG_SEC_FACES and SW_SG_SEC_POOL required. */
SW_MODULE_ABI sw_result sw_lod_face_patches(const sw_sg_scene *scene, uint32_t face,
                                            sw_sg_bezier_set *out, sw_status *status);

/* ---- super-surfaces (supersurface.c) --------------------------------------------------------- */

/* One Bézier patch: face index, and its (iu, iv) in the grid of sw_lod_face_patches(face). */
typedef struct sw_lod_ss_patch {
    uint32_t face;
    uint16_t iu, iv;
} sw_lod_ss_patch;

enum sw_lod_ss_cluster_flags {
    /* All its faces belong to a closed shell with consistent orientation (the importer's
     * SW_SG_FACE_CLOSED_SHELL), so the cone may cull it from behind (Kumar §4.4). */
    SW_LOD_SS_BACK_CULLABLE = 1u << 0,
    /* A single patch without a usable cone bound (full cone; see sw_lod_gauss_cone). */
    SW_LOD_SS_FULL_CONE = 1u << 1,
    /* Grown by the second pass: its cone is within merge_alpha_deg, not alpha_deg. */
    SW_LOD_SS_MERGED = 1u << 2,
    /* Absorbed a tiny cluster: its cone is within 90 degrees only. */
    SW_LOD_SS_MERGED_TINY = 1u << 3,
};

/* A super-surface: patches[first, first + count), sorted by (face, iv, iu). */
typedef struct sw_lod_ss_cluster {
    uint32_t first, count;
    double axis[3];        /* outward normal cone: unit axis ... */
    double cos_half_angle; /* ... and cosine of its half-angle (-1: no bound) */
    double half_angle;     /* radians, in [0, pi] */
    double box[6];         /* object-space box of the patches' control points: lo xyz, hi xyz */
    uint32_t flags;        /* sw_lod_ss_cluster_flags */
} sw_lod_ss_cluster;

/* Two patches (indices into patches[]) that share an edge: a Bézier-grid neighbour in one face,
 * or patches of B-rep-adjacent faces along their common trim boundary (found by sampling both
 * boundaries in 3D: a sample of one face within the edge tolerances + 1 % of a chord of the other
 * face's sampled boundary; chords are split at knot lines so each lies in one patch). Not
 * included: a periodic face's seam (the importer records no face as adjacent to itself), and
 * patches that touch only at a corner are paired only when the sampling happens to meet there.
 * a < b. */
typedef struct sw_lod_ss_pair {
    uint32_t a, b;
} sw_lod_ss_pair;

typedef struct sw_lod_supersurfaces {
    sw_lod_ss_patch *patches; /* n_patches, grouped by cluster */
    sw_lod_cone *patch_cones; /* n_patches, outward, aligned with patches[] */
    uint32_t *cluster_of;     /* n_patches: cluster index of patches[k] */
    uint32_t n_patches;
    sw_lod_ss_cluster *clusters;
    uint32_t n_clusters;
    sw_lod_ss_pair *adjacency; /* patch adjacency the clustering grew over, sorted */
    uint32_t n_adjacency;
    double alpha, merge_alpha; /* the bounds used, radians */
} sw_lod_supersurfaces;

/* Zero fields take the defaults (sw_lod_ss_desc_defaults). */
typedef struct sw_lod_ss_desc {
    double alpha_deg;       /* cone half-angle bound of a grown cluster; default 45 */
    uint32_t min_patches;   /* second pass: clusters below this many patches merge; default 4 */
    double merge_alpha_deg; /* bound a merged cluster's cone must stay within; default 1.5 alpha */
    double tiny_rel;        /* a cluster below min_patches whose box diagonal is below tiny_rel of
                             * the neighbour's merges even beyond merge_alpha (up to 90 degrees);
                             * default 0.02; negative disables */
} sw_lod_ss_desc;

void sw_lod_ss_desc_defaults(sw_lod_ss_desc *desc);

/* Clusters every patch of every face of the scene. desc may be NULL (defaults). Deterministic:
 * the same scene and desc give the same output, bit for bit. Precondition: SW_SG_SEC_FACES,
 * LOOPS, CURVES, ADJACENCY and POOL required. On success *out is owned by the caller (free with
 * sw_lod_supersurfaces_free). Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (a face with more than
 * 65535 patches in u or v), SW_ERR_INVALID_ARGUMENT (bad desc values, a face whose uv_box misses
 * its domain), SW_ERR_INVALID_GEOMETRY (a trim loop that cannot be flattened). */
sw_result sw_lod_supersurfaces_build(const sw_sg_scene *scene, const sw_lod_ss_desc *desc,
                                     sw_lod_supersurfaces **out, sw_status *status);
void sw_lod_supersurfaces_free(sw_lod_supersurfaces *ss); /* NULL allowed */

#ifdef __cplusplus
}
#endif
#endif

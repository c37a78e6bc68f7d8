/* SPDX-License-Identifier: MIT */
/* splinewalk lod/: cluster proxies, the hierarchical LOD across objects (Erikson et al. 2001,
 * "HLODs"): one mesh standing for every unit instance under a node of the static set's BVH, drawn
 * instead of them where its error bound is within the view's tolerance.
 *
 * A proxy is made by vertex clustering (Rossignac and Borrel 1993) of its inputs — the instances'
 * static levels, or the proxies of the node's children — on a grid of cubic cells: the vertices of
 * one cell, of one part (a colour) and of one normal class (the dominant axis of the normal, with
 * its sign) become one vertex, their mean; a triangle whose three vertices stay distinct survives.
 * Clustering merges across the gaps between faces and units (closing the cracks a cell spans).
 * Normal classes keep the two sides of a thin plate and the faces of a sharp edge apart, so
 * shading keeps its creases.
 *
 * The bound (sw_lod_proxy_mesh.bound) is certified, both ways, with no sampling. Each input vertex
 * v moves to its representative r(v), |v - r(v)| = d_v.
 *  - output -> input: a surviving triangle (r_a, r_b, r_c) is the image of an input triangle
 *    (v_a, v_b, v_c) under the affine map that moves each corner to its representative; its point
 *    sum l_i r_i lies within sum l_i d_i <= max d_i of the input point sum l_i v_i.
 *  - input -> output: a point of an input triangle whose image survives is, the same way, within
 *    max d_i of the output. A triangle whose image collapsed to a point or a segment is within
 *    max d_i of it; where that point or segment is a vertex or an edge of the output, that is all.
 *    Where it is not (a part smaller than a cell, which clustering alone would let vanish, as
 *    Rossignac and Borrel's does), the triangle is kept as it is: its distance is 0.
 * So bound = max d_v over the vertices of surviving or collapsed-onto-the-output triangles. The
 * input's own error (each level's ε_k, certified against the exact surface both ways, or a child
 * proxy's bound) adds to it by the triangle inequality. */
#ifndef SW_LOD_PROXY_H
#define SW_LOD_PROXY_H

#include <splinewalk/sw_result.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_proxy_input {
    const double *pos;    /* 3 per vertex */
    const float *nrm;     /* 3 per vertex, unit */
    const uint32_t *part; /* per vertex: its part (< n_parts); a triangle's corners share one */
    uint32_t n_vertices, n_parts;
    const uint32_t *tri; /* 3 per triangle */
    uint32_t n_triangles;
} sw_lod_proxy_input;

typedef struct sw_lod_proxy_mesh {
    double *pos;    /* 3 per vertex, the input's frame */
    float *nrm;     /* 3 per vertex, unit */
    uint32_t *part; /* per vertex */
    uint32_t *tri;  /* 3 per triangle, the input's orientation */
    uint32_t n_vertices, n_triangles;
    double bound;       /* certified Hausdorff distance between input and output, both ways */
    uint64_t collapsed; /* input triangles whose image is a point or a segment */
    uint64_t vanished;  /* of them, images not on the output: kept as they are */
} sw_lod_proxy_mesh;

/* Clusters `in` on the grid of cells of size `cell` > 0 whose corner is `origin`. The output's
 * vertices are grouped by part, in increasing part order. Errors: SW_ERR_INVALID_ARGUMENT (a cell
 * that is not positive and finite, an index out of range, a grid of more than 2^40 cells per
 * axis), SW_ERR_OUT_OF_MEMORY. */
sw_result sw_lod_proxy_cluster(const sw_lod_proxy_input *in, double cell, const double origin[3],
                               sw_lod_proxy_mesh *out, sw_status *status);
void sw_lod_proxy_mesh_free(sw_lod_proxy_mesh *m); /* NULL allowed */

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* gpu/ private: conservative occlusion culling on the visibility thread, with no GL.
 *
 * A software depth map of the frame at a quarter of its resolution holds, per map pixel, a depth
 * beyond which nothing at that pixel can be seen: the farthest point, within the pixel, of a
 * planar face already found visible that covers the whole pixel. The cull stage walks the BVH near
 * to far (stage_cull.c); each node and each face occurrence whose box lies behind the map over
 * its whole screen rectangle is culled, and each visible planar face big enough on screen is
 * drawn into the map as it is found. Nothing is carried from frame to frame, so a frame culls
 * exactly what its own view hides: no pixel lost, no pop when something comes into view.
 *
 * Why it is conservative (what the drawn frame shows, not just the exact surfaces):
 *  - An occluder is a planar face (sw_sg_surface_affine): the GPU draws it exactly up to its trim
 *    texture and float rounding. Its outline is its trim loops flattened once per scene (their
 *    object-space distance from the exact loops is stored), mapped by the plane and clipped at the
 *    near plane. A map pixel counts as covered only when its square lies inside the outline and
 *    farther than `margin` pixels from every outline edge, the margin being that flattening error
 *    on screen plus the frame's ε_img plus a pixel of the full frame: the drawn face, with its trim
 *    texture at the resolution its error bound needs, covers at least that shrunk region (a trim
 *    texture drawn coarser — the frame's atlas budget — is counted in bound_exceeded).
 *  - Its depth over a covered pixel is the largest of the plane's depths at the pixel's four
 *    corners (1 / depth is affine in screen coordinates on a plane, so the corners bound it), with
 *    a relative allowance for the depth buffer's and the float evaluation's rounding.
 *  - A box is hidden only when every map pixel its projection (grown by two full-frame pixels,
 *    for fat-border slivers and rasterisation) touches is covered nearer than the box's nearest
 *    depth, and no corner of the box is nearer than the near plane.
 * So every pixel an occluded face would have drawn is drawn by an occluder nearer to the eye.
 */
#ifndef SW_GPU_OCCLUSION_H
#define SW_GPU_OCCLUSION_H

#include "sw_gpu.h"
#include "sw_gpu_internal.h"

#include <stddef.h>
#include <stdint.h>

/* ---- per scene: the planar faces' outlines (occluders.c) ------------------------------------ */
typedef struct sw__occ_face {
    uint32_t first_loop, n_loops; /* loops of sw_gpu_occluders.loop_first / loop_count; 0: none */
    double err;                   /* object-space distance of the outline from the exact loops */
} sw__occ_face;

struct sw_gpu_occluders {
    uint64_t scene_serial; /* sw_sg_scene_serial of the scene it was built for */
    uint32_t n_faces, n_occluders;
    sw__occ_face *faces;               /* n_faces */
    uint32_t *loop_first, *loop_count; /* per loop: its first point and its point count */
    double *points;                    /* 3 per point, object space */
    size_t n_loops, n_points;
};

/* ---- per frame: the map (occlusion.c) ------------------------------------------------------ */
typedef struct sw__occ_map {
    int32_t w, h;     /* map pixels */
    int32_t tw, th;   /* 8 x 8 tiles */
    float *depth;     /* w x h: depth beyond which the pixel is hidden; INFINITY: not covered */
    float *tile_max;  /* tw x th: the largest depth of the tile's pixels */
    double scale;     /* full-frame pixels per map pixel */
    double f, cx, cy; /* focal length and centre in map pixels */
    double right[3], up[3], fwd[3], near_plane;
    double edge_margin; /* map pixels an outline edge keeps from a covered pixel (ε_img + 1
                           full-frame pixel), without the outline's own error */
    double box_margin;  /* map pixels a tested box's rectangle grows by */
    double min_extent;  /* map pixels an occluder's rectangle must span in x and y */
    /* scratch of one occluder */
    double *pts; /* projected points, 3 per point (x, y, depth) */
    size_t cap_pts;
    uint32_t *counts;
    size_t cap_counts;
    uint8_t *band; /* the occluder rectangle's pixels touched by an edge's margin */
    size_t cap_band;
    double *xs; /* one row's crossings */
    size_t cap_xs;
    double *vp; /* one loop's points in view space, before clipping */
    size_t cap_vp;
    /* counters of the frame */
    uint64_t occluders_drawn, tests, hidden;
} sw__occ_map;

/* A map for the view at a quarter of its resolution (at least 1 x 1), ε_img eps_px. Returns 0
 * when out of memory (the frame then culls without occlusion). */
int sw__occ_map_init(sw__occ_map *m, const sw__gpu_view *v, double eps_px);
void sw__occ_map_free(sw__occ_map *m);

/* Draws face `face` of an occurrence with transform world (row-major 3 x 4) into the map when it
 * is an occluder, its outline is in front of the eye in part and its rectangle spans min_extent.
 * Returns 1 when drawn, 0 when not, -1 when out of memory. */
int sw__occ_map_add_face(sw__occ_map *m, const sw_gpu_occluders *oc, uint32_t face,
                         const double world[12], const double eye[3]);

/* 1 when everything in the eye-relative box (min xyz, max xyz) is hidden by the map. */
int sw__occ_map_box_hidden(sw__occ_map *m, const double box[6]);

#endif

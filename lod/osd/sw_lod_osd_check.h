/* SPDX-License-Identifier: MIT */
/* The OpenSubdiv cross-check (`splinewalk check-osd`): every uniform, non-rational bicubic
 * B-spline region of a scene — a knot span whose six surrounding knots are equally spaced in both
 * directions, on a face whose weights are all equal — is evaluated by the project's NURBS
 * evaluator, by de Casteljau on its extracted Bézier patch, and by OpenSubdiv's limit evaluation of
 * the same control net (its regular patches are uniform unclamped bicubic B-splines). Anything
 * else has OCCT as its reference (tests/import). */
#ifndef SW_LOD_OSD_CHECK_H
#define SW_LOD_OSD_CHECK_H

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_lod_osd_report {
    uint64_t faces_checked; /* faces with at least one uniform region */
    uint64_t regions;       /* uniform regions evaluated */
    uint64_t samples;
    double max_rel_nurbs;  /* max |ours - OSD| / diagonal of the region's control net */
    double max_rel_bezier; /* the same for the extracted Bézier patch */
} sw_lod_osd_report;

/* Checks face `face` of a scene (SW_SG_SEC_ALL required) at `samples_per_region` points of each
 * uniform region (deterministic, seeded by `seed`), accumulating into *report. Errors from
 * OpenSubdiv (SW_ERR_INTERNAL, SW_ERR_OUT_OF_MEMORY) are passed on. */
sw_result sw_lod_osd_check_face(const sw_sg_scene *scene, uint32_t face, int samples_per_region,
                                uint64_t seed, sw_lod_osd_report *report, sw_status *status);

/* Checks a generated uniform test net: an nx x ny grid of random heights (seeded) as a uniform
 * unclamped bicubic B-spline surface, every interior region. */
sw_result sw_lod_osd_check_generated(int32_t nx, int32_t ny, int samples_per_region, uint64_t seed,
                                     sw_lod_osd_report *report, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: MIT */
/* Exporting a scene as an OCCT BREP compound (export_occt.cpp, a C++ shim that lets no exception
 * through), so that OCCT-based programs read the very geometry splinewalk draws: every face a
 * Geom_BSplineSurface bounded by wires of its trim loops' pcurves, every instance a located copy
 * sharing its prototype's TShape, transforms as locations. Colours and names are not written.
 */
#ifndef SW_SG_EXPORT_H
#define SW_SG_EXPORT_H

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_sg_export_report {
    uint32_t faces;       /* TopoDS faces made (one per scene face drawn) */
    uint64_t occurrences; /* face occurrences of the compound, instances expanded */
} sw_sg_export_report;

/* The BREP text of `scene` (SW_SG_SEC_ALL required) in memory: *text is sw__malloc'd, NUL after
 * its *len bytes, the caller's to sw__free. Errors: SW_ERR_INVALID_GEOMETRY (OCCT refused a
 * face's surface or curves; the face is named), SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL (an OCCT
 * exception). `report` may be NULL. */
sw_result sw_sg_export_brep_text(const sw_sg_scene *scene, char **text, size_t *len,
                                 sw_sg_export_report *report, sw_status *status);
/* sw_sg_export_brep_text written to `path` through the project's one writer (sw_safe_write.h:
 * replaced whole or left as it was). Adds its errors: SW_ERR_IO (a full disk too),
 * SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE. */
sw_result sw_sg_export_brep(const sw_sg_scene *scene, const char *path, sw_sg_export_report *report,
                            sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

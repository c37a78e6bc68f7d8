/* SPDX-License-Identifier: MIT */
/* Importing STEP / IGES / BREP through OpenCASCADE (import_occt.cpp, a C++ shim that lets no
 * exception through). Every face becomes a NURBS surface with its wires' pcurves as 2D rational
 * B-spline trim loops (snapped closed), its orientation, the assembly tree with instances and
 * transforms (XCAF for STEP), colours where present, and face adjacency through shared edges.
 */
#ifndef SW_SG_IMPORT_H
#define SW_SG_IMPORT_H

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Progress in [0, 1]; called from the importing thread. */
typedef void (*sw_sg_progress_fn)(void *ctx, double fraction, const char *stage);
/* A face that could not be converted: named, counted, never silently dropped. */
typedef void (*sw_sg_warning_fn)(void *ctx, const char *message);

typedef struct sw_sg_import_desc {
    const char *path;            /* .step/.stp/.iges/.igs/.brep (case-insensitive) */
    sw_sg_progress_fn progress;  /* may be NULL */
    sw_sg_warning_fn warning;    /* may be NULL */
    void *user_data;
} sw_sg_import_desc;

typedef struct sw_sg_import_report {
    uint32_t faces_read, faces_converted, faces_failed;
    double ms_read, ms_convert;
} sw_sg_import_report;

/* Errors: SW_ERR_NOT_FOUND, SW_ERR_UNSUPPORTED (extension), SW_ERR_FORMAT (the reader failed,
 * or the file holds no faces), SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL (an OCCT exception, with its
 * message). `report` may be NULL. */
sw_result sw_sg_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                            sw_sg_import_report *report, sw_status *status);

/* Adds the faces of `path` under node `parent` of an existing builder with a transform (NULL =
 * identity): how the built-in default scene assembles several models. */
sw_result sw_sg_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                            const sw_sg_import_desc *desc, sw_sg_import_report *report,
                            sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

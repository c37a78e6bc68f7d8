/* SPDX-License-Identifier: MIT */
/* Importing STEP / IGES / BREP through OpenCASCADE (import_occt.cpp, a C++ shim that lets no
 * exception through, in the import module; the core calls it through an installed importer). Every
 * face becomes a NURBS surface with its wires' pcurves as 2D rational B-spline trim loops (snapped
 * closed), its orientation, the assembly tree with instances and transforms (XCAF for STEP),
 * colours where present, and face adjacency through shared edges.
 */
#ifndef SW_SG_IMPORT_H
#define SW_SG_IMPORT_H

#include "sw_module_abi.h"

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Progress in [0, 1]; called from the importing thread. */
typedef void (*sw_sg_progress_fn)(void *ctx, double fraction, const char *stage);
/* A face that could not be converted: named, counted, never silently dropped. */
typedef void (*sw_sg_warning_fn)(void *ctx, const char *message);

/* A face the importer skipped or repaired, as a record (the warning callback gets the same in
 * words). Strings are borrowed for the call only. */
typedef enum sw_sg_face_action { SW_SG_FACE_SKIPPED = 1, SW_SG_FACE_REPAIRED = 2 } sw_sg_face_action;
typedef struct sw_sg_face_problem {
    const char *path;          /* the file */
    uint32_t face;             /* the face's index in the file, 0-based, in OCCT's reading order
                                  (as `info` counts faces read); SW_SG_NONE for a face the reader
                                  dropped before conversion */
    uint32_t entity;           /* the file's own number of a face the reader dropped (STEP #N,
                                  IGES directory entry); 0 otherwise */
    const char *name;          /* the name of the part holding the face; "" if none */
    sw_sg_face_action action;
    sw_result reason;          /* SW_ERR_INVALID_GEOMETRY (the face's data), SW_ERR_UNSUPPORTED
                                  (beyond what the scene holds: degree > SW_SG_MAX_DEGREE),
                                  SW_ERR_INTERNAL (OCCT failed on it) */
    const char *message;       /* what was wrong, and for a repair what was done */
} sw_sg_face_problem;
typedef void (*sw_sg_face_problem_fn)(void *ctx, const sw_sg_face_problem *problem);

/* sw_sg_import_desc.flags */
#define SW_SG_IMPORT_PARTIAL 1u /* a truncated file: import what is whole instead of refusing */

typedef struct sw_sg_import_desc {
    const char *path;            /* .step/.stp/.iges/.igs/.brep (case-insensitive) */
    sw_sg_progress_fn progress;  /* may be NULL */
    sw_sg_warning_fn warning;    /* may be NULL */
    void *user_data;
    sw_sg_face_problem_fn face_problem; /* may be NULL */
    uint32_t flags;                     /* SW_SG_IMPORT_* */
} sw_sg_import_desc;

typedef struct sw_sg_import_report {
    uint32_t faces_read, faces_converted, faces_failed; /* failed = skipped */
    uint32_t faces_repaired;  /* converted after an exact repair (counted in faces_converted) */
    uint32_t faces_dropped;   /* dropped by the reader before conversion (in faces_failed, not in
                                 faces_read) */
    int32_t truncated;        /* 1: the file was cut short and imported in part (PARTIAL) */
    double ms_read, ms_convert;
} sw_sg_import_report;

/* A face whose data cannot be drawn exactly (a zero weight, a degree above SW_SG_MAX_DEGREE, a
 * trim loop that does not close, ...) is repaired where an exact repair exists, else skipped; each
 * one goes to face_problem and warning, and the rest of the file is imported.
 * Errors: SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE, SW_ERR_UNSUPPORTED (extension),
 * SW_ERR_TRUNCATED (an IGES file whose Terminate record is missing or disagrees with its records,
 * without SW_SG_IMPORT_PARTIAL), SW_ERR_FORMAT (the reader failed, or the file holds no faces),
 * SW_ERR_OUT_OF_MEMORY, SW_ERR_INTERNAL (an OCCT exception, with its message). `report` may be
 * NULL. */
sw_result sw_sg_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                            sw_sg_import_report *report, sw_status *status);

/* Adds the faces of `path` under node `parent` of an existing builder with a transform (NULL =
 * identity): how the built-in default scene assembles several models. */
sw_result sw_sg_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                            const sw_sg_import_desc *desc, sw_sg_import_report *report,
                            sw_status *status);

/* ---- the installed importer (cad_import.c) ---------------------------------------------------
 * sw_sg_import_file and sw_sg_import_into live in the import module (import_occt.cpp, OpenCASCADE)
 * above the core. The core reads CAD files through the importer the module installs
 * (sw_import_install); without one, sw_sg_cad_import_file and sw_sg_cad_import_into return
 * SW_ERR_UNSUPPORTED saying so. */
typedef struct sw_sg_importer {
    sw_result (*import_file)(const sw_sg_import_desc *desc, sw_sg_scene **out,
                             sw_sg_import_report *report, sw_status *status);
    sw_result (*import_into)(sw_sg_builder *b, uint32_t parent, const double xform[12],
                             const sw_sg_import_desc *desc, sw_sg_import_report *report,
                             sw_status *status);
} sw_sg_importer;
/* `importer` must outlive its use (static storage); NULL uninstalls. Any thread. */
SW_MODULE_ABI void sw_sg_importer_install(const sw_sg_importer *importer);
/* sw_sg_import_file and sw_sg_import_into through the installed importer. */
sw_result sw_sg_cad_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                                sw_sg_import_report *report, sw_status *status);
sw_result sw_sg_cad_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                                const sw_sg_import_desc *desc, sw_sg_import_report *report,
                                sw_status *status);

#ifdef __cplusplus
}
#endif
#endif

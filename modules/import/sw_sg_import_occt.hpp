/* SPDX-License-Identifier: MIT */
/* C++-only entry points of the OCCT importer (import_occt.cpp) with a per-face observer, so tests
 * can compare each imported face with OCCT's own geometry of the same face. Never included from C.
 */
#ifndef SW_SG_IMPORT_OCCT_HPP
#define SW_SG_IMPORT_OCCT_HPP

#include "sw_sg_import.h"

#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

struct sw__occt_face_observer {
    virtual ~sw__occt_face_observer() = default;
    /* Scene face `face` was made from `source` (as located in its part's frame) through
     * `converted`, its NURBS conversion: the surface and the pcurves the loops come from. */
    virtual void on_face(uint32_t face, const TopoDS_Face &source,
                         const TopoDS_Face &converted) = 0;
};

/* sw_sg_import_into / sw_sg_import_file with an observer (may be NULL). */
sw_result sw__occt_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                               const sw_sg_import_desc *desc, sw_sg_import_report *report,
                               sw_status *status, sw__occt_face_observer *observer);
/* The faces of a shape already in memory, converted, checked and repaired as an imported file's
 * are (no XCAF names or colours), into b under its root; desc->path names the shape in messages
 * and is not opened. The importer's conversion layer without a reader: its fuzz harness calls it.
 */
sw_result sw__occt_import_shape(sw_sg_builder *b, const TopoDS_Shape &shape,
                                const sw_sg_import_desc *desc, sw_sg_import_report *report,
                                sw_status *status);
/* The shape of a BREP, STEP (.step, .stp) or IGES (.iges, .igs) file by OCCT's plain readers,
 * the format by the extension: no XCAF names or colours, no partial reading, no message. A null
 * shape when the file cannot be read, holds nothing or has another extension. The importer's
 * fall-back, and the reader of tools that make inputs from sample parts. */
TopoDS_Shape sw__occt_read_plain(const char *path);
sw_result sw__occt_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                               sw_sg_import_report *report, sw_status *status,
                               sw__occt_face_observer *observer);

#endif

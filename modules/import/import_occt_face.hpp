/* SPDX-License-Identifier: MIT */
/* The OCCT importer's face conversion (face_occt.cpp): one OCCT face into a NURBS surface and its
 * trim loops, plain data the importer then checks, repairs and adds. Never installed; C++ only. */
#ifndef SW_IMPORT_OCCT_FACE_HPP
#define SW_IMPORT_OCCT_FACE_HPP

#include "sw_sg_scene.h"

#include <TopoDS_Face.hxx>

#include <string>
#include <vector>

namespace sw_occt
{

/* A face converted but not yet in the builder: nothing is added unless all of it succeeded. */
struct curve_data {
    int32_t degree = 0;
    std::vector<double> knots, cpw; /* flat knots; (w*u, w*v, w) */
};
struct loop_data {
    uint32_t flags = 0;
    std::vector<curve_data> curves;
};
struct face_data {
    sw_sg_face_rec rec{};
    std::vector<double> knots_u, knots_v, cpw;
    std::vector<loop_data> loops;
};

/* A face that cannot be converted; the message says why, the code what kind of reason it is. */
struct face_error {
    std::string why;
    sw_result code = SW_ERR_INVALID_GEOMETRY;
};

/* The face as a NURBS surface with its loops (what = the face's name in messages). The conversion
 * runs on a copy scaled by 2^scale_exp (import_scale_exp) and the poles are scaled back;
 * `converted` is the face BRepBuilderAPI_NurbsConvert made, at the scaled size. Throws face_error
 * or Standard_Failure when it cannot. */
face_data convert_face(const TopoDS_Face &f, TopoDS_Face &converted, const std::string &what,
                       int scale_exp);
/* The face scaled by 2^scale_exp about the origin (its tolerances alike), or itself. */
TopoDS_Face scaled_face(const TopoDS_Face &f, int scale_exp);
/* The power of two by which a shape is scaled for its faces' conversion: OCCT converts with
 * absolute tolerances (Precision::Confusion, 1e-7), so a part 0.01 across is converted to 1e-5 of
 * its size. Nonzero when the vertices' box diagonal is below 1: it then brings it into
 * [64, 128), unless the largest coordinate would pass 1e15. */
int import_scale_exp(const TopoDS_Shape &shape);
/* The scene's own checks of one face, before it is added (SW_ERR_INVALID_GEOMETRY and why). */
sw_result validate_face(const face_data &fd, const std::string &what, sw_status *st);
/* Exact repairs of a face the checks refuse (weights out of range rescaled by one power of two,
 * each point unchanged); says what it did in `done`; true when something was repaired. */
bool repair_face(face_data &fd, std::string &done);

} // namespace sw_occt

#endif

/* SPDX-License-Identifier: MIT */
/* The OCCT importer's state, shared by the conversion of a shape into an sw_sg_builder
 * (import_occt.cpp) and the file and document readers that produce the shape
 * (read_occt.cpp). Private to the import module. */
#pragma once

#include "import_occt_face.hpp"
#include "sw_sg_iges.h"
#include "sw_sg_import_occt.hpp"
#include "sw_status_util.h"

#include <NCollection_DataMap.hxx>
#include <Standard_Failure.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelMapHasher.hxx>
#include <TDocStd_Document.hxx>
#include <TopAbs_Orientation.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_ShapeMapHasher.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XSControl_WorkSession.hxx>

#include <algorithm>
#include <exception>
#include <map>
#include <new>
#include <set>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace sw_occt
{

struct oom_error {
};

double now_ms();
void xform_of(const TopLoc_Location &loc, double x[12]);
bool is_identity(const TopLoc_Location &loc);
std::string base_name(const std::string &path);

struct rgba {
    float c[4];
};

class importer
{
  public:
    importer(sw_sg_builder *b, const sw_sg_import_desc *desc, sw__occt_face_observer *obs)
        : b_(b), desc_(desc), obs_(obs), path_(desc->path), name_(base_name(desc->path))
    {
    }

    sw_result run(uint32_t parent, const double xform[12], sw_sg_import_report *report,
                  sw_status *status);
    /* The faces of a shape already in memory, as run() converts what it read (no XCAF). */
    sw_result run_shape(const TopoDS_Shape &shape, uint32_t parent, const double xform[12],
                        sw_sg_import_report *report, sw_status *status);

  private:
    sw_sg_builder *b_;
    const sw_sg_import_desc *desc_;
    sw__occt_face_observer *obs_;
    std::string path_, name_;
    std::string part_name_; /* the XCAF name of the part whose faces are being converted */
    int scale_exp_ = 0;     /* faces converted scaled by 2^scale_exp_ (import_scale_exp) */
    sw_sg_import_report rep_{};
    uint32_t faces_estimate_ = 1;

    NCollection_DataMap<TopoDS_Shape, uint32_t, TopTools_ShapeMapHasher> faces_;
    std::set<std::pair<uint32_t, uint32_t>> adjacency_;
    /* Per converted face: the orientation its REVERSED flag was taken from, and its shell vote
     * (1: every part context so far a closed outward shell, 2: some context is not). */
    std::unordered_map<uint32_t, TopAbs_Orientation> face_orient_;
    std::unordered_map<uint32_t, uint8_t> closed_vote_;
    /* TopoDS sharing: occurrences of (TShape, orientation) among compound children. */
    std::map<std::pair<const void *, int>, int> uses_;
    std::map<std::pair<const void *, int>, uint32_t> protos_;
    /* XCAF */
    Handle(XCAFDoc_ShapeTool) st_;
    Handle(XCAFDoc_ColorTool) ct_;
    NCollection_DataMap<TDF_Label, int, TDF_LabelMapHasher> label_uses_;
    NCollection_DataMap<TDF_Label, uint32_t, TDF_LabelMapHasher> label_protos_;
    std::unordered_map<const void *, rgba> face_colors_;

    void progress(double f, const char *stage)
    {
        if (desc_->progress)
            desc_->progress(desc_->user_data, std::min(f, 1.0), stage);
    }
    void warn(const std::string &m)
    {
        if (desc_->warning)
            desc_->warning(desc_->user_data, m.c_str());
    }
    std::string part_note() const
    {
        return part_name_.empty() ? std::string() : " (part '" + part_name_ + "')";
    }
    /* A skipped or repaired face: to the warning callback in words, to face_problem as a record.
     * `face` is SW_SG_NONE for a face the reader dropped before conversion (`entity` names it). */
    void problem(uint32_t face, sw_sg_face_action action, sw_result reason,
                 const std::string &message, uint32_t entity = 0)
    {
        warn(message);
        if (desc_->face_problem) {
            const sw_sg_face_problem p{path_.c_str(), face,   entity,         part_name_.c_str(),
                                       action,        reason, message.c_str()};
            desc_->face_problem(desc_->user_data, &p);
        }
    }
    uint32_t node(sw_sg_node_kind kind, uint32_t parent, uint32_t ref, const double *xf,
                  const float *color, const char *name)
    {
        uint32_t n = sw_sg_builder_add_node(b_, kind, parent, ref, xf, color, name);
        if (n == SW_SG_NONE)
            throw oom_error{};
        return n;
    }

    sw_result read_brep(TopoDS_Shape &shape, sw_status *status);
    sw_result check_iges(sw_sg_iges_scan &scan, sw_status *status);
    sw_result read_iges_partial(const sw_sg_iges_scan &scan, TopoDS_Shape &shape,
                                sw_status *status);
    void report_dropped_faces(const Handle(XSControl_WorkSession) & ws, bool step);
    sw_result read_cad(Handle(TDocStd_Document) & doc, TopoDS_Shape &shape, bool step,
                       sw_status *status);
    void estimate_faces(const TopoDS_Shape &shape);
    sw_result convert(const TopoDS_Shape &shape, uint32_t parent, const double xform[12],
                      sw_status *status);

    void count_uses(const TopoDS_Shape &s, std::unordered_set<const void *> &seen);
    void add_shape(const TopoDS_Shape &s, uint32_t parent);
    void fill_shape(const TopoDS_Shape &local, uint32_t n);
    void add_part(const TopoDS_Shape &part, uint32_t n);
    bool shell_closed_outward(const TopoDS_Shape &shell) const;
    void vote_shells(const TopoDS_Shape &part);
    void mark_closed_faces();
    uint32_t face_index(const TopoDS_Face &f);
    uint32_t push_face(face_data &fd);

    void count_label_uses(const TDF_Label &l);
    void add_label(const TDF_Label &ref, const TDF_Label &occurrence, uint32_t parent,
                   const TopLoc_Location &loc);
    void fill_label(const TDF_Label &l, uint32_t n);
    bool label_color(const TDF_Label &l, rgba &out) const;
    std::string label_name(const TDF_Label &l) const;
};

/* Runs one import, turning what escapes it into a status naming `path`. */
template <typename F> sw_result guarded(const char *path, sw_status *status, F run)
{
    try {
        return run();
    } catch (const oom_error &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory while importing", path);
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory while importing", path);
    } catch (const Standard_Failure &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "%s: OCCT failed: %s: %s", path,
                        e.DynamicType()->Name(), e.GetMessageString());
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "%s: %s", path, e.what());
    } catch (...) {
        return sw__fail(status, SW_ERR_INTERNAL, "%s: unknown exception while importing", path);
    }
}

} // namespace sw_occt

/* SPDX-License-Identifier: MIT */
/* The OCCT importer's conversion of a shape into an sw_sg_builder: the part tree (XCAF labels
 * where a document reader made them, else the shape's own compounds), every face converted once
 * to a NURBS surface (BRepBuilderAPI_NurbsConvert, face_occt.cpp) whose wires' pcurves become 2D
 * rational B-spline trim loops, snapped closed (sw_sg_trim.h) as Guthe et al. 2005 §4's
 * parity-based trim textures require. Shapes shared with different locations become one prototype
 * subtree drawn by INSTANCE nodes. Faces sharing an edge are recorded as adjacent (for Kumar et al.
 * 1997's super-surfaces). The readers of STEP, IGES and BREP files are read_occt.cpp.
 *
 * This is a C++ shim: no exception leaves it. A face that cannot be converted becomes a warning
 * and a count, anything else SW_ERR_INTERNAL.
 */
#include "import_occt_importer.hpp"

#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <TDF_LabelSequence.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Iterator.hxx>
#include <gp_Trsf.hxx>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

namespace sw_occt
{

double now_ms()
{
    using namespace std::chrono;
    return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

void xform_of(const TopLoc_Location &loc, double x[12])
{
    const gp_Trsf t = loc.Transformation();
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            x[r * 4 + c] = t.Value(r + 1, c + 1);
}

/* A location chain can compose to the identity (Room.brep's walls). */
bool is_identity(const TopLoc_Location &loc)
{
    return loc.IsIdentity() || loc.Transformation().Form() == gp_Identity;
}

std::string base_name(const std::string &path)
{
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

void importer::estimate_faces(const TopoDS_Shape &shape)
{
    std::unordered_set<const void *> tshapes;
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next())
        tshapes.insert(ex.Current().TShape().get());
    faces_estimate_ = std::max<uint32_t>(1, (uint32_t)tshapes.size());
}

void importer::count_uses(const TopoDS_Shape &s, std::unordered_set<const void *> &seen)
{
    if (!seen.insert(s.TShape().get()).second || s.ShapeType() != TopAbs_COMPOUND)
        return;
    for (TopoDS_Iterator it(s, Standard_True, Standard_False); it.More(); it.Next()) {
        uses_[{it.Value().TShape().get(), (int)it.Value().Orientation()}]++;
        count_uses(it.Value(), seen);
    }
}

/* `s` is located in its parent's frame; a shape used more than once becomes a prototype. */
void importer::add_shape(const TopoDS_Shape &s, uint32_t parent)
{
    if (s.IsNull())
        return;
    double xf[12];
    xform_of(s.Location(), xf);
    const TopoDS_Shape local = s.Located(TopLoc_Location());
    const std::pair<const void *, int> key{s.TShape().get(), (int)s.Orientation()};
    auto u = uses_.find(key);
    if (u != uses_.end() && u->second > 1) {
        auto p = protos_.find(key);
        uint32_t proto;
        if (p == protos_.end()) {
            proto = node(SW_SG_NODE_GROUP, SW_SG_NONE, 0, nullptr, nullptr, nullptr);
            protos_[key] = proto;
            fill_shape(local, proto);
        } else {
            proto = p->second;
        }
        node(SW_SG_NODE_INSTANCE, parent, proto, xf, nullptr, nullptr);
        return;
    }
    uint32_t n = is_identity(s.Location())
                     ? parent
                     : node(SW_SG_NODE_TRANSFORM, parent, 0, xf, nullptr, nullptr);
    fill_shape(local, n);
}

void importer::fill_shape(const TopoDS_Shape &local, uint32_t n)
{
    if (local.ShapeType() == TopAbs_COMPOUND) {
        for (TopoDS_Iterator it(local, Standard_True, Standard_False); it.More(); it.Next())
            add_shape(it.Value(), n);
    } else {
        add_part(local, n);
    }
}

/* A solid, shell or face: its faces as SURFACE nodes under `n`, and their adjacency. */
void importer::add_part(const TopoDS_Shape &part, uint32_t n)
{
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(part, TopAbs_FACE, faces);
    for (int i = 1; i <= faces.Extent(); i++) {
        const TopoDS_Face &f = TopoDS::Face(faces(i));
        uint32_t idx = face_index(f);
        if (idx == SW_SG_NONE)
            continue;
        auto c = face_colors_.find(f.TShape().get());
        node(SW_SG_NODE_SURFACE, n, idx, nullptr, c == face_colors_.end() ? nullptr : c->second.c,
             nullptr);
    }
    TopTools_IndexedDataMapOfShapeListOfShape edge_faces;
    TopExp::MapShapesAndAncestors(part, TopAbs_EDGE, TopAbs_FACE, edge_faces);
    for (int i = 1; i <= edge_faces.Extent(); i++) {
        std::vector<uint32_t> idx;
        for (const TopoDS_Shape &f : edge_faces(i)) {
            const uint32_t *k = faces_.Seek(f);
            if (k && *k != SW_SG_NONE)
                idx.push_back(*k);
        }
        for (size_t a = 0; a < idx.size(); a++)
            for (size_t c = a + 1; c < idx.size(); c++)
                if (idx[a] != idx[c])
                    adjacency_.insert({std::min(idx[a], idx[c]), std::max(idx[a], idx[c])});
    }
    vote_shells(part);
}

/* Kumar et al. 1997 §4.4 culls back patches only of closed shells with consistent orientation
 * (an open sheet is seen from both sides). A shell qualifies when (1) each of its faces was
 * converted (a missing face is a hole to look through) with the orientation its scene face's
 * REVERSED flag was taken from; (2) every edge but degenerate ones (poles, apexes) is used exactly
 * twice, once FORWARD and once REVERSED in the orientation composed down from the shell — closed
 * and consistently oriented: neighbours traverse their common edge in opposite directions (a seam
 * is two uses in one face); (3) its signed volume (the divergence theorem over the oriented faces,
 * BRepGProp) is clearly positive, so the consistent normals point out, not in (a reversed shell,
 * or a solid's void). Anything else, or an OCCT failure, counts as not closed. */
bool importer::shell_closed_outward(const TopoDS_Shape &shell) const
{
    if (shell.Orientation() != TopAbs_FORWARD && shell.Orientation() != TopAbs_REVERSED)
        return false;
    NCollection_DataMap<TopoDS_Shape, std::pair<int, int>, TopTools_ShapeMapHasher> uses;
    int n_faces = 0;
    for (TopExp_Explorer fx(shell, TopAbs_FACE); fx.More(); fx.Next(), n_faces++) {
        const TopoDS_Shape &f = fx.Current();
        const uint32_t *k = faces_.Seek(f);
        if (!k || *k == SW_SG_NONE)
            return false;
        auto o = face_orient_.find(*k);
        if (o == face_orient_.end() || o->second != f.Orientation())
            return false;
        for (TopExp_Explorer ex(f, TopAbs_EDGE); ex.More(); ex.Next()) {
            const TopoDS_Edge &e = TopoDS::Edge(ex.Current());
            if (BRep_Tool::Degenerated(e))
                continue;
            if (e.Orientation() != TopAbs_FORWARD && e.Orientation() != TopAbs_REVERSED)
                return false;
            std::pair<int, int> *c = uses.ChangeSeek(e);
            if (!c)
                c = uses.Bound(e, {0, 0});
            (e.Orientation() == TopAbs_FORWARD ? c->first : c->second)++;
        }
    }
    if (n_faces == 0 || uses.IsEmpty())
        return false;
    for (NCollection_DataMap<TopoDS_Shape, std::pair<int, int>, TopTools_ShapeMapHasher>::Iterator
             it(uses);
         it.More(); it.Next())
        if (it.Value().first != 1 || it.Value().second != 1)
            return false;
    Bnd_Box bb;
    BRepBndLib::Add(shell, bb);
    if (bb.IsVoid())
        return false;
    const double diag = std::sqrt(bb.SquareExtent());
    GProp_GProps props;
    BRepGProp::VolumeProperties(shell, props);
    /* Far above the integration's noise, far below any real part's volume. */
    return std::isfinite(props.Mass()) && props.Mass() > 1e-9 * diag * diag * diag;
}

/* Every face of the part votes: closed when its shell qualifies, open otherwise (also a face in
 * no shell). A face is flagged only when all its votes, over all parts, say closed. */
void importer::vote_shells(const TopoDS_Shape &part)
{
    TopTools_IndexedMapOfShape in_shell;
    auto vote = [this](const TopoDS_Shape &f, bool closed) {
        const uint32_t *k = faces_.Seek(f);
        if (!k || *k == SW_SG_NONE)
            return;
        uint8_t &v = closed_vote_[*k];
        v = closed ? (v == 0 ? 1 : v) : 2;
    };
    for (TopExp_Explorer sx(part, TopAbs_SHELL); sx.More(); sx.Next()) {
        bool closed = false;
        try {
            closed = shell_closed_outward(sx.Current());
        } catch (const Standard_Failure &) {
            closed = false;
        }
        for (TopExp_Explorer fx(sx.Current(), TopAbs_FACE); fx.More(); fx.Next()) {
            vote(fx.Current(), closed);
            in_shell.Add(fx.Current());
        }
    }
    for (TopExp_Explorer fx(part, TopAbs_FACE); fx.More(); fx.Next())
        if (!in_shell.Contains(fx.Current()))
            vote(fx.Current(), false);
}

void importer::mark_closed_faces()
{
    for (const auto &v : closed_vote_)
        if (v.second == 1) {
            sw_sg_face_rec *rec = sw_sg_builder_face_ptr(b_, v.first);
            if (rec)
                rec->flags |= SW_SG_FACE_CLOSED_SHELL;
        }
}

/* The scene face of `f`, converting it the first time; SW_SG_NONE when it failed. */
uint32_t importer::face_index(const TopoDS_Face &f)
{
    if (const uint32_t *k = faces_.Seek(f))
        return *k;
    const uint32_t ordinal = rep_.faces_read++;
    const std::string what = name_ + ": face " + std::to_string(ordinal);
    uint32_t idx = SW_SG_NONE;
    std::string why, repaired;
    sw_result code = SW_OK;
    TopoDS_Face converted;
    try {
        face_data fd = convert_face(f, converted, what, scale_exp_);
        if (obs_) /* the observer sees it at the file's size, as the scene's face */
            converted = scaled_face(converted, -scale_exp_);
        sw_status st{};
        if (validate_face(fd, what, &st) != SW_OK) {
            /* the message names the face already ("FILE: face N: ...") */
            if (!repair_face(fd, repaired) || validate_face(fd, what, nullptr) != SW_OK) {
                repaired.clear();
                throw face_error{st.message, st.result};
            }
            std::string found = st.message;
            if (found.compare(0, what.size() + 2, what + ": ") == 0)
                found.erase(0, what.size() + 2);
            repaired = path_ + ": face " + std::to_string(ordinal) + part_note() +
                       " repaired: " + found + "; exact repair: " + repaired;
        }
        idx = push_face(fd);
        face_orient_[idx] = f.Orientation();
    } catch (const face_error &e) {
        why = e.why, code = e.code;
        if (why.compare(0, what.size() + 2, what + ": ") == 0) /* the message names the face */
            why.erase(0, what.size() + 2);
    } catch (const Standard_Failure &e) {
        why = std::string(e.DynamicType()->Name()) + ": " + e.GetMessageString();
        code = SW_ERR_INTERNAL;
    }
    if (idx == SW_SG_NONE) {
        rep_.faces_failed++;
        problem(ordinal, SW_SG_FACE_SKIPPED, code,
                path_ + ": face " + std::to_string(ordinal) + part_note() + " skipped: " + why);
    } else {
        rep_.faces_converted++;
        if (!repaired.empty()) {
            rep_.faces_repaired++;
            problem(ordinal, SW_SG_FACE_REPAIRED, SW_ERR_INVALID_GEOMETRY, repaired);
        }
        if (obs_)
            obs_->on_face(idx, f, converted);
    }
    faces_.Bind(f, idx);
    progress(0.1 + 0.9 * rep_.faces_read / faces_estimate_, "convert");
    return idx;
}

uint32_t importer::push_face(face_data &fd)
{
    auto push = [this](const std::vector<double> &v) {
        uint64_t off = sw_sg_builder_push_doubles(b_, v.data(), v.size());
        if (off == UINT64_MAX)
            throw oom_error{};
        return off;
    };
    fd.rec.knots_u = push(fd.knots_u);
    fd.rec.knots_v = push(fd.knots_v);
    fd.rec.cpw = push(fd.cpw);
    fd.rec.first_loop = SW_SG_NONE;
    for (const loop_data &ld : fd.loops) {
        sw_sg_loop_rec lr{SW_SG_NONE, (uint32_t)ld.curves.size(), ld.flags, 0};
        for (const curve_data &c : ld.curves) {
            sw_sg_curve_rec cr{};
            cr.degree = (uint32_t)c.degree;
            cr.n = (uint32_t)(c.cpw.size() / 3);
            cr.knots = push(c.knots);
            cr.cpw = push(c.cpw);
            uint32_t ci = sw_sg_builder_add_curve(b_, &cr);
            if (ci == SW_SG_NONE)
                throw oom_error{};
            if (lr.first_curve == SW_SG_NONE)
                lr.first_curve = ci;
        }
        uint32_t li = sw_sg_builder_add_loop(b_, &lr);
        if (li == SW_SG_NONE)
            throw oom_error{};
        if (fd.rec.first_loop == SW_SG_NONE)
            fd.rec.first_loop = li;
    }
    fd.rec.n_loops = (uint32_t)fd.loops.size();
    uint32_t fi = sw_sg_builder_add_face(b_, &fd.rec);
    if (fi == SW_SG_NONE)
        throw oom_error{};
    return fi;
}

/* The conversion of what was read: the part tree (XCAF labels where the reader made them, else the
 * shape's own compounds), each face converted once, closed shells and adjacency. */
sw_result importer::convert(const TopoDS_Shape &shape, uint32_t parent, const double xform[12],
                            sw_status *status)
{
    progress(0.1, "convert");
    const double t0 = now_ms();
    TDF_LabelSequence free;
    if (!st_.IsNull()) {
        st_->GetFreeShapes(free);
        TopoDS_Compound all;
        BRep_Builder bb;
        bb.MakeCompound(all);
        for (const TDF_Label &l : free) {
            bb.Add(all, st_->GetShape(l));
            count_label_uses(l);
        }
        estimate_faces(all);
        scale_exp_ = import_scale_exp(all);
    } else {
        std::unordered_set<const void *> seen;
        count_uses(shape, seen);
        estimate_faces(shape);
        scale_exp_ = import_scale_exp(shape);
    }
    uint32_t top = node(xform ? SW_SG_NODE_TRANSFORM : SW_SG_NODE_GROUP, parent, 0, xform, nullptr,
                        name_.c_str());
    if (!st_.IsNull()) {
        for (const TDF_Label &l : free)
            add_label(l, l, top, st_->GetLocation(l));
    } else {
        add_shape(shape, top);
    }
    mark_closed_faces();
    for (const auto &a : adjacency_)
        if (sw_sg_builder_add_adjacency(b_, a.first, a.second) == SW_SG_NONE)
            throw oom_error{};
    rep_.ms_convert = now_ms() - t0;
    if (rep_.faces_converted == 0)
        return sw__fail(status, SW_ERR_FORMAT, "%s: no face could be imported (%u read)",
                        path_.c_str(), rep_.faces_read);
    return SW_OK;
}

sw_result importer::run_shape(const TopoDS_Shape &shape, uint32_t parent, const double xform[12],
                              sw_sg_import_report *report, sw_status *status)
{
    const sw_result r = convert(shape, parent, xform, status);
    if (report)
        *report = rep_;
    if (r == SW_OK) {
        progress(1.0, "done");
        sw__status_ok(status);
    }
    return r;
}

} // namespace sw_occt

using namespace sw_occt;

sw_result sw__occt_import_shape(sw_sg_builder *b, const TopoDS_Shape &shape,
                                const sw_sg_import_desc *desc, sw_sg_import_report *report,
                                sw_status *status)
{
    if (!b || !desc || !desc->path)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "import: no builder or no name");
    return guarded(desc->path, status, [&] {
        importer imp(b, desc, nullptr);
        return imp.run_shape(shape, 0, nullptr, report, status);
    });
}

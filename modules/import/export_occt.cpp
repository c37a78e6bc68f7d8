/* SPDX-License-Identifier: MIT */
/* The BREP exporter (sw_sg_export.h). A trimmed face becomes a face on its Geom_BSplineSurface
 * whose wires are its trim loops: one edge per trim curve (the pcurve, as a Geom2d_BSplineCurve),
 * consecutive edges sharing a vertex at the surface point of their join. The 3D curve of an edge
 * on a planar face (a bilinear parallelogram: an affine map) is the pcurve's control polygon
 * mapped through it, exactly; elsewhere BRepLib approximates it. An edge whose image is one point
 * (a loop along a pole) is marked degenerate. An untrimmed face (its loop is its box) is made by
 * BRepBuilderAPI_MakeFace on that box, which also builds the seams of closed surfaces.
 *
 * The importer reads OCCT's convention, which the loops already follow: outer loops counter-
 * clockwise, holes clockwise, in a FORWARD face; a SW_SG_FACE_REVERSED face is written REVERSED.
 */
#include "sw_hooks.h"
#include "sw_safe_write.h"
#include "sw_sg_export.h"
#include "sw_status_util.h"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <BRep_Builder.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Trsf.hxx>

#include <cmath>
#include <cstring>
#include <new>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace
{

constexpr double k_tol = 1e-7;

struct export_error {
    sw_result r;
    std::string why;
};

/* A flat clamped knot vector as OCCT's distinct knots and multiplicities. */
void knots_mults(const double *k, int count, TColStd_Array1OfReal *&knots,
                 TColStd_Array1OfInteger *&mults)
{
    std::vector<double> v;
    std::vector<int> m;
    for (int i = 0; i < count; ++i) {
        if (!v.empty() && k[i] == v.back())
            m.back()++;
        else
            v.push_back(k[i]), m.push_back(1);
    }
    knots = new TColStd_Array1OfReal(1, (int)v.size());
    mults = new TColStd_Array1OfInteger(1, (int)v.size());
    for (size_t i = 0; i < v.size(); ++i)
        knots->SetValue((int)i + 1, v[i]), mults->SetValue((int)i + 1, m[i]);
}

Handle(Geom_BSplineSurface) bspline_surface(const sw_sg_surface &s)
{
    TColgp_Array2OfPnt poles(1, s.n_u, 1, s.n_v);
    TColStd_Array2OfReal weights(1, s.n_u, 1, s.n_v);
    for (int j = 0; j < s.n_v; ++j)
        for (int i = 0; i < s.n_u; ++i) {
            const double *h = s.cpw + ((size_t)j * s.n_u + i) * 4;
            poles(i + 1, j + 1) = gp_Pnt(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
            weights(i + 1, j + 1) = h[3];
        }
    TColStd_Array1OfReal *ku, *kv;
    TColStd_Array1OfInteger *mu, *mv;
    knots_mults(s.knots_u, s.n_u + s.deg_u + 1, ku, mu);
    knots_mults(s.knots_v, s.n_v + s.deg_v + 1, kv, mv);
    Handle(Geom_BSplineSurface) r;
    try {
        r = new Geom_BSplineSurface(poles, weights, *ku, *kv, *mu, *mv, s.deg_u, s.deg_v);
    } catch (...) {
        delete ku, delete kv, delete mu, delete mv;
        throw;
    }
    delete ku, delete kv, delete mu, delete mv;
    return r;
}

/* The 2D curve, and its image through the affine map `affine` (o, du, dv) when given. */
void bspline_curves(const sw_sg_curve &c, const double *affine, Handle(Geom2d_BSplineCurve) & c2,
                    Handle(Geom_BSplineCurve) & c3)
{
    TColgp_Array1OfPnt2d poles(1, c.n);
    TColgp_Array1OfPnt poles3(1, c.n);
    TColStd_Array1OfReal weights(1, c.n);
    for (int i = 0; i < c.n; ++i) {
        const double *h = c.cpw + (size_t)i * 3, u = h[0] / h[2], v = h[1] / h[2];
        poles(i + 1) = gp_Pnt2d(u, v);
        weights(i + 1) = h[2];
        if (affine)
            poles3(i + 1) = gp_Pnt(affine[0] + u * affine[3] + v * affine[6],
                                   affine[1] + u * affine[4] + v * affine[7],
                                   affine[2] + u * affine[5] + v * affine[8]);
    }
    TColStd_Array1OfReal *k;
    TColStd_Array1OfInteger *m;
    knots_mults(c.knots, c.n + c.degree + 1, k, m);
    try {
        c2 = new Geom2d_BSplineCurve(poles, weights, *k, *m, c.degree);
        if (affine)
            c3 = new Geom_BSplineCurve(poles3, weights, *k, *m, c.degree);
    } catch (...) {
        delete k, delete m;
        throw;
    }
    delete k, delete m;
}

/* A bilinear patch whose corners form a parallelogram, weights 1, over [a, b] x [c, d]: the
 * affine map (u, v) -> o + u du + v dv. */
bool affine_map(const sw_sg_surface &s, double out[9])
{
    if (s.deg_u != 1 || s.deg_v != 1 || s.n_u != 2 || s.n_v != 2)
        return false;
    const double *p = s.cpw;
    for (int i = 0; i < 4; ++i)
        if (p[4 * i + 3] != 1.0)
            return false;
    const double u0 = s.knots_u[1], u1 = s.knots_u[2], v0 = s.knots_v[1], v1 = s.knots_v[2];
    for (int k = 0; k < 3; ++k) {
        const double twist = p[12 + k] - p[8 + k] - p[4 + k] + p[k];
        if (std::fabs(twist) > 1e-12 * (1.0 + std::fabs(p[k])))
            return false;
        out[3 + k] = (p[4 + k] - p[k]) / (u1 - u0);
        out[6 + k] = (p[8 + k] - p[k]) / (v1 - v0);
        out[k] = p[k] - u0 * out[3 + k] - v0 * out[6 + k];
    }
    return true;
}

class exporter
{
  public:
    explicit exporter(const sw_sg_scene *scene) : scene_(scene), v_(sw_sg_scene_view_ptr(scene))
    {
        faces_.resize(v_->n_faces);
    }
    TopoDS_Shape node_shape(uint32_t n);
    uint32_t faces_made = 0;
    uint64_t occurrences = 0;

  private:
    const sw_sg_scene *scene_;
    const sw_sg_scene_view *v_;
    BRep_Builder bb_;
    std::vector<TopoDS_Face> faces_;
    std::unordered_map<uint32_t, TopoDS_Shape> protos_;
    std::unordered_map<uint32_t, uint64_t> proto_occ_;

    const TopoDS_Face &face(uint32_t f);
    TopoDS_Face make_face(uint32_t f);
    TopoDS_Wire make_wire(const sw_sg_loop_rec &l, const Handle(Geom_BSplineSurface) & s,
                          const TopoDS_Face &face, const double *affine, bool flip);
    double loop_area(const sw_sg_loop_rec &l) const;
    TopoDS_Shape children(uint32_t n, uint64_t &occ);
    TopoDS_Shape shape(uint32_t n, uint64_t &occ);
};

TopLoc_Location location_of(const double x[12])
{
    gp_Trsf t;
    t.SetValues(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], x[11]);
    return TopLoc_Location(t);
}

bool is_identity(const double x[12])
{
    static const double id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    for (int i = 0; i < 12; ++i)
        if (x[i] != id[i])
            return false;
    return true;
}

/* Signed area of a loop's control polygon: its orientation (the curves stay near it). */
double exporter::loop_area(const sw_sg_loop_rec &l) const
{
    double a = 0.0, first[2] = {0, 0}, prev[2] = {0, 0};
    bool any = false;
    for (uint32_t k = 0; k < l.n_curves; ++k) {
        sw_sg_curve c;
        sw_sg_scene_curve(scene_, l.first_curve + k, &c);
        for (int i = 0; i < c.n; ++i) {
            const double *h = c.cpw + (size_t)i * 3, p[2] = {h[0] / h[2], h[1] / h[2]};
            if (any)
                a += prev[0] * p[1] - p[0] * prev[1];
            else
                first[0] = p[0], first[1] = p[1], any = true;
            prev[0] = p[0], prev[1] = p[1];
        }
    }
    return 0.5 * (a + prev[0] * first[1] - first[0] * prev[1]);
}

/* The loop as a wire; flip: its edges reversed (and in reverse order), for loops that run
 * against OCCT's convention (the importer keeps a REVERSED face's loops as its wire explorer
 * walks them, reversed). */
TopoDS_Wire exporter::make_wire(const sw_sg_loop_rec &l, const Handle(Geom_BSplineSurface) & s,
                                const TopoDS_Face &face, const double *affine, bool flip)
{
    std::vector<TopoDS_Vertex> verts(l.n_curves);
    std::vector<sw_sg_curve> cs(l.n_curves);
    for (uint32_t k = 0; k < l.n_curves; ++k) {
        sw_sg_scene_curve(scene_, l.first_curve + k, &cs[k]);
        const double *h = cs[k].cpw; /* the start: the previous curve's end, bit for bit */
        bb_.MakeVertex(verts[k], s->Value(h[0] / h[2], h[1] / h[2]), k_tol);
    }
    TopoDS_Wire w;
    bb_.MakeWire(w);
    std::vector<TopoDS_Edge> edges(l.n_curves);
    for (uint32_t k = 0; k < l.n_curves; ++k) {
        const sw_sg_curve &c = cs[k];
        Handle(Geom2d_BSplineCurve) c2;
        Handle(Geom_BSplineCurve) c3;
        bspline_curves(c, affine, c2, c3);
        const double t0 = c.knots[c.degree], t1 = c.knots[c.n];
        const TopoDS_Vertex &a = verts[k], &b = verts[(k + 1) % l.n_curves];
        TopoDS_Edge e;
        bb_.MakeEdge(e);
        const gp_Pnt pa = BRep_Tool::Pnt(a), pb = BRep_Tool::Pnt(b);
        const gp_Pnt2d mid = c2->Value(0.5 * (t0 + t1));
        const bool degenerate =
            !affine && pa.Distance(pb) <= k_tol && pa.Distance(s->Value(mid.X(), mid.Y())) <= k_tol;
        if (c3)
            bb_.UpdateEdge(e, c3, k_tol);
        bb_.UpdateEdge(e, c2, face, k_tol);
        bb_.Range(e, t0, t1);
        bb_.Add(e, a.Oriented(TopAbs_FORWARD));
        bb_.Add(e, b.Oriented(TopAbs_REVERSED));
        if (degenerate)
            bb_.Degenerated(e, Standard_True);
        else if (!c3)
            BRepLib::BuildCurve3d(e, k_tol);
        edges[k] = e;
    }
    for (uint32_t k = 0; k < l.n_curves; ++k)
        bb_.Add(w, flip ? TopoDS::Edge(edges[l.n_curves - 1 - k].Reversed()) : edges[k]);
    w.Closed(Standard_True);
    return w;
}

TopoDS_Face exporter::make_face(uint32_t f)
{
    const sw_sg_face_rec &rec = v_->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene_, f, &s);
    Handle(Geom_BSplineSurface) bs = bspline_surface(s);
    TopoDS_Face face;
    if (!(rec.flags & SW_SG_FACE_TRIMMED) || rec.n_loops == 0) {
        BRepBuilderAPI_MakeFace mf(bs, rec.uv_box[0], rec.uv_box[1], rec.uv_box[2], rec.uv_box[3],
                                   k_tol);
        if (!mf.IsDone())
            throw export_error{SW_ERR_INVALID_GEOMETRY,
                               "face " + std::to_string(f) + ": OCCT made no face of its box"};
        face = mf.Face();
    } else {
        double affine[9];
        const bool flat = affine_map(s, affine);
        bb_.MakeFace(face, bs, k_tol);
        uint32_t outer = 0;
        for (uint32_t l = 0; l < rec.n_loops; ++l)
            if (v_->loops[rec.first_loop + l].flags & SW_SG_LOOP_OUTER)
                outer = l;
        const bool flip = loop_area(v_->loops[rec.first_loop + outer]) < 0.0;
        for (uint32_t l = 0; l < rec.n_loops; ++l)
            bb_.Add(face,
                    make_wire(v_->loops[rec.first_loop + l], bs, face, flat ? affine : 0, flip));
    }
    if (rec.flags & SW_SG_FACE_REVERSED)
        face.Orientation(TopAbs_REVERSED);
    ++faces_made;
    return face;
}

const TopoDS_Face &exporter::face(uint32_t f)
{
    if (faces_[f].IsNull())
        faces_[f] = make_face(f);
    return faces_[f];
}

TopoDS_Shape exporter::children(uint32_t n, uint64_t &occ)
{
    TopoDS_Compound c;
    bb_.MakeCompound(c);
    for (uint32_t k = v_->nodes[n].first_child; k != SW_SG_NONE; k = v_->nodes[k].next_sibling) {
        TopoDS_Shape s = shape(k, occ);
        if (!s.IsNull())
            bb_.Add(c, s);
    }
    return c;
}

/* The shape of node n in its parent's frame; occ += the face occurrences it draws. */
TopoDS_Shape exporter::shape(uint32_t n, uint64_t &occ)
{
    const sw_sg_node_rec &nd = v_->nodes[n];
    TopoDS_Shape s;
    switch (nd.kind) {
    case SW_SG_NODE_SURFACE:
        s = face(nd.ref);
        occ += 1;
        break;
    case SW_SG_NODE_INSTANCE: {
        auto p = protos_.find(nd.ref);
        if (p == protos_.end()) {
            uint64_t po = 0;
            TopoDS_Shape ps = shape(nd.ref, po); /* located by the prototype's own transform */
            p = protos_.emplace(nd.ref, ps).first;
            proto_occ_[nd.ref] = po;
        }
        s = p->second;
        occ += proto_occ_[nd.ref];
        break;
    }
    default:
        s = children(n, occ);
        break;
    }
    if (nd.kind != SW_SG_NODE_GROUP && !is_identity(nd.xform))
        s = s.Moved(location_of(nd.xform));
    return s;
}

TopoDS_Shape exporter::node_shape(uint32_t n)
{
    return shape(n, occurrences);
}

} // namespace

extern "C" sw_result sw_sg_export_brep_text(const sw_sg_scene *scene, char **text, size_t *len,
                                            sw_sg_export_report *report, sw_status *status)
{
    *text = NULL;
    *len = 0;
    if (!scene)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "export: no scene");
    const char *path = "BREP export";
    try {
        exporter ex(scene);
        TopoDS_Shape all = ex.node_shape(sw_sg_scene_view_ptr(scene)->root);
        std::ostringstream os;
        BRepTools::Write(all, os);
        if (!os.good())
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: the BREP text could not be built",
                            path);
        const std::string s = os.str();
        char *t = static_cast<char *>(sw__malloc(s.size() + 1));
        if (!t)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", path,
                            s.size());
        std::memcpy(t, s.data(), s.size() + 1);
        *text = t;
        *len = s.size();
        if (report)
            *report = {ex.faces_made, ex.occurrences};
        sw__status_ok(status);
        return SW_OK;
    } catch (const export_error &e) {
        return sw__fail(status, e.r, "%s: %s", path, e.why.c_str());
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory while exporting", path);
    } catch (const Standard_Failure &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "%s: OCCT failed: %s: %s", path,
                        e.DynamicType()->Name(), e.GetMessageString());
    } catch (...) {
        return sw__fail(status, SW_ERR_INTERNAL, "%s: unknown exception while exporting", path);
    }
}

extern "C" sw_result sw_sg_export_brep(const sw_sg_scene *scene, const char *path,
                                       sw_sg_export_report *report, sw_status *status)
{
    if (!scene || !path)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "export: no scene or no path");
    char *text;
    size_t len;
    sw_result r = sw_sg_export_brep_text(scene, &text, &len, report, status);
    if (r == SW_OK)
        r = sw__write_file(path, text, len, 0, status);
    sw__free(text);
    return r;
}

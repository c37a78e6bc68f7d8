/* SPDX-License-Identifier: MIT */
/* The OCCT importer's face conversion (import_occt_face.hpp): a face's surface through
 * BRepBuilderAPI_NurbsConvert to a non-periodic B-spline, its wires' pcurves to 2D rational
 * B-spline trim loops shifted into the surface's domain and snapped closed (sw_sg_trim.h), as
 * Guthe et al. 2005 §4's parity-based trim textures require; then the scene's checks of the face
 * and the exact repairs. A C++ shim: face_error is the only exception it throws. */
#include "import_occt_face.hpp"
#include "sw_sg_trim.h"
#include "sw_status_util.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GeomConvert.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESGeom_BoundedSurface.hxx>
#include <IGESGeom_TrimmedSurface.hxx>
#include <IGESSolid_Face.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <NCollection_DataMap.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <StepGeom_Surface.hxx>
#include <StepShape_Face.hxx>
#include <StepShape_FaceSurface.hxx>
#include <TCollection_HAsciiString.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelMapHasher.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ShapeMapHasher.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <algorithm>
#include <cctype>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <new>
#include <set>
#include <string>
#include <sys/stat.h>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace sw_occt
{

uint32_t kind_of(GeomAbs_SurfaceType t)
{
    switch (t) {
    case GeomAbs_Plane:
        return SW_SG_KIND_PLANE;
    case GeomAbs_Cylinder:
        return SW_SG_KIND_CYLINDER;
    case GeomAbs_Cone:
        return SW_SG_KIND_CONE;
    case GeomAbs_Sphere:
        return SW_SG_KIND_SPHERE;
    case GeomAbs_Torus:
        return SW_SG_KIND_TORUS;
    case GeomAbs_BezierSurface:
        return SW_SG_KIND_BEZIER;
    case GeomAbs_BSplineSurface:
        return SW_SG_KIND_BSPLINE;
    case GeomAbs_SurfaceOfRevolution:
        return SW_SG_KIND_REVOLUTION;
    case GeomAbs_SurfaceOfExtrusion:
        return SW_SG_KIND_EXTRUSION;
    case GeomAbs_OffsetSurface:
        return SW_SG_KIND_OFFSET;
    default:
        return SW_SG_KIND_OTHER;
    }
}

/* ---- face conversion ------------------------------------------------------------------------ */

Handle(Geom_BSplineSurface) nurbs_surface(const TopoDS_Face &cf, double period[2])
{
    Handle(Geom_Surface) s = BRep_Tool::Surface(cf);
    if (s.IsNull())
        throw face_error{"no surface"};
    Handle(Geom_BSplineSurface) bs = Handle(Geom_BSplineSurface)::DownCast(s);
    bs = bs.IsNull() ? GeomConvert::SurfaceToBSplineSurface(s)
                     : Handle(Geom_BSplineSurface)::DownCast(bs->Copy());
    if (bs.IsNull())
        throw face_error{"surface is not convertible to a B-spline"};
    period[0] = bs->IsUPeriodic() ? bs->UPeriod() : 0.0;
    period[1] = bs->IsVPeriodic() ? bs->VPeriod() : 0.0;
    if (bs->IsUPeriodic())
        bs->SetUNotPeriodic();
    if (bs->IsVPeriodic())
        bs->SetVNotPeriodic();
    return bs;
}

void surface_arrays(const Handle(Geom_BSplineSurface) & s, face_data &fd)
{
    const int nu = s->NbUPoles(), nv = s->NbVPoles(), du = s->UDegree(), dv = s->VDegree();
    if (du > SW_SG_MAX_DEGREE || dv > SW_SG_MAX_DEGREE)
        throw face_error{"surface degree above " + std::to_string(SW_SG_MAX_DEGREE),
                         SW_ERR_UNSUPPORTED};
    TColStd_Array1OfReal ku(1, nu + du + 1), kv(1, nv + dv + 1);
    s->UKnotSequence(ku);
    s->VKnotSequence(kv);
    fd.knots_u.assign(ku.begin(), ku.end());
    fd.knots_v.assign(kv.begin(), kv.end());
    fd.cpw.resize((size_t)nu * nv * 4);
    double *p = fd.cpw.data();
    for (int j = 1; j <= nv; j++) /* OCCT's Pole(i, j): i along U, so U runs fastest here */
        for (int i = 1; i <= nu; i++, p += 4) {
            const gp_Pnt &q = s->Pole(i, j);
            const double w = s->Weight(i, j);
            p[0] = w * q.X(), p[1] = w * q.Y(), p[2] = w * q.Z(), p[3] = w;
        }
    fd.rec.deg_u = (uint32_t)du, fd.rec.deg_v = (uint32_t)dv;
    fd.rec.n_u = (uint32_t)nu, fd.rec.n_v = (uint32_t)nv;
}

/* The edge's pcurve over its range, in the direction the wire runs along it. */
curve_data pcurve(const TopoDS_Edge &e, const TopoDS_Face &cf)
{
    double f = 0.0, l = 0.0;
    Handle(Geom2d_Curve) c = BRep_Tool::CurveOnSurface(e, cf, f, l);
    if (c.IsNull())
        throw face_error{"an edge has no pcurve"};
    Handle(Geom2d_BSplineCurve) bs =
        Geom2dConvert::CurveToBSplineCurve(new Geom2d_TrimmedCurve(c, f, l));
    if (bs.IsNull())
        throw face_error{"a pcurve is not convertible to a B-spline"};
    if (bs->IsPeriodic())
        bs->SetNotPeriodic();
    if (e.Orientation() == TopAbs_REVERSED)
        bs->Reverse();
    if (bs->Degree() > SW_SG_MAX_DEGREE)
        throw face_error{"pcurve degree above " + std::to_string(SW_SG_MAX_DEGREE),
                         SW_ERR_UNSUPPORTED};
    curve_data cd;
    cd.degree = bs->Degree();
    const int n = bs->NbPoles();
    TColStd_Array1OfReal k(1, n + cd.degree + 1);
    bs->KnotSequence(k);
    cd.knots.assign(k.begin(), k.end());
    cd.cpw.resize((size_t)n * 3);
    for (int i = 1; i <= n; i++) {
        const gp_Pnt2d &q = bs->Pole(i);
        const double w = bs->Weight(i);
        cd.cpw[(i - 1) * 3] = w * q.X(), cd.cpw[(i - 1) * 3 + 1] = w * q.Y();
        cd.cpw[(i - 1) * 3 + 2] = w;
    }
    return cd;
}

struct uv_domain {
    double u0, u1, v0, v1;
    double diag() const
    {
        return std::hypot(u1 - u0, v1 - v0);
    }
};

/* Euclidean bounding box of a loop's control points: u0, u1, v0, v1. */
void loop_box(const loop_data &ld, double box[4])
{
    box[0] = box[2] = HUGE_VAL, box[1] = box[3] = -HUGE_VAL;
    for (const curve_data &c : ld.curves)
        for (size_t i = 0; i < c.cpw.size(); i += 3) {
            double u = c.cpw[i] / c.cpw[i + 2], v = c.cpw[i + 1] / c.cpw[i + 2];
            box[0] = std::min(box[0], u), box[1] = std::max(box[1], u);
            box[2] = std::min(box[2], v), box[3] = std::max(box[3], v);
        }
}

/* Pcurves of a periodic surface may lie whole periods away from the non-periodic domain. */
void shift_into_domain(loop_data &ld, const uv_domain &d, const double period[2])
{
    double box[4];
    loop_box(ld, box);
    double shift[2] = {0.0, 0.0};
    const double lo[2] = {d.u0, d.v0}, hi[2] = {d.u1, d.v1};
    for (int a = 0; a < 2; a++) {
        double centre = 0.5 * (box[2 * a] + box[2 * a + 1]);
        if (period[a] > 0.0 && (centre < lo[a] || centre > hi[a]))
            shift[a] = -std::floor((centre - lo[a]) / period[a]) * period[a];
    }
    if (shift[0] == 0.0 && shift[1] == 0.0)
        return;
    for (curve_data &c : ld.curves)
        for (size_t i = 0; i < c.cpw.size(); i += 3)
            c.cpw[i] += shift[0] * c.cpw[i + 2], c.cpw[i + 1] += shift[1] * c.cpw[i + 2];
}

/* How far apart in (u, v) two points within 3D distance `tol3` of each other can be near (u, v):
 * tol3 over the smallest singular value of the Jacobian [Su Sv]. */
double uv_reach(const Handle(Geom_BSplineSurface) & s, const uv_domain &d, double u, double v,
                double tol3)
{
    u = std::clamp(u, d.u0, d.u1), v = std::clamp(v, d.v0, d.v1);
    gp_Pnt p;
    gp_Vec su, sv;
    s->D1(u, v, p, su, sv);
    const double e = su.Dot(su), f = su.Dot(sv), g = sv.Dot(sv);
    const double lmin = 0.5 * (e + g - std::sqrt((e - g) * (e - g) + 4.0 * f * f));
    const double smin = std::sqrt(std::max(lmin, 0.0));
    return smin > tol3 / d.diag() ? tol3 / smin : d.diag();
}

/* Snaps a loop closed. The allowed gap is generous: OCCT's loops have gaps up to the edge and
 * vertex tolerances, which map to large parameter distances where the surface is nearly
 * degenerate, so the largest mapping over the loop's joins is used. */
void snap_loop(loop_data &ld, const Handle(Geom_BSplineSurface) & s, const uv_domain &d,
               double tol3, const std::string &what)
{
    const size_t n = ld.curves.size();
    double max_gap = 1e-9 * d.diag();
    std::vector<double *> cpw(n);
    std::vector<int32_t> np(n);
    for (size_t k = 0; k < n; k++) {
        curve_data &c = ld.curves[k];
        cpw[k] = c.cpw.data();
        np[k] = (int32_t)(c.cpw.size() / 3);
        const double *end = c.cpw.data() + c.cpw.size() - 3;
        max_gap = std::max(max_gap, 4.0 * uv_reach(s, d, end[0] / end[2], end[1] / end[2], tol3));
    }
    sw_status st{};
    if (sw_sg_trim_snap_loop((int32_t)n, cpw.data(), np.data(), max_gap, what.c_str(), &st) !=
        SW_OK)
        throw face_error{st.message};
}

/* A loop of curves each lying on one side of its own parameter box: an axis-aligned rectangle,
 * the domain's or a part of it. Such a trim needs no texture (Guthe §4.4): restricting the patches
 * to the box — which the renderer does for every face — is the whole trim. */
bool is_axis_rectangle(const loop_data &ld, const uv_domain &d)
{
    const double eps = 1e-9 * d.diag();
    double box[4];
    loop_box(ld, box);
    if (!(box[1] - box[0] > eps) || !(box[3] - box[2] > eps))
        return false;
    for (const curve_data &c : ld.curves) {
        bool side[4] = {true, true, true, true};
        for (size_t i = 0; i < c.cpw.size(); i += 3) {
            double u = c.cpw[i] / c.cpw[i + 2], v = c.cpw[i + 1] / c.cpw[i + 2];
            side[0] &= std::fabs(u - box[0]) <= eps, side[1] &= std::fabs(u - box[1]) <= eps;
            side[2] &= std::fabs(v - box[2]) <= eps, side[3] &= std::fabs(v - box[3]) <= eps;
        }
        if (!(side[0] || side[1] || side[2] || side[3]))
            return false;
    }
    return true;
}

curve_data line_curve(double u0, double v0, double u1, double v1)
{
    curve_data c;
    c.degree = 1;
    c.knots = {0.0, 0.0, 1.0, 1.0};
    c.cpw = {u0, v0, 1.0, u1, v1, 1.0};
    return c;
}

/* The face's loops: each wire's edges in the order BRepTools_WireExplorer walks them on the
 * source face `f`, each edge's pcurve read from the converted face `cf` (nc's result). The walk
 * is taken on the source face because the conversion re-approximates pcurves and edge
 * tolerances: on a part scaled by 10^4 (a unit conversion) the explorer then stopped after the
 * first of a wire's four edges, and the one-curve loop, snapped closed, cut triangular holes in
 * the face. A wire the explorer cannot walk whole is refused (the face is skipped and named)
 * rather than drawn with a loop that misses edges. */
void wire_loops(const TopoDS_Face &f, const TopoDS_Face &cf, BRepBuilderAPI_NurbsConvert &nc,
                face_data &fd)
{
    const TopoDS_Wire outer = BRepTools::OuterWire(f);
    int index = 0;
    for (TopoDS_Iterator it(f); it.More(); it.Next()) {
        if (it.Value().ShapeType() != TopAbs_WIRE)
            continue;
        const TopoDS_Wire &w = TopoDS::Wire(it.Value());
        loop_data ld;
        ld.flags = w.IsSame(outer) ? (uint32_t)SW_SG_LOOP_OUTER : 0u;
        int walked = 0, edges = 0;
        for (BRepTools_WireExplorer ex(w, f); ex.More(); ex.Next(), walked++) {
            TopoDS_Shape converted = nc.ModifiedShape(ex.Current());
            if (converted.IsNull() || converted.ShapeType() != TopAbs_EDGE)
                throw face_error{"BRepBuilderAPI_NurbsConvert gave no edge for an edge of wire " +
                                 std::to_string(index)};
            converted.Orientation(ex.Current().Orientation());
            ld.curves.push_back(pcurve(TopoDS::Edge(converted), cf));
        }
        for (TopExp_Explorer ex(w, TopAbs_EDGE); ex.More(); ex.Next())
            edges++;
        if (walked < edges)
            throw face_error{"wire " + std::to_string(index) + ": its edges do not join (" +
                             std::to_string(walked) + " of " + std::to_string(edges) + " walked)"};
        if (!ld.curves.empty())
            fd.loops.push_back(std::move(ld));
        index++;
    }
}

double max_tolerance(const TopoDS_Face &f, TopAbs_ShapeEnum type)
{
    double t = 0.0;
    for (TopExp_Explorer ex(f, type); ex.More(); ex.Next())
        t = std::max(t, type == TopAbs_EDGE ? BRep_Tool::Tolerance(TopoDS::Edge(ex.Current()))
                                            : BRep_Tool::Tolerance(TopoDS::Vertex(ex.Current())));
    return t;
}

/* A B-spline surface whose poles or weights no exact repair can bring into the scene's range
 * (sw_sg_geom.h: a coordinate beyond SW_SG_COORD_MAX, a weight <= 0 or not finite, or two weights
 * more than SW_SG_WEIGHT_RATIO_MAX apart) is refused before BRepBuilderAPI_NurbsConvert sees it:
 * OCCT re-projects the face's pcurves onto such a surface for seconds to minutes (Ball.brep with
 * one weight 1e-20: 5 minutes; with one coordinate 1e31: 11 s), then the face is refused anyway. */
void check_poles(const Handle(Geom_BSplineSurface) & s, const std::string &what)
{
    if (s.IsNull())
        return;
    for (int j = 1; j <= s->NbVPoles(); j++)
        for (int i = 1; i <= s->NbUPoles(); i++) {
            const gp_Pnt &p = s->Pole(i, j);
            const double c[3] = {p.X(), p.Y(), p.Z()};
            for (int k = 0; k < 3; k++)
                if (!(std::fabs(c[k]) <= SW_SG_COORD_MAX)) {
                    char buf[160];
                    std::snprintf(buf, sizeof buf,
                                  ": control point (%d, %d) coordinate %d is %g, beyond %g", i - 1,
                                  j - 1, k, c[k], SW_SG_COORD_MAX);
                    throw face_error{what + buf};
                }
        }
    if (!s->IsURational() && !s->IsVRational())
        return;
    double lo = HUGE_VAL, hi = 0.0;
    int lo_at[2] = {0, 0}, hi_at[2] = {0, 0};
    for (int j = 1; j <= s->NbVPoles(); j++)
        for (int i = 1; i <= s->NbUPoles(); i++) {
            const double w = s->Weight(i, j);
            char buf[160];
            if (!(w > 0.0) || !std::isfinite(w)) {
                std::snprintf(buf, sizeof buf, ": weight of control point (%d, %d) is %g", i - 1,
                              j - 1, w);
                throw face_error{what + buf};
            }
            if (w < lo)
                lo = w, lo_at[0] = i - 1, lo_at[1] = j - 1;
            if (w > hi)
                hi = w, hi_at[0] = i - 1, hi_at[1] = j - 1;
        }
    if (hi > lo * SW_SG_WEIGHT_RATIO_MAX) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      ": weights %g (control point (%d, %d)) and %g (control point (%d, %d)) "
                      "differ by a factor %g > %g",
                      lo, lo_at[0], lo_at[1], hi, hi_at[0], hi_at[1], hi / lo,
                      SW_SG_WEIGHT_RATIO_MAX);
        throw face_error{what + buf};
    }
}

/* The fewest poles OCCT's knot arrays can serve: degree + 1 on an open knot vector; on a periodic
 * one, the period's flat knots (as many as its poles) must hold the degree + 1 - m knots that
 * BSplCLib::KnotSequence copies from the neighbouring period on each side (m: the first knot's
 * multiplicity). So 6 poles of degree 6 with a first knot of multiplicity 6 are a valid closed
 * net (a face of OCCT's MODERN_Sink_1 holds one), 2 poles of degree 5 are not. */
int poles_needed(int degree, bool periodic, int first_mult)
{
    return periodic ? degree + 1 - first_mult : degree + 1;
}

/* Too few poles for the degree, or knots beyond the scene's range (SW_SG_COORD_MAX) or not
 * finite: OCCT's B-spline constructors compare neighbouring knots only, so a NaN passes them, and
 * its span search then never ends. */
void check_knots(const Handle(Geom_BSplineSurface) & s, const std::string &what)
{
    if (s.IsNull())
        return;
    /* OCCT's constructor takes a periodic net with fewer poles than its degree needs (2 poles of
     * degree 5); its iso curves then read past their knot arrays (seen in BSplCLib::KnotSequence
     * under BRepTools::UVBounds) */
    for (int dir = 0; dir < 2; dir++) {
        const int poles = dir ? s->NbVPoles() : s->NbUPoles();
        const int degree = dir ? s->VDegree() : s->UDegree();
        const bool periodic = dir ? s->IsVPeriodic() : s->IsUPeriodic();
        const int first_mult = dir ? s->VMultiplicity(1) : s->UMultiplicity(1);
        if (poles < poles_needed(degree, periodic, first_mult)) {
            char buf[160];
            std::snprintf(buf, sizeof buf, ": %d control points in %c for degree %d", poles,
                          dir ? 'v' : 'u', degree);
            throw face_error{what + buf};
        }
    }
    for (int dir = 0; dir < 2; dir++)
        for (int i = 1, n = dir ? s->NbVKnots() : s->NbUKnots(); i <= n; i++) {
            const double k = dir ? s->VKnot(i) : s->UKnot(i);
            if (!(std::fabs(k) <= SW_SG_COORD_MAX)) {
                char buf[160];
                std::snprintf(buf, sizeof buf, ": %c knot %d is %g, beyond %g", dir ? 'v' : 'u',
                              i - 1, k, SW_SG_COORD_MAX);
                throw face_error{what + buf};
            }
        }
}

/* One point of the face's source geometry: finite and inside the scene's range, else the face is
 * refused before BRepBuilderAPI_NurbsConvert projects its pcurves onto it (a cone with a NaN
 * angle kept OCCT's projection in an endless SVD). */
void check_point(const double *c, int n, const char *of, const std::string &what)
{
    for (int k = 0; k < n; k++)
        if (!(std::fabs(c[k]) <= SW_SG_COORD_MAX)) {
            char buf[200];
            std::snprintf(buf, sizeof buf, ": %s has a coordinate %g, beyond %g", of, c[k],
                          SW_SG_COORD_MAX);
            throw face_error{what + buf};
        }
}

/* A 2D or 3D point's coordinates into c; returns how many. */
int coords(const gp_Pnt2d &p, double *c)
{
    c[0] = p.X(), c[1] = p.Y();
    return 2;
}

int coords(const gp_Pnt &p, double *c)
{
    c[0] = p.X(), c[1] = p.Y(), c[2] = p.Z();
    return 3;
}

/* A spline curve's knots, poles and weights finite and inside the scene's range, read without
 * evaluating it (OCCT's span search never ends on a NaN knot); a trimmed curve is checked through
 * its basis. Other curves have no such data. */
template <typename Spline, typename Trimmed, typename Curve>
void check_spline_curve(const Handle(Curve) & c, const char *of, const std::string &what)
{
    Handle(Curve) basis = c;
    while (Handle(Trimmed) t = Handle(Trimmed)::DownCast(basis))
        basis = t->BasisCurve();
    const Handle(Spline) bs = Handle(Spline)::DownCast(basis);
    if (bs.IsNull())
        return;
    if (bs->NbPoles() < poles_needed(bs->Degree(), bs->IsPeriodic(), bs->Multiplicity(1)))
        throw face_error{what + ": " + of + " has fewer control points than its degree needs"};
    for (int i = 1; i <= bs->NbKnots(); i++) {
        const double k = bs->Knot(i);
        check_point(&k, 1, of, what);
    }
    for (int i = 1; i <= bs->NbPoles(); i++) {
        double xyw[4];
        const int n = coords(bs->Pole(i), xyw);
        xyw[n] = bs->Weight(i);
        check_point(xyw, n + 1, of, what);
    }
}

/* The converted face's pcurves, before anything evaluates them (BRepTools_WireExplorer does):
 * the conversion's projection can leave NaN in them. */
void check_converted(const TopoDS_Face &cf, const std::string &what)
{
    for (TopExp_Explorer ex(cf, TopAbs_EDGE); ex.More(); ex.Next()) {
        double t[2];
        const Handle(Geom2d_Curve) pc =
            BRep_Tool::CurveOnSurface(TopoDS::Edge(ex.Current()), cf, t[0], t[1]);
        if (pc.IsNull())
            continue;
        check_point(t, 2, "an edge's converted pcurve range", what);
        check_spline_curve<Geom2d_BSplineCurve, Geom2d_TrimmedCurve>(
            pc, "an edge's converted pcurve", what);
    }
}

/* The face's parameter box inside its surface's own domain in each direction that is not
 * periodic, up to 5 % of the domain's span (pcurves of real files overshoot a little; the
 * conversion snaps them): a sphere face whose v range lies beyond the poles kept OCCT's pcurve
 * projection busy without end. Unbounded directions (planes) pass. */
void check_in_domain(const double b[4], const Handle(Geom_Surface) & s, const std::string &what)
{
    double d[4];
    s->Bounds(d[0], d[1], d[2], d[3]);
    const bool periodic[2] = {s->IsUPeriodic() == Standard_True, s->IsVPeriodic() == Standard_True};
    for (int dir = 0; dir < 2; dir++) {
        const double lo = d[2 * dir], hi = d[2 * dir + 1], slack = 0.05 * (hi - lo);
        if (periodic[dir] || !(b[2 * dir] < lo - slack || b[2 * dir + 1] > hi + slack))
            continue;
        char buf[200];
        std::snprintf(buf, sizeof buf, ": its %c range [%g, %g] lies beyond its surface's [%g, %g]",
                      dir ? 'v' : 'u', b[2 * dir], b[2 * dir + 1], lo, hi);
        throw face_error{what + buf};
    }
}

/* The face's parameter bounds, its surface on a 3 x 3 grid over them, and each edge's 3D curve
 * and pcurve at both ends and the middle, checked with check_point: elementary and swept surfaces
 * have no poles for check_poles to read, and their parameters (a radius, an angle, an axis) reach
 * the conversion only through these values. */
/* One sampled point through check_point; a point where the geometry is undefined (an offset
 * surface's singular point) throws: that sample is left out, not the face. */
template <typename Eval> void check_sample(Eval point_at, const char *of, const std::string &what)
{
    double c[3];
    int n;
    try {
        n = coords(point_at(), c);
    } catch (const Standard_Failure &) {
        return;
    }
    check_point(c, n, of, what);
}

/* An edge's curve (2D pcurve or 3D curve) over [t0, t1]: its range, its spline data, then its
 * points at both ends and the middle. */
template <typename Spline, typename Trimmed, typename Curve>
void check_edge_curve(const Handle(Curve) & c, const double t[2], const char *of,
                      const std::string &what)
{
    check_point(t, 2, of, what);
    check_spline_curve<Spline, Trimmed>(c, of, what);
    for (int i = 0; i <= 2; i++)
        check_sample([&] { return c->Value(t[0] + (t[1] - t[0]) * i / 2); }, of, what);
}

void check_values(const TopoDS_Face &f, const Handle(Geom_Surface) & s, const std::string &what)
{
    double b[4];
    BRepTools::UVBounds(f, b[0], b[1], b[2], b[3]);
    check_point(b, 4, "the face's parameter box", what);
    check_in_domain(b, s, what);
    for (int i = 0; i <= 2; i++)
        for (int j = 0; j <= 2; j++)
            check_sample(
                [&] {
                    return s->Value(b[0] + (b[1] - b[0]) * i / 2, b[2] + (b[3] - b[2]) * j / 2);
                },
                "its surface", what);
    for (TopExp_Explorer ex(f, TopAbs_EDGE); ex.More(); ex.Next()) {
        const TopoDS_Edge &e = TopoDS::Edge(ex.Current());
        double t[2];
        if (Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(e, f, t[0], t[1]); !pc.IsNull())
            check_edge_curve<Geom2d_BSplineCurve, Geom2d_TrimmedCurve>(pc, t, "an edge's pcurve",
                                                                       what);
        if (Handle(Geom_Curve) c3 = BRep_Tool::Curve(e, t[0], t[1]); !c3.IsNull())
            check_edge_curve<Geom_BSplineCurve, Geom_TrimmedCurve>(c3, t, "an edge's curve", what);
    }
}

TopoDS_Face scaled_face(const TopoDS_Face &f, int scale_exp)
{
    if (scale_exp == 0)
        return f;
    gp_Trsf t;
    t.SetScale(gp_Pnt(0.0, 0.0, 0.0), std::ldexp(1.0, scale_exp));
    BRepBuilderAPI_Transform xf(f, t, Standard_True);
    if (!xf.IsDone() || xf.Shape().IsNull() || xf.Shape().ShapeType() != TopAbs_FACE)
        throw face_error{"the face could not be scaled for its conversion"};
    return TopoDS::Face(xf.Shape());
}

/* Converts one face; throws face_error or Standard_Failure when it cannot. */
face_data convert_face(const TopoDS_Face &f, TopoDS_Face &converted, const std::string &what,
                       int scale_exp)
{
    face_data fd;
    fd.rec.kind = kind_of(BRepAdaptor_Surface(f, Standard_False).GetType());
    fd.rec.flags = f.Orientation() == TopAbs_REVERSED ? (uint32_t)SW_SG_FACE_REVERSED : 0u;
    fd.rec.tolerance = max_tolerance(f, TopAbs_EDGE);

    /* OCCT's readers leave a face without its surface when the file's surface could not be
     * built (a BREP weight of 0: Standard_ConstructionError, caught by the reader); the NURBS
     * conversion would dereference it. */
    const Handle(Geom_Surface) raw = BRep_Tool::Surface(f);
    if (raw.IsNull())
        throw face_error{"the file's surface of this face could not be built by OCCT (invalid "
                         "surface data)"};
    check_knots(Handle(Geom_BSplineSurface)::DownCast(raw), what);
    check_poles(Handle(Geom_BSplineSurface)::DownCast(raw), what);
    check_values(f, raw, what);

    /* converted at a size where OCCT's absolute tolerances are small (import_scale_exp) */
    const TopoDS_Face work = scaled_face(f, scale_exp);
    BRepBuilderAPI_NurbsConvert nc(work);
    if (!nc.IsDone())
        throw face_error{"BRepBuilderAPI_NurbsConvert failed"};
    TopoDS_Shape cs = nc.ModifiedShape(work);
    if (cs.IsNull() || cs.ShapeType() != TopAbs_FACE)
        throw face_error{"BRepBuilderAPI_NurbsConvert gave no face"};
    converted = TopoDS::Face(cs);

    double period[2];
    Handle(Geom_BSplineSurface) s = nurbs_surface(converted, period);
    surface_arrays(s, fd);
    uv_domain d{fd.knots_u[fd.rec.deg_u], fd.knots_u[fd.rec.n_u], fd.knots_v[fd.rec.deg_v],
                fd.knots_v[fd.rec.n_v]};

    check_converted(converted, what);
    wire_loops(work, converted, nc, fd);
    const double tol3 =
        std::max(std::ldexp(fd.rec.tolerance, scale_exp), max_tolerance(converted, TopAbs_VERTEX));
    for (loop_data &ld : fd.loops) {
        shift_into_domain(ld, d, period);
        snap_loop(ld, s, d, tol3, what);
    }
    /* back to the file's size: a power of two, each pole exactly */
    for (size_t i = 0; scale_exp != 0 && i < fd.cpw.size(); i += 4)
        for (int c = 0; c < 3; c++)
            fd.cpw[i + c] = std::ldexp(fd.cpw[i + c], -scale_exp);
    if (fd.loops.empty()) { /* a face without wires is bounded by its surface's domain */
        loop_data ld;
        ld.flags = SW_SG_LOOP_OUTER;
        ld.curves = {line_curve(d.u0, d.v0, d.u1, d.v0), line_curve(d.u1, d.v0, d.u1, d.v1),
                     line_curve(d.u1, d.v1, d.u0, d.v1), line_curve(d.u0, d.v1, d.u0, d.v0)};
        fd.loops.push_back(std::move(ld));
    }
    const bool untrimmed = fd.loops.size() == 1 && is_axis_rectangle(fd.loops[0], d);
    if (!untrimmed)
        fd.rec.flags |= SW_SG_FACE_TRIMMED;

    double box[4] = {HUGE_VAL, -HUGE_VAL, HUGE_VAL, -HUGE_VAL};
    for (const loop_data &ld : fd.loops) {
        double lb[4];
        loop_box(ld, lb);
        box[0] = std::min(box[0], lb[0]), box[1] = std::max(box[1], lb[1]);
        box[2] = std::min(box[2], lb[2]), box[3] = std::max(box[3], lb[3]);
    }
    fd.rec.uv_box[0] = std::clamp(box[0], d.u0, d.u1),
    fd.rec.uv_box[1] = std::clamp(box[1], d.u0, d.u1);
    fd.rec.uv_box[2] = std::clamp(box[2], d.v0, d.v1),
    fd.rec.uv_box[3] = std::clamp(box[3], d.v0, d.v1);
    return fd;
}

int import_scale_exp(const TopoDS_Shape &shape)
{
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double largest = 0.0;
    for (TopExp_Explorer ex(shape, TopAbs_VERTEX); ex.More(); ex.Next()) {
        const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(ex.Current()));
        const double c[3] = {p.X(), p.Y(), p.Z()};
        for (int k = 0; k < 3; k++) {
            if (!std::isfinite(c[k]))
                return 0; /* the faces' own checks say what is wrong */
            lo[k] = std::min(lo[k], c[k]), hi[k] = std::max(hi[k], c[k]);
            largest = std::max(largest, std::fabs(c[k]));
        }
    }
    const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    if (!(diag > 0.0) || !(diag < 1.0))
        return 0;
    int e = 0;
    std::frexp(diag, &e); /* diag in [2^(e-1), 2^e) */
    int k = 7 - e;        /* diag 2^k in [64, 128) */
    while (k > 0 && std::ldexp(largest, k) > 1e15)
        k--;
    return k;
}

/* ---- the scene's checks, face by face ---------------------------------------------------------
 * The scene refuses invalid geometry as a whole (sw_sg_scene_validate, at sw_sg_builder_finish).
 * The same checks are made here on each converted face before it enters the builder, so that one
 * bad face is repaired or skipped, with its file, index and reason, instead of refusing the file
 * with a message about "scene: face N". */

sw_result validate_face(const face_data &fd, const std::string &what, sw_status *st)
{
    const sw_sg_surface s{(int32_t)fd.rec.deg_u, (int32_t)fd.rec.deg_v, (int32_t)fd.rec.n_u,
                          (int32_t)fd.rec.n_v,   fd.knots_u.data(),     fd.knots_v.data(),
                          fd.cpw.data()};
    sw_result r = sw_sg_surface_validate(&s, what.c_str(), st);
    for (size_t l = 0; r == SW_OK && l < fd.loops.size(); l++)
        for (size_t k = 0; r == SW_OK && k < fd.loops[l].curves.size(); k++) {
            const curve_data &cd = fd.loops[l].curves[k];
            const sw_sg_curve c{cd.degree, (int32_t)(cd.cpw.size() / 3), 3, cd.knots.data(),
                                cd.cpw.data()};
            const std::string cw =
                what + ": loop " + std::to_string(l) + " curve " + std::to_string(k);
            r = sw_sg_curve_validate(&c, cw.c_str(), st);
        }
    if (r == SW_OK && !(std::isfinite(fd.rec.tolerance) && fd.rec.tolerance >= 0.0 &&
                        std::isfinite(fd.rec.uv_box[0]) && std::isfinite(fd.rec.uv_box[1]) &&
                        std::isfinite(fd.rec.uv_box[2]) && std::isfinite(fd.rec.uv_box[3])))
        r = sw__fail(st, SW_ERR_INVALID_GEOMETRY, "%s: tolerance or parameter box not finite",
                     what.c_str());
    return r;
}

/* The exact repair there is for weights: when all of a net's weights are positive and finite and
 * within SW_SG_WEIGHT_RATIO_MAX of each other, but lie as a whole outside [SW_SG_WEIGHT_MIN,
 * SW_SG_WEIGHT_MAX], every homogeneous coordinate is multiplied by one power of two that brings
 * the largest weight into [0.5, 1): each point of the curve or surface stays where it was, bit
 * for bit (unless a value would underflow: then nothing is changed). A zero or negative weight has
 * no exact repair — a zero weight makes its point's term vanish from numerator and denominator
 * alike, so at a clamped corner the surface is 0/0 and its limit depends on the direction it is
 * approached from (along a collapsed edge and across it); any positive weight put there moves the
 * surface wherever that control point has influence — so such a face is skipped. Returns the
 * factor's exponent, or 0 when no repair was made. */
int rescale_weights(std::vector<double> &cpw, size_t dim)
{
    double lo = HUGE_VAL, hi = 0.0;
    for (size_t i = dim - 1; i < cpw.size(); i += dim) {
        const double w = cpw[i];
        if (!(w > 0.0) || !std::isfinite(w))
            return 0;
        lo = std::min(lo, w), hi = std::max(hi, w);
    }
    if (cpw.empty() || (lo >= SW_SG_WEIGHT_MIN && hi <= SW_SG_WEIGHT_MAX) ||
        hi > lo * SW_SG_WEIGHT_RATIO_MAX)
        return 0;
    int e = 0;
    std::frexp(hi, &e);
    for (double v : cpw) {
        const double x = std::ldexp(v, -e);
        if (v != 0.0 && (!std::isfinite(x) || std::fabs(x) < DBL_MIN))
            return 0;
    }
    for (double &v : cpw)
        v = std::ldexp(v, -e);
    return -e != 0 ? -e : 0;
}

/* Repairs what rescale_weights can in the face's surface and curves; says what it did in `done`.
 */
bool repair_face(face_data &fd, std::string &done)
{
    bool any = false;
    if (int e = rescale_weights(fd.cpw, 4)) {
        done += "surface weights scaled by 2^" + std::to_string(e);
        any = true;
    }
    for (size_t l = 0; l < fd.loops.size(); l++)
        for (size_t k = 0; k < fd.loops[l].curves.size(); k++)
            if (int e = rescale_weights(fd.loops[l].curves[k].cpw, 3)) {
                done += std::string(any ? "; " : "") + "loop " + std::to_string(l) + " curve " +
                        std::to_string(k) + " weights scaled by 2^" + std::to_string(e);
                any = true;
            }
    return any;
}

} // namespace sw_occt

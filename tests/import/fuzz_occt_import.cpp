// SPDX-License-Identifier: MIT
// libFuzzer harness for the OCCT importer's conversion layer (modules/import/import_occt.cpp,
// face_occt.cpp): the input is read as the parameters of OCCT shapes — B-spline, plane,
// cylinder, sphere, torus, cone, extrusion and revolution surfaces, their parameter bounds and
// an optional trimming wire of 2D lines, circles or B-splines — drawn from moderate
// values and from hostile ones (NaN, ±inf, ±1e308, 1e-300, zero and negative weights, repeated
// knots). The faces are assembled with BRep_Builder, as OCCT's BREP reader assembles a file's
// (no algorithm runs on them on the way) into a shell that a compound holds twice (once moved:
// the closed-shell vote and the prototype-and-instances walk of an assembly), and go through
// sw__occt_import_shape, then the scene
// builder. Offset surfaces are left out: OCCT's own face construction on a fuzzed offset spends
// seconds in exceptions thrown at its singular points before the importer sees the face. It must
// never crash, hang or leak, and what it accepts must be drawable:
// - every face read is either converted or skipped with a reason (converted + skipped = read);
// - the import either succeeds or fails with the reason a file would get (a format, geometry,
//   limit or memory error naming the input), never with an exception that escaped;
// - a finished scene's surfaces and trim curves evaluate to finite points inside the scene's
//   coordinate limit at every sampled parameter (a face admitted with a NaN pole, a zero weight
//   or a 1e308 coordinate would break this).
// Planted: the Standard_Failure catch of the importer's face_index removed, the committed corpus
// replayed: it fails (an exception escapes as SW_ERR_INTERNAL).
// SW_FUZZ_VERBOSE=1 prints each import's outcome and skipped faces; SW_FUZZ_WRITE_BREP=FILE
// writes the input's shape as a BREP file (to replay a finding through `splinewalk import`).
#include "sw_sg_geom.h"
#include "sw_sg_import_occt.hpp"
#include "sw_sg_scene.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Circle.hxx>
#include <Geom2d_Line.hxx>
#include <GeomAPI.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pln.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax2d.hxx>
#include <gp_Ax3.hxx>
#include <gp_Trsf.hxx>
#include <gp_Vec.hxx>
#include <gp_Vec2d.hxx>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace
{

/* The input as a stream of choices; past its end every choice is 0 (a moderate value). */
class reader
{
  public:
    reader(const uint8_t *p, size_t n) : p_(p), n_(n) {}
    uint8_t byte()
    {
        return at_ < n_ ? p_[at_++] : 0;
    }
    int pick(int lo, int hi)
    {
        return lo + byte() % (hi - lo + 1);
    }
    /* Mostly moderate values in [-10, 10], sometimes hostile ones, sometimes raw bits. Finite
     * magnitudes between 1e6 and the scene's limit 1e30 are left out: there OCCT's own pcurve
     * projection (BRepBuilderAPI_NurbsConvert) may take unbounded time on a face small beside
     * its distance from the origin (a radius-1 cylinder at z = 1e10: 27 s), which the harness
     * cannot tell from a hang in the importer (docs/reliability.md). Beyond 1e30 the importer
     * refuses the face before OCCT's algorithms run, and that stays in. */
    double value()
    {
        const double v = any_value();
        return std::fabs(v) > 1e6 && std::fabs(v) <= 1e30 ? std::copysign(1e31, v) : v;
    }
    double any_value()
    {
        static const double hostile[] = {std::numeric_limits<double>::quiet_NaN(),
                                         INFINITY,
                                         -INFINITY,
                                         1e308,
                                         -1e308,
                                         DBL_MAX,
                                         1e-300,
                                         -1e-300,
                                         0.0,
                                         -0.0,
                                         DBL_MIN,
                                         5e-324,
                                         1e31,
                                         -1e31,
                                         1e-15,
                                         1e-7};
        const uint8_t b = byte();
        if (b < 224)
            return (b - 112) / 8.0;
        if (b < 224 + 16)
            return hostile[b - 224];
        double raw = 0.0;
        for (size_t k = 0; k < sizeof raw; k++)
            reinterpret_cast<uint8_t *>(&raw)[k] = byte();
        return raw;
    }
    gp_Pnt point()
    {
        return gp_Pnt(value(), value(), value());
    }
    /* throws Standard_ConstructionError on a zero or NaN direction */
    gp_Dir dir()
    {
        return gp_Dir(value(), value(), value());
    }

  private:
    const uint8_t *p_;
    size_t n_, at_ = 0;
};

/* Knots: `distinct` values from a start by non-negative steps (zero steps, NaN and inf allowed
 * through value()), clamped multiplicities at the ends for a non-periodic spline. */
void knots_of(reader &r, int degree, int distinct, bool periodic, TColStd_Array1OfReal &k,
              TColStd_Array1OfInteger &m)
{
    double at = r.value();
    for (int i = 1; i <= distinct; i++) {
        k(i) = at;
        at += std::fabs(r.value()) + (r.byte() % 4 ? 1.0 : 0.0);
        m(i) = 1 + r.byte() % 2;
    }
    if (!periodic)
        m(1) = m(distinct) = degree + 1;
}

Handle(Geom_BSplineSurface) bspline_surface(reader &r)
{
    const int du = r.pick(1, 5), dv = r.pick(1, 5), iu = r.pick(0, 3), iv = r.pick(0, 3);
    const bool rational = r.byte() % 2, periodic = r.byte() % 8 == 0;
    TColStd_Array1OfReal ku(1, iu + 2), kv(1, iv + 2);
    TColStd_Array1OfInteger mu(1, iu + 2), mv(1, iv + 2);
    knots_of(r, du, iu + 2, periodic, ku, mu);
    knots_of(r, dv, iv + 2, false, kv, mv);
    int nu = 0, nv = 0;
    for (int i = 1; i <= iu + 2; i++)
        nu += mu(i);
    for (int i = 1; i <= iv + 2; i++)
        nv += mv(i);
    nu -= periodic ? mu(1) : du + 1;
    nv -= dv + 1;
    if (nu < 2 || nv < 2 || nu > 64 || nv > 64)
        return nullptr;
    TColgp_Array2OfPnt poles(1, nu, 1, nv);
    TColStd_Array2OfReal weights(1, nu, 1, nv);
    for (int j = 1; j <= nv; j++)
        for (int i = 1; i <= nu; i++) {
            poles(i, j) = gp_Pnt(i + 0.1 * r.value(), j + 0.1 * r.value(), r.value());
            weights(i, j) = rational ? r.value() : 1.0;
        }
    if (rational)
        return new Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, du, dv, periodic, false);
    return new Geom_BSplineSurface(poles, ku, kv, mu, mv, du, dv, periodic, false);
}

Handle(Geom_BSplineCurve) bspline_curve(reader &r)
{
    const int d = r.pick(1, 4), inner = r.pick(0, 3);
    TColStd_Array1OfReal k(1, inner + 2);
    TColStd_Array1OfInteger m(1, inner + 2);
    knots_of(r, d, inner + 2, false, k, m);
    int n = -(d + 1);
    for (int i = 1; i <= inner + 2; i++)
        n += m(i);
    if (n < 2 || n > 64)
        return nullptr;
    TColgp_Array1OfPnt poles(1, n);
    for (int i = 1; i <= n; i++)
        poles(i) = gp_Pnt(r.value(), i + 0.1 * r.value(), r.value());
    return new Geom_BSplineCurve(poles, k, m, d);
}

Handle(Geom_Surface) surface(reader &r)
{
    switch (r.byte() % 9) {
    case 0:
        return new Geom_Plane(gp_Ax3(r.point(), r.dir()));
    case 1:
        return new Geom_CylindricalSurface(gp_Ax3(r.point(), r.dir()), r.value());
    case 2:
        return new Geom_SphericalSurface(gp_Ax3(r.point(), r.dir()), r.value());
    case 3:
        return new Geom_ToroidalSurface(gp_Ax3(r.point(), r.dir()), r.value(), r.value());
    case 4:
        return new Geom_ConicalSurface(gp_Ax3(r.point(), r.dir()), r.value(), r.value());
    case 5: {
        Handle(Geom_BSplineCurve) c = bspline_curve(r);
        return c.IsNull() ? nullptr : new Geom_SurfaceOfLinearExtrusion(c, r.dir());
    }
    case 6: {
        Handle(Geom_BSplineCurve) c = bspline_curve(r);
        return c.IsNull() ? nullptr : new Geom_SurfaceOfRevolution(c, gp_Ax1(r.point(), r.dir()));
    }
    default:
        return bspline_surface(r);
    }
}

Handle(Geom2d_Curve) trim_curve(reader &r, double u0, double u1, double v0, double v1)
{
    const double cu = 0.5 * (u0 + u1), cv = 0.5 * (v0 + v1);
    switch (r.byte() % 3) {
    case 0:
        return new Geom2d_Circle(gp_Ax2d(gp_Pnt2d(cu + r.value(), cv + r.value()), gp_Dir2d(1, 0)),
                                 r.value());
    case 1: {
        const int n = r.pick(2, 6);
        TColgp_Array1OfPnt2d poles(1, n + 1);
        for (int i = 1; i <= n; i++)
            poles(i) = gp_Pnt2d(cu + r.value(), cv + r.value());
        poles(n + 1) = poles(1); /* closed */
        TColStd_Array1OfReal k(1, n);
        TColStd_Array1OfInteger m(1, n);
        for (int i = 1; i <= n; i++)
            k(i) = i, m(i) = 1;
        m(1) = m(n) = 2;
        return new Geom2d_BSplineCurve(poles, k, m, 1);
    }
    default:
        return new Geom2d_Line(gp_Pnt2d(cu + r.value(), cv + r.value()), gp_Dir2d(1, 0));
    }
}

/* The surface's exact 3D curve at a constant parameter (an iso line), or none where OCCT
 * cannot make it. */
Handle(Geom_Curve) iso(const Handle(Geom_Surface) & s, bool along_u, double at)
{
    try {
        return along_u ? s->VIso(at) : s->UIso(at);
    } catch (const Standard_Failure &) {
        return nullptr;
    }
}

/* A corner vertex at the surface's point (u, v), or the origin where it cannot be evaluated. */
TopoDS_Vertex vertex_at(const Handle(Geom_Surface) & s, double u, double v)
{
    gp_Pnt p;
    try {
        p = s->Value(u, v);
    } catch (const Standard_Failure &) {
    }
    BRep_Builder bb;
    TopoDS_Vertex vx;
    bb.MakeVertex(vx, p, 1e-7);
    return vx;
}

/* An edge of face f from vertex a to vertex b along the 2D curve c2 over [t0, t1], with the 3D
 * curve c3 over the same range when there is one, built as OCCT's BREP reader builds an edge
 * (BRep_Builder: no algorithm runs on it). */
TopoDS_Edge edge_on(const TopoDS_Face &f, const Handle(Geom2d_Curve) & c2,
                    const Handle(Geom_Curve) & c3, double t0, double t1, const TopoDS_Vertex &a,
                    const TopoDS_Vertex &b)
{
    BRep_Builder bb;
    TopoDS_Edge e;
    bb.MakeEdge(e);
    if (!c3.IsNull())
        bb.UpdateEdge(e, c3, 1e-7);
    bb.UpdateEdge(e, c2, f, 1e-7);
    bb.Range(e, t0, t1);
    bb.Add(e, a.Oriented(TopAbs_FORWARD));
    bb.Add(e, b.Oriented(TopAbs_REVERSED));
    bb.SameRange(e, Standard_True);
    bb.SameParameter(e, Standard_True);
    return e;
}

/* Boxes that only make OCCT's pcurve projection slow are kept out, so that the fuzzer's time goes
 * to the importer: less than a period in a periodic direction (two edges on the same seam, which
 * a file's face would share as one seam edge, and a torus face wound 14 rad around both ways),
 * and a cone face not across its apex. Each was a timeout of 60 s inside OCCT's
 * ProjLib_ComputeApproxOnPolarSurface. */
void tame_box(const Handle(Geom_Surface) & s, double &u0, double &u1, double &v0, double &v1)
{
    if (s->IsUPeriodic() && u1 - u0 > 0.75 * s->UPeriod())
        u1 = u0 + 0.75 * s->UPeriod();
    if (s->IsVPeriodic() && v1 - v0 > 0.75 * s->VPeriod())
        v1 = v0 + 0.75 * s->VPeriod();
    if (Handle(Geom_ConicalSurface) cone = Handle(Geom_ConicalSurface)::DownCast(s);
        !cone.IsNull() && std::sin(cone->SemiAngle()) != 0.0) {
        const double apex = -cone->RefRadius() / std::sin(cone->SemiAngle());
        if (v0 < apex && apex < v1)
            v0 = apex + 0.25 * (v1 - apex);
    }
}

/* A hole made of one closed 2D curve from the input (a 3D curve only on a plane, where it is
 * exact), added to f. */
void add_hole(reader &r, TopoDS_Face &f, const Handle(Geom_Surface) & s, double u0, double u1,
              double v0, double v1)
{
    BRep_Builder bb;
    Handle(Geom2d_Curve) c = trim_curve(r, u0, u1, v0, v1);
    double t0 = c->FirstParameter(), t1 = c->LastParameter();
    t0 = std::isfinite(t0) ? t0 : r.value(), t1 = std::isfinite(t1) ? t1 : r.value();
    Handle(Geom_Curve) c3;
    if (Handle(Geom_Plane) pl = Handle(Geom_Plane)::DownCast(s); !pl.IsNull())
        c3 = GeomAPI::To3d(c, pl->Pln());
    gp_Pnt2d q0, q1;
    try {
        q0 = c->Value(t0), q1 = c->Value(t1);
    } catch (const Standard_Failure &) {
    }
    TopoDS_Wire hole;
    bb.MakeWire(hole);
    bb.Add(hole,
           edge_on(f, c, c3, t0, t1, vertex_at(s, q0.X(), q0.Y()), vertex_at(s, q1.X(), q1.Y())));
    bb.Add(f, hole);
}

/* A face of the surface bounded by its parameter box from the input: four edges along iso lines
 * (the 2D lines parametrised by u or v, the surface's iso curves as 3D curves), sometimes with a
 * hole (add_hole); built with
 * BRep_Builder as a BREP file's face is, so that every hostile value reaches the importer
 * (OCCT's MakeFace evaluates, and crashes on some). */
TopoDS_Face face(reader &r)
{
    Handle(Geom_Surface) s = surface(r);
    if (s.IsNull())
        return TopoDS_Face();
    double u0 = r.value(), u1 = u0 + std::fabs(r.value()) + 0.5;
    double v0 = r.value(), v1 = v0 + std::fabs(r.value()) + 0.5;
    tame_box(s, u0, u1, v0, v1);
    BRep_Builder bb;
    TopoDS_Face f;
    bb.MakeFace(f, s, 1e-7);
    const TopoDS_Vertex c00 = vertex_at(s, u0, v0), c10 = vertex_at(s, u1, v0),
                        c11 = vertex_at(s, u1, v1), c01 = vertex_at(s, u0, v1);
    auto along_u = [&](double v) { return new Geom2d_Line(gp_Pnt2d(0.0, v), gp_Dir2d(1, 0)); };
    auto along_v = [&](double u) { return new Geom2d_Line(gp_Pnt2d(u, 0.0), gp_Dir2d(0, 1)); };
    TopoDS_Wire outer;
    bb.MakeWire(outer);
    bb.Add(outer, edge_on(f, along_u(v0), iso(s, true, v0), u0, u1, c00, c10));
    bb.Add(outer, edge_on(f, along_v(u1), iso(s, false, u1), v0, v1, c10, c11));
    bb.Add(outer, edge_on(f, along_u(v1), iso(s, true, v1), u0, u1, c01, c11).Reversed());
    bb.Add(outer, edge_on(f, along_v(u0), iso(s, false, u0), v0, v1, c00, c01).Reversed());
    bb.Add(f, outer);
    if (r.byte() % 3 == 0) {
        try {
            add_hole(r, f, s, u0, u1, v0, v1);
        } catch (const Standard_Failure &) {
            /* OCCT refused the hole's curve (a negative radius): the face stays without it */
        }
    }
    return f;
}

/* Finite and inside the coordinate limit (a rational B-spline with positive weights stays in its
 * control points' hull, which validation bounds by SW_SG_COORD_MAX). */
bool drawable(const double *p, int n)
{
    for (int k = 0; k < n; k++)
        if (!(std::fabs(p[k]) <= SW_SG_COORD_MAX * (1.0 + 1e-9)))
            return false;
    return true;
}

void check_scene(const sw_sg_scene *scene)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    for (uint32_t f = 0; f < v->n_faces; f++) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(scene, f, &s);
        const double a = s.knots_u[s.deg_u], b = s.knots_u[s.n_u];
        const double c = s.knots_v[s.deg_v], d = s.knots_v[s.n_v];
        for (int i = 0; i <= 3; i++)
            for (int j = 0; j <= 3; j++) {
                double p[3];
                sw_sg_surface_eval(&s, a + (b - a) * i / 3, c + (d - c) * j / 3, p);
                if (!drawable(p, 3))
                    abort();
            }
    }
    for (uint32_t k = 0; k < v->n_curves; k++) {
        sw_sg_curve cv;
        sw_sg_scene_curve(scene, k, &cv);
        const double a = cv.knots[cv.degree], b = cv.knots[cv.n];
        for (int i = 0; i <= 4; i++) {
            double p[3];
            sw_sg_curve_eval(&cv, a + (b - a) * i / 4, p);
            if (!drawable(p, cv.dim - 1))
                abort();
        }
    }
}

void import_and_check(const TopoDS_Shape &shape)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        abort();
    sw_sg_import_desc desc{};
    desc.path = "fuzz.brep";
    if (std::getenv("SW_FUZZ_VERBOSE"))
        desc.warning = [](void *, const char *m) { std::fprintf(stderr, "warning: %s\n", m); };
    sw_sg_import_report rep{};
    sw_status st{};
    const sw_result r = sw__occt_import_shape(b, shape, &desc, &rep, &st);
    if (std::getenv("SW_FUZZ_VERBOSE")) /* what the corpus reaches, for the figures */
        std::fprintf(stderr, "import: %s, faces read %u converted %u skipped %u repaired %u: %s\n",
                     sw_result_str(r), rep.faces_read, rep.faces_converted, rep.faces_failed,
                     rep.faces_repaired, st.message);
    if (rep.faces_converted + rep.faces_failed != rep.faces_read)
        abort();
    if (r != SW_OK) {
        /* what a file would get; SW_ERR_INTERNAL is an exception that escaped the importer */
        if (r == SW_ERR_INTERNAL || std::strncmp(st.message, "fuzz.brep", 9) != 0)
            abort();
        sw_sg_builder_free(b);
        return;
    }
    sw_sg_scene *scene = nullptr; /* finish frees the builder, whatever it returns */
    if (sw_sg_builder_finish(b, &scene, &st) == SW_OK)
        check_scene(scene);
    sw_sg_scene_free(scene);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r(data, size);
    BRep_Builder bb;
    TopoDS_Shell shell;
    bb.MakeShell(shell);
    const int faces = r.pick(1, 4);
    for (int i = 0; i < faces; i++) {
        try {
            TopoDS_Face f = face(r);
            if (!f.IsNull())
                bb.Add(shell, f);
        } catch (const Standard_Failure &e) {
            /* OCCT refused the parameters (a zero direction, decreasing knots, ...): no face */
            if (std::getenv("SW_FUZZ_VERBOSE"))
                std::fprintf(stderr, "no face: %s: %s\n", e.DynamicType()->Name(),
                             e.GetMessageString());
        }
    }
    /* The faces as a shell (the closed-shell vote), placed twice: once as it is and once moved,
     * as an assembly uses a part twice (one prototype drawn by two instances). */
    TopoDS_Compound all;
    bb.MakeCompound(all);
    bb.Add(all, shell);
    gp_Trsf moved;
    moved.SetTranslation(gp_Vec(1.0, 2.0, 3.0));
    bb.Add(all, shell.Moved(TopLoc_Location(moved)));
    if (const char *out = std::getenv("SW_FUZZ_WRITE_BREP")) /* the input as a BREP file */
        BRepTools::Write(all, out);
    import_and_check(all);
    return 0;
}

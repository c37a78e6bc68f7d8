/* SPDX-License-Identifier: MIT */
/* Test support: OCCT BRepMesh_IncrementalMesh of a model file as world-space triangles, the
 * independent reference the image tests draw through sw_gpu_render_triangles (see
 * occt_reference.hpp). Reading and meshing follow tests/gpu/test_gpu_models.cpp: absolute
 * deflection, angular deflection 0.5 rad, parallel meshing.
 */
#include "occt_reference.hpp"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRepPrimAPI_MakeWedge.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Poly_Triangulation.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Solid.hxx>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <memory>

namespace sw_test
{

namespace
{

std::string lower_extension(const std::string &path)
{
    size_t dot = path.find_last_of('.');
    std::string e = dot == std::string::npos ? std::string() : path.substr(dot + 1);
    for (char &c : e)
        c = (char)std::tolower((unsigned char)c);
    return e;
}

bool read_shape(const std::string &path, TopoDS_Shape &shape, std::string &error)
{
    std::string ext = lower_extension(path);
    if (ext == "brep") {
        BRep_Builder b;
        if (!BRepTools::Read(shape, path.c_str(), b))
            error = "BRepTools::Read failed";
    } else if (ext == "step" || ext == "stp") {
        STEPControl_Reader r;
        if (r.ReadFile(path.c_str()) != IFSelect_RetDone) {
            error = "STEPControl_Reader::ReadFile failed";
            return false;
        }
        r.TransferRoots();
        shape = r.OneShape();
    } else if (ext == "iges" || ext == "igs") {
        IGESControl_Reader r;
        if (r.ReadFile(path.c_str()) != IFSelect_RetDone) {
            error = "IGESControl_Reader::ReadFile failed";
            return false;
        }
        r.TransferRoots();
        shape = r.OneShape();
    } else {
        error = "unsupported extension '" + ext + "'";
        return false;
    }
    if (error.empty() && shape.IsNull())
        error = "the file holds no shape";
    return error.empty();
}

std::array<double, 6> empty_box()
{
    return {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
}

void grow(std::array<double, 6> &b, const double p[3])
{
    for (int k = 0; k < 3; ++k) {
        b[k] = std::min(b[k], p[k]);
        b[3 + k] = std::max(b[3 + k], p[k]);
    }
}

std::array<double, 6> zero_if_empty(const std::array<double, 6> &b)
{
    return b[0] <= b[3] ? b : std::array<double, 6>{};
}

/* Appends one meshed face occurrence, its location applied. */
/* The face's triangulation; its nodes mapped by p -> centre + (p - centre) / up (a face of a
 * copy meshed scaled up by `up` about `centre`: see scale_up). */
void append_face(const TopoDS_Face &f, occt_triangles &out, const gp_Pnt &centre = gp_Pnt(),
                 double up = 1.0)
{
    TopLoc_Location loc;
    Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(f, loc);
    if (tri.IsNull())
        return;
    uint32_t base = (uint32_t)out.n_vertices();
    for (Standard_Integer i = 1; i <= tri->NbNodes(); ++i) {
        gp_Pnt p = tri->Node(i).Transformed(loc.Transformation());
        if (up != 1.0)
            p = gp_Pnt(centre.XYZ() + (p.XYZ() - centre.XYZ()) / up);
        out.pos.insert(out.pos.end(), {p.X(), p.Y(), p.Z()});
    }
    for (Standard_Integer i = 1; i <= tri->NbTriangles(); ++i) {
        Standard_Integer a, b, c;
        tri->Triangle(i).Get(a, b, c);
        out.idx.insert(out.idx.end(),
                       {base + (uint32_t)a - 1, base + (uint32_t)b - 1, base + (uint32_t)c - 1});
    }
    ++out.faces_meshed;
}

/* The frustum as a solid: a wedge (BRepPrimAPI_MakeWedge) whose base is the far rectangle and
 * whose top, z_far - z_near towards the eye, the near one. Local axes: x = right, z = -up, so
 * that y = z x x = -fwd. */
TopoDS_Solid frustum_solid(const occt_clip_frustum &c)
{
    const gp_XYZ eye(c.eye[0], c.eye[1], c.eye[2]), fwd(c.fwd[0], c.fwd[1], c.fwd[2]),
        right(c.right[0], c.right[1], c.right[2]), up(c.up[0], c.up[1], c.up[2]);
    const double hx1 = c.tan_x * c.z_far, hy1 = c.tan_y * c.z_far;
    const double hx0 = c.tan_x * c.z_near, hy0 = c.tan_y * c.z_near;
    const gp_XYZ corner = eye + fwd * c.z_far - right * hx1 + up * hy1;
    BRepPrimAPI_MakeWedge wedge(gp_Ax2(gp_Pnt(corner), gp_Dir(up * -1.0), gp_Dir(right)), 2.0 * hx1,
                                c.z_far - c.z_near, 2.0 * hy1, hx1 - hx0, hy1 - hy0, hx1 + hx0,
                                hy1 + hy0);
    return wedge.Solid();
}

/* The selection cut to the frustum placed by t (the selection's own scaling, see scale_up): its
 * faces' parts inside it (their shared edges cut alike), or nothing when the cut fails, drops a
 * face that reaches into the frustum, or leaves no face. */
TopoDS_Shape cut_to(const TopoDS_Shape &sel, const occt_clip_frustum &c, const gp_Trsf &t)
{
    const TopoDS_Solid frustum =
        TopoDS::Solid(BRepBuilderAPI_Transform(frustum_solid(c), t, Standard_True).Shape());
    BRepAlgoAPI_Common common(sel, frustum);
    if (!common.IsDone() || common.HasErrors())
        return TopoDS_Shape();
    for (TopExp_Explorer e(sel, TopAbs_FACE); e.More(); e.Next()) {
        if (!common.IsDeleted(e.Current()))
            continue;
        BRepExtrema_DistShapeShape dist(e.Current(), frustum);
        if (!dist.IsDone() || dist.InnerSolution() || dist.Value() <= Precision::Confusion())
            return TopoDS_Shape();
    }
    TopExp_Explorer any(common.Shape(), TopAbs_FACE);
    return any.More() ? common.Shape() : TopoDS_Shape();
}

} // namespace

bool occt_clip_frustum::contains(const double p[3]) const
{
    const double d[3] = {p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]};
    const double z = d[0] * fwd[0] + d[1] * fwd[1] + d[2] * fwd[2];
    const double x = d[0] * right[0] + d[1] * right[1] + d[2] * right[2];
    const double y = d[0] * up[0] + d[1] * up[1] + d[2] * up[2];
    return z >= z_near && z <= z_far && std::fabs(x) <= tan_x * z && std::fabs(y) <= tan_y * z;
}

std::array<double, 6> occt_triangles::box() const
{
    std::array<double, 6> b = empty_box();
    for (size_t i = 0; i + 2 < pos.size(); i += 3)
        grow(b, &pos[i]);
    return zero_if_empty(b);
}

struct occt_model::impl {
    TopoDS_Shape shape;
    std::vector<TopoDS_Face> faces; /* occurrences, with their locations */
    std::vector<std::array<double, 6>> boxes;
};

occt_model::occt_model() : p_(new impl) {}
occt_model::~occt_model() = default;

bool occt_model::read(const std::string &path, std::string *error)
{
    std::string err;
    p_->faces.clear();
    p_->boxes.clear();
    try {
        if (read_shape(path, p_->shape, err)) {
            for (TopExp_Explorer ex(p_->shape, TopAbs_FACE); ex.More(); ex.Next()) {
                const TopoDS_Face &f = TopoDS::Face(ex.Current());
                Bnd_Box bb;
                BRepBndLib::Add(f, bb, Standard_False);
                if (bb.IsVoid())
                    continue;
                double b[6];
                bb.Get(b[0], b[1], b[2], b[3], b[4], b[5]);
                p_->faces.push_back(f);
                p_->boxes.push_back({b[0], b[1], b[2], b[3], b[4], b[5]});
            }
            if (p_->faces.empty())
                err = "no faces";
        }
    } catch (const Standard_Failure &e) {
        err = std::string("OCCT exception: ") + e.GetMessageString();
    }
    if (!err.empty() && error)
        *error = path + ": " + err;
    return err.empty();
}

size_t occt_model::n_faces() const { return p_->faces.size(); }

const std::vector<std::array<double, 6>> &occt_model::face_boxes() const { return p_->boxes; }

occt_closure occt_model::closure() const
{
    occt_closure c;
    if (p_->shape.IsNull())
        return c;
    TopTools_IndexedDataMapOfShapeListOfShape faces_of;
    TopExp::MapShapesAndAncestors(p_->shape, TopAbs_EDGE, TopAbs_FACE, faces_of);
    for (Standard_Integer i = 1; i <= faces_of.Extent(); ++i) {
        const TopoDS_Edge &e = TopoDS::Edge(faces_of.FindKey(i));
        if (BRep_Tool::Degenerated(e))
            continue;
        ++c.edges;
        c.free_edges += faces_of(i).Extent() < 2;
        c.max_tolerance = std::max(c.max_tolerance, BRep_Tool::Tolerance(e));
    }
    for (TopExp_Explorer ex(p_->shape, TopAbs_VERTEX); ex.More(); ex.Next())
        c.max_tolerance =
            std::max(c.max_tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(ex.Current())));
    return c;
}

std::array<double, 6> occt_model::box() const
{
    std::array<double, 6> b = empty_box();
    for (const auto &fb : p_->boxes) {
        grow(b, &fb[0]);
        grow(b, &fb[3]);
    }
    return zero_if_empty(b);
}

namespace
{

/* The selection as BRepMesh and the cut see it: itself, or a copy scaled up by `up` about its box
 * centre. BRepMesh meshes nothing finer than OCCT's confusion tolerance (1e-7, absolute): a close
 * view of a part converted to a small unit (a diagonal of 0.01) asks for 3.5e-9 and got no
 * triangle, and a boolean cut at that size loses precision too (Axis_of_bearing at 0.01, mid view:
 * 87 % of edge pixels within 1 px, 6.3 px at most, where cut after scaling: 100 %). Below k_finest
 * the copy is meshed at the deflection scaled alike and its nodes mapped back in double
 * (append_face): the same surfaces at the deflection asked for. */
struct scaled_selection {
    TopoDS_Shape shape;
    std::unique_ptr<BRepBuilderAPI_Transform> xf; /* when up > 1 */
    gp_Trsf t;
    gp_Pnt centre;
    double up = 1.0;

    TopoDS_Face face(const TopoDS_Shape &f) const
    {
        return TopoDS::Face(xf ? xf->ModifiedShape(f) : f);
    }
};

void scale_up(const TopoDS_Shape &sel, double deflection, scaled_selection &s)
{
    const double k_finest = 100.0 * Precision::Confusion();
    s.up = deflection < k_finest ? k_finest / deflection : 1.0;
    s.shape = sel;
    if (!(s.up > 1.0))
        return;
    Bnd_Box bb;
    BRepBndLib::Add(sel, bb);
    double x0, y0, z0, x1, y1, z1;
    bb.Get(x0, y0, z0, x1, y1, z1);
    s.centre = gp_Pnt(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1));
    s.t.SetScale(s.centre, s.up);
    s.xf = std::make_unique<BRepBuilderAPI_Transform>(sel, s.t, Standard_True);
    s.shape = s.xf->Shape();
}

/* BRepMesh of the shape at an absolute deflection; its time in ms. ForceFaceDeflection: BRepMesh
 * otherwise meshes a face no finer than twice its largest edge or vertex tolerance
 * (BRepMesh_Deflection), which on a loosely toleranced face can be many pixels at a close view
 * (linkrods.step: 8.3e-4, 2.7 px at its close-up's silhouette, where its facets showed a depth
 * edge 3 px from the exact one). */
double mesh_shape(const TopoDS_Shape &shape, double deflection, double angle_rad)
{
    auto t0 = std::chrono::steady_clock::now();
    IMeshTools_Parameters prm;
    prm.Deflection = prm.DeflectionInterior = deflection;
    prm.Angle = prm.AngleInterior = angle_rad;
    prm.Relative = Standard_False;
    prm.InParallel = Standard_True;
    prm.ForceFaceDeflection = Standard_True;
    BRepMesh_IncrementalMesh mesher(shape, prm);
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/* Whether every face of the shape got a triangulation. */
bool every_face_meshed(const TopoDS_Shape &shape)
{
    TopLoc_Location loc;
    for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next())
        if (BRep_Tool::Triangulation(TopoDS::Face(e.Current()), loc).IsNull())
            return false;
    return true;
}

} // namespace

bool occt_model::mesh(double deflection, occt_triangles &out, const occt_face_filter &keep,
                      double angle_rad, const occt_clip_frustum *clip)
{
    out = occt_triangles{};
    if (!(deflection > 0.0) || p_->faces.empty())
        return false;
    try {
        /* A finer triangulation left from an earlier call would be kept by BRepMesh. */
        BRepTools::Clean(p_->shape, Standard_True);
        BRep_Builder b;
        TopoDS_Compound sel;
        b.MakeCompound(sel);
        std::vector<size_t> chosen;
        for (size_t i = 0; i < p_->faces.size(); ++i)
            if (!keep || keep(p_->boxes[i])) {
                b.Add(sel, p_->faces[i]);
                chosen.push_back(i);
            }
        if (chosen.empty())
            return false;
        out.triangles_per_face.assign(p_->faces.size(), 0);
        /* A close view shows a small part of its faces; meshed whole at its deflection they took
         * minutes (screw.step's close view: over 300 s). A cut that fails, or leaves a face
         * BRepMesh cannot mesh, fails the call: the caller meshes whole faces, at a deflection
         * planned for them. */
        scaled_selection sc;
        scale_up(sel, deflection, sc);
        TopoDS_Shape cut = clip ? cut_to(sc.shape, *clip, sc.t) : TopoDS_Shape();
        if (!cut.IsNull()) {
            out.ms = mesh_shape(cut, deflection * sc.up, angle_rad);
            if (!every_face_meshed(cut))
                return false;
            for (TopExp_Explorer e(cut, TopAbs_FACE); e.More(); e.Next())
                append_face(TopoDS::Face(e.Current()), out, sc.centre, sc.up);
            return !out.idx.empty();
        }
        if (clip)
            return false;
        out.ms = mesh_shape(sc.shape, deflection * sc.up, angle_rad);
        for (size_t i : chosen) {
            size_t before = out.n_triangles();
            append_face(sc.face(p_->faces[i]), out, sc.centre, sc.up);
            out.triangles_per_face[i] = (uint32_t)(out.n_triangles() - before);
        }
    } catch (const Standard_Failure &) {
        out = occt_triangles{};
        return false;
    }
    return !out.idx.empty();
}

bool occt_reference_mesh(const std::string &path, double deflection, occt_triangles &out,
                         std::string *error)
{
    occt_model m;
    if (!m.read(path, error))
        return false;
    if (m.mesh(deflection, out))
        return true;
    if (error)
        *error = path + ": BRepMesh produced no triangles";
    return false;
}

} // namespace sw_test

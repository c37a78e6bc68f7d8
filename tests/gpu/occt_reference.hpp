/* tests/gpu: OCCT's BRepMesh of a STEP / BREP file, the independent reference the image tests
 * compare sw_gpu_render_scene with (drawn through sw_gpu_render_triangles). Header-only, for the
 * C++ tests of this folder. */
#ifndef SW_TESTS_GPU_OCCT_REFERENCE_HPP
#define SW_TESTS_GPU_OCCT_REFERENCE_HPP

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace
{

struct ref_mesh {
    std::vector<double> pos;
    std::vector<uint32_t> idx;
};

inline bool ends_with(const std::string &s, const char *e)
{
    size_t n = std::strlen(e);
    return s.size() >= n && s.compare(s.size() - n, n, e) == 0;
}

inline bool read_shape(const std::string &path, TopoDS_Shape &shape)
{
    if (ends_with(path, ".brep")) {
        BRep_Builder b;
        return BRepTools::Read(shape, path.c_str(), b);
    }
    STEPControl_Reader r;
    if (r.ReadFile(path.c_str()) != IFSelect_RetDone)
        return false;
    r.TransferRoots();
    shape = r.OneShape();
    return !shape.IsNull();
}

inline bool reference_mesh(const std::string &path, double deflection, ref_mesh &m)
{
    TopoDS_Shape shape;
    if (!read_shape(path, shape))
        return false;
    BRepMesh_IncrementalMesh mesher(shape, deflection, Standard_False, 0.5, Standard_True);
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
        TopLoc_Location loc;
        const TopoDS_Face &f = TopoDS::Face(ex.Current());
        Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(f, loc);
        if (tri.IsNull())
            continue;
        uint32_t base = (uint32_t)(m.pos.size() / 3);
        for (Standard_Integer i = 1; i <= tri->NbNodes(); ++i) {
            gp_Pnt p = tri->Node(i).Transformed(loc.Transformation());
            m.pos.insert(m.pos.end(), {p.X(), p.Y(), p.Z()});
        }
        for (Standard_Integer i = 1; i <= tri->NbTriangles(); ++i) {
            Standard_Integer a, b, c;
            tri->Triangle(i).Get(a, b, c);
            m.idx.insert(m.idx.end(),
                         {base + (uint32_t)a - 1, base + (uint32_t)b - 1, base + (uint32_t)c - 1});
        }
    }
    return !m.idx.empty();
}

} // namespace

#endif

/* SPDX-License-Identifier: MIT */
/* bench/peers: the OCCT mesher shim (see peer_occt.h). Normals are averaged per vertex from the
 * triangles of the face (area-weighted), which is what the draw's Lambert shading needs. */
#include "peer_occt.h"

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

namespace
{

double ms_since(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void append_face(const TopoDS_Face &face, std::vector<float> &v, std::vector<uint32_t> &idx,
                 bp_occt_mesh *out)
{
    TopLoc_Location loc;
    Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    out->faces++;
    if (tri.IsNull() || tri->NbTriangles() == 0) {
        out->faces_unmeshed++;
        return;
    }
    const gp_Trsf xf = loc.Transformation();
    const size_t base = v.size() / BP_OCCT_VERTEX_FLOATS;
    const int nn = tri->NbNodes();
    for (int i = 1; i <= nn; ++i) {
        gp_Pnt p = tri->Node(i).Transformed(xf);
        v.insert(v.end(), {(float)p.X(), (float)p.Y(), (float)p.Z(), 0.0f, 0.0f, 0.0f});
    }
    for (int t = 1; t <= tri->NbTriangles(); ++t) {
        int a, b, c;
        tri->Triangle(t).Get(a, b, c);
        const uint32_t k[3] = {(uint32_t)(base + a - 1), (uint32_t)(base + b - 1),
                               (uint32_t)(base + c - 1)};
        float *pa = &v[k[0] * 6], *pb = &v[k[1] * 6], *pc = &v[k[2] * 6];
        const float e1[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
        const float e2[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
        const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                            e1[0] * e2[1] - e1[1] * e2[0]};
        for (uint32_t q : k)
            for (int j = 0; j < 3; ++j)
                v[q * 6 + 3 + j] += n[j];
        idx.insert(idx.end(), {k[0], k[1], k[2]});
    }
}

} // namespace

extern "C" int bp_occt_mesh_brep(const char *path, double deflection, bp_occt_mesh *out, char *err,
                                 size_t err_size)
{
    std::memset(out, 0, sizeof *out);
    try {
        auto t0 = std::chrono::steady_clock::now();
        TopoDS_Shape shape;
        BRep_Builder builder;
        if (!BRepTools::Read(shape, path, builder) || shape.IsNull()) {
            std::snprintf(err, err_size, "%s: OCCT cannot read it as a BREP", path);
            return -1;
        }
        out->ms_read = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        BRepMesh_IncrementalMesh mesher(shape, deflection, Standard_False, 0.5, Standard_True);
        out->ms_mesh = ms_since(t0);
        std::vector<float> v;
        std::vector<uint32_t> idx;
        for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next())
            append_face(TopoDS::Face(ex.Current()), v, idx, out);
        if (out->faces == 0 || idx.empty()) {
            std::snprintf(err, err_size, "%s: no face was meshed (%llu faces)", path,
                          (unsigned long long)out->faces);
            return -1;
        }
        if (v.size() / BP_OCCT_VERTEX_FLOATS > UINT32_MAX) {
            std::snprintf(err, err_size, "%s: more than 2^32 vertices", path);
            return -1;
        }
        out->v = static_cast<float *>(std::malloc(v.size() * sizeof(float)));
        out->idx = static_cast<uint32_t *>(std::malloc(idx.size() * sizeof(uint32_t)));
        if (!out->v || !out->idx) {
            bp_occt_mesh_free(out);
            std::snprintf(err, err_size, "out of memory");
            return -1;
        }
        std::memcpy(out->v, v.data(), v.size() * sizeof(float));
        std::memcpy(out->idx, idx.data(), idx.size() * sizeof(uint32_t));
        out->n_v = v.size() / BP_OCCT_VERTEX_FLOATS;
        out->n_idx = idx.size();
        return 0;
    } catch (const std::bad_alloc &) {
        std::snprintf(err, err_size, "out of memory");
    } catch (const Standard_Failure &e) {
        std::snprintf(err, err_size, "%s: OCCT exception: %s", path, e.GetMessageString());
    } catch (...) {
        std::snprintf(err, err_size, "%s: unknown exception in OCCT", path);
    }
    bp_occt_mesh_free(out);
    return -1;
}

extern "C" void bp_occt_mesh_free(bp_occt_mesh *m)
{
    if (!m)
        return;
    std::free(m->v);
    std::free(m->idx);
    m->v = nullptr;
    m->idx = nullptr;
    m->n_v = m->n_idx = 0;
}

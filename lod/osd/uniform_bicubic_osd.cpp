/* SPDX-License-Identifier: MIT */
// OpenSubdiv shim: the limit surface of a regular control grid, evaluated by OpenSubdiv's Far
// layer (TopologyRefiner -> adaptive refinement -> PatchTableFactory -> PatchMap + EvaluateBasis),
// in double precision. It is the independent reference for sw_sg_uniform_bicubic_eval (Guthe et
// al. 2005 §6 approximates surfaces by bi-cubic patches of this kind). No exception escapes.
#include "sw_lod_osd.h"

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefiner.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/version.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <vector>

namespace
{

using namespace OpenSubdiv;

// The primvar type PrimvarRefiner and PatchTable::ComputeLocalPointValues interpolate.
struct Point3 {
    double p[3];
    void Clear(void * = nullptr)
    {
        p[0] = p[1] = p[2] = 0.0;
    }
    void AddWithWeight(const Point3 &src, double w)
    {
        p[0] += w * src.p[0];
        p[1] += w * src.p[1];
        p[2] += w * src.p[2];
    }
};

sw_result fail(sw_status *status, sw_result r, const char *fmt, ...)
{
    if (status) {
        va_list ap;
        va_start(ap, fmt);
        status->result = r;
        std::vsnprintf(status->message, sizeof status->message, fmt, ap);
        va_end(ap);
    }
    return r;
}

sw_result check_args(const double *verts, int32_t nx, int32_t ny, const sw_lod_osd_sample *samples,
                     size_t count, const double *pos, sw_status *status)
{
    if (!verts || !pos || (count > 0 && !samples))
        return fail(status, SW_ERR_INVALID_ARGUMENT, "OpenSubdiv grid: NULL array");
    if (nx < 2 || ny < 2 || nx > 4096 || ny > 4096)
        return fail(status, SW_ERR_INVALID_ARGUMENT, "OpenSubdiv grid: %d x %d vertices", (int)nx,
                    (int)ny);
    for (size_t k = 0; k < count; k++) {
        const sw_lod_osd_sample &q = samples[k];
        if (q.face_i < 0 || q.face_i >= nx - 1 || q.face_j < 0 || q.face_j >= ny - 1)
            return fail(status, SW_ERR_INVALID_ARGUMENT,
                        "OpenSubdiv grid: sample %zu on face (%d, %d) outside %d x %d faces", k,
                        (int)q.face_i, (int)q.face_j, (int)nx - 1, (int)ny - 1);
        if (!(q.s >= 0.0 && q.s <= 1.0 && q.t >= 0.0 && q.t <= 1.0))
            return fail(status, SW_ERR_INVALID_ARGUMENT,
                        "OpenSubdiv grid: sample %zu at (%g, %g) outside [0,1]^2", k, q.s, q.t);
    }
    return SW_OK;
}

std::unique_ptr<Far::TopologyRefiner> make_refiner(int nx, int ny)
{
    const int fx = nx - 1, fy = ny - 1;
    std::vector<int> verts_per_face(static_cast<size_t>(fx) * fy, 4);
    std::vector<int> face_verts;
    face_verts.reserve(static_cast<size_t>(fx) * fy * 4);
    for (int j = 0; j < fy; j++)
        for (int i = 0; i < fx; i++) {
            face_verts.push_back(j * nx + i);
            face_verts.push_back(j * nx + i + 1);
            face_verts.push_back((j + 1) * nx + i + 1);
            face_verts.push_back((j + 1) * nx + i);
        }
    Far::TopologyDescriptor desc;
    desc.numVertices = nx * ny;
    desc.numFaces = fx * fy;
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = face_verts.data();

    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    return std::unique_ptr<Far::TopologyRefiner>(
        Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
}

sw_result eval_grid(const double *verts, int nx, int ny, const sw_lod_osd_sample *samples,
                    size_t count, double *pos, double *ds, double *dt, sw_status *status)
{
    std::unique_ptr<Far::TopologyRefiner> refiner = make_refiner(nx, ny);
    if (!refiner)
        return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: cannot build the topology refiner");
    const int isolation = 2; // boundary corners only; regular faces stay level-0 patches
    refiner->RefineAdaptive(Far::TopologyRefiner::AdaptiveOptions(isolation));

    Far::PatchTableFactory::Options opts(isolation);
    opts.SetPatchPrecision<double>();
    opts.endCapType = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
    std::unique_ptr<Far::PatchTable> table(Far::PatchTableFactory::Create(*refiner, opts));
    if (!table)
        return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: cannot build the patch table");

    // All refined vertices, level by level, then the patch table's local points.
    const int n_refined = refiner->GetNumVerticesTotal();
    std::vector<Point3> pts(static_cast<size_t>(n_refined) + table->GetNumLocalPoints());
    for (int v = 0; v < nx * ny; v++)
        for (int c = 0; c < 3; c++)
            pts[v].p[c] = verts[v * 3 + c];
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    Point3 *src = pts.data();
    for (int level = 1; level <= refiner->GetMaxLevel(); level++) {
        Point3 *dst = src + refiner->GetLevel(level - 1).GetNumVertices();
        primvar.Interpolate(level, src, dst);
        src = dst;
    }
    if (table->GetNumLocalPoints() > 0)
        table->ComputeLocalPointValues(pts.data(), pts.data() + n_refined);

    Far::PatchMap map(*table);
    double wp[20], wds[20], wdt[20];
    for (size_t k = 0; k < count; k++) {
        const sw_lod_osd_sample &q = samples[k];
        const int face = q.face_j * (nx - 1) + q.face_i;
        const Far::PatchTable::PatchHandle *h = map.FindPatch(face, q.s, q.t);
        if (!h)
            return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: no patch for face %d at (%g, %g)",
                        face, q.s, q.t);
        table->EvaluateBasis(*h, q.s, q.t, wp, wds, wdt);
        Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
        if (cvs.size() > 20)
            return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: patch with %d control points",
                        cvs.size());
        for (int c = 0; c < 3; c++) {
            double p = 0.0, du = 0.0, dv = 0.0;
            for (int r = 0; r < cvs.size(); r++) {
                const double x = pts[cvs[r]].p[c];
                p += wp[r] * x;
                du += wds[r] * x;
                dv += wdt[r] * x;
            }
            pos[k * 3 + c] = p;
            if (ds)
                ds[k * 3 + c] = du;
            if (dt)
                dt[k * 3 + c] = dv;
        }
    }
    return SW_OK;
}

} // namespace

extern "C" sw_result sw_lod_osd_eval_grid(const double *verts, int32_t nx, int32_t ny,
                                          const sw_lod_osd_sample *samples, size_t count,
                                          double *pos, double *ds, double *dt, sw_status *status)
{
    sw_result r = check_args(verts, nx, ny, samples, count, pos, status);
    if (r != SW_OK)
        return r;
    try {
        r = eval_grid(verts, nx, ny, samples, count, pos, ds, dt, status);
    } catch (const std::bad_alloc &) {
        return fail(status, SW_ERR_OUT_OF_MEMORY, "OpenSubdiv: out of memory");
    } catch (const std::exception &e) {
        return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: %s", e.what());
    } catch (...) {
        return fail(status, SW_ERR_INTERNAL, "OpenSubdiv: unknown exception");
    }
    if (r == SW_OK && status) {
        status->result = SW_OK;
        status->message[0] = '\0';
    }
    return r;
}

extern "C" const char *sw_lod_osd_version(void)
{
#define SW__STR2(x) #x
#define SW__STR(x) SW__STR2(x)
    return SW__STR(OPENSUBDIV_VERSION_MAJOR) "." SW__STR(OPENSUBDIV_VERSION_MINOR) "." SW__STR(
        OPENSUBDIV_VERSION_PATCH);
#undef SW__STR
#undef SW__STR2
}

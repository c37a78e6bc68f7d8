/* SPDX-License-Identifier: MIT */
// OpenMesh shim: a static LOD's simplified levels (Kumar et al. 1997 §4.2), borders first.
//
// Where the paper is loose: §4.2 simplifies with simplification envelopes (Cohen et al. 1996),
// which bound the distance to the input both ways; OpenMesh's Hausdorff module bounds only the
// removed vertices' distance to the mesh. The caller therefore measures every level against the
// exact surface afterwards (sw_lod_static_measure) and declares ε_k from that measurement.
// §4.2 also leaves open how a border is simplified "first": we run Douglas-Peucker per border
// polyline between corners, restricted to the vertices the previous level kept, so each level's
// border is a sub-polyline of the previous one's and within the level's tolerance of level 0's.
#include "sw_lod_static_decimate.h"
#include "sw_status_util.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModHausdorffT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <cmath>
#include <exception>
#include <new>
#include <utility>
#include <vector>

namespace
{

struct traits : public OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
    VertexAttributes(OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    HalfedgeAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::PrevHalfedge);
    FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using mesh_t = OpenMesh::TriMesh_ArrayKernelT<traits>;

enum plan : unsigned char { PLAN_INTERIOR = 0, PLAN_KEEP = 1, PLAN_REMOVE = 2 };

// Binary module: a border vertex Douglas-Peucker dropped may collapse only along its border edge
// (so the border becomes the simplified polyline); a kept one not at all (it is also locked).
template <class MeshT> class mod_border_plan : public OpenMesh::Decimater::ModBaseT<MeshT>
{
  public:
    DECIMATING_MODULE(mod_border_plan, MeshT, BorderPlan);
    explicit mod_border_plan(MeshT &m) : Base(m, true) {}
    void set_plan(OpenMesh::VPropHandleT<unsigned char> p)
    {
        plan_ = p;
    }
    float collapse_priority(const CollapseInfo &ci) override
    {
        const unsigned char p = Base::mesh().property(plan_, ci.v0);
        if (p == PLAN_KEEP)
            return Base::ILLEGAL_COLLAPSE;
        if (p == PLAN_REMOVE && !Base::mesh().is_boundary(Base::mesh().edge_handle(ci.v0v1)))
            return Base::ILLEGAL_COLLAPSE;
        return Base::LEGAL_COLLAPSE;
    }

  private:
    OpenMesh::VPropHandleT<unsigned char> plan_;
};

double dist_point_segment(const mesh_t::Point &p, const mesh_t::Point &a, const mesh_t::Point &b)
{
    const mesh_t::Point ab = b - a;
    const double l2 = ab.sqrnorm();
    double t = l2 > 0.0 ? ((p - a) | ab) / l2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return (p - (a + ab * t)).norm();
}

// Border chains of level 0: vertex sequences from corner to corner (both included).
std::vector<std::vector<int>> border_chains(const mesh_t &m, const uint8_t *corner)
{
    std::vector<std::vector<int>> chains;
    std::vector<char> seen(m.n_halfedges(), 0);
    for (auto h : m.halfedges()) {
        if (!m.is_boundary(h) || seen[h.idx()])
            continue;
        std::vector<int> loop;
        for (auto g = h; !seen[g.idx()]; g = m.next_halfedge_handle(g)) {
            seen[g.idx()] = 1;
            loop.push_back(m.from_vertex_handle(g).idx());
        }
        const size_t n = loop.size();
        std::vector<size_t> cut;
        for (size_t i = 0; i < n; ++i)
            if (corner[loop[i]])
                cut.push_back(i);
        if (cut.size() < 2) { // a loop without two corners: its first vertex and the farthest
            const auto p0 = m.point(m.vertex_handle(loop[cut.empty() ? 0 : cut[0]]));
            size_t first = cut.empty() ? 0 : cut[0], far = first;
            double best = -1.0;
            for (size_t i = 0; i < n; ++i) {
                const double d = (m.point(m.vertex_handle(loop[i])) - p0).norm();
                if (d > best)
                    best = d, far = i;
            }
            cut.assign({first < far ? first : far, first < far ? far : first});
            if (cut[0] == cut[1])
                cut.pop_back();
        }
        for (size_t c = 0; c < cut.size(); ++c) {
            const size_t a = cut[c], b = c + 1 < cut.size() ? cut[c + 1] : cut[0] + n;
            std::vector<int> ch;
            for (size_t i = a; i <= b; ++i)
                ch.push_back(loop[i % n]);
            chains.push_back(std::move(ch));
        }
    }
    return chains;
}

// Douglas-Peucker over a level-0 chain, splitting only at vertices still present: marks the
// present vertices to keep. Iterative (chains can be long).
void restricted_dp(const mesh_t &m, const std::vector<int> &ch, double tol, std::vector<char> &keep)
{
    std::vector<std::pair<size_t, size_t>> stack{{0, ch.size() - 1}};
    keep[0] = keep[ch.size() - 1] = 1;
    while (!stack.empty()) {
        const auto [a, b] = stack.back();
        stack.pop_back();
        if (b < a + 2)
            continue;
        const auto pa = m.point(m.vertex_handle(ch[a])), pb = m.point(m.vertex_handle(ch[b]));
        double worst = 0.0, best_d = -1.0;
        size_t best = 0;
        for (size_t i = a + 1; i < b; ++i) {
            const auto vh = m.vertex_handle(ch[i]);
            const double d = dist_point_segment(m.point(vh), pa, pb);
            worst = d > worst ? d : worst;
            if (!m.status(vh).deleted() && d > best_d)
                best_d = d, best = i;
        }
        if (worst <= tol || best_d < 0.0)
            continue;
        keep[best] = 1;
        stack.push_back({a, best});
        stack.push_back({best, b});
    }
}

// Plans the borders for tolerance tol: kept vertices locked, dropped ones marked.
void plan_borders(mesh_t &m, const std::vector<std::vector<int>> &chains, double tol,
                  OpenMesh::VPropHandleT<unsigned char> plan)
{
    for (const auto &ch : chains) {
        std::vector<char> keep(ch.size(), 0);
        restricted_dp(m, ch, tol, keep);
        for (size_t i = 0; i < ch.size(); ++i) {
            const auto vh = m.vertex_handle(ch[i]);
            if (m.status(vh).deleted())
                continue;
            m.property(plan, vh) = keep[i] ? PLAN_KEEP : PLAN_REMOVE;
            m.status(vh).set_locked(keep[i] != 0);
        }
    }
}

sw_result run(const sw_lod_decimate_input *in, sw_lod_decimate_level_fn fn, void *ctx,
              sw_status *status)
{
    mesh_t m;
    m.reserve(in->n_vertices, 3 * (size_t)in->n_triangles, in->n_triangles);
    for (uint32_t v = 0; v < in->n_vertices; ++v)
        m.add_vertex(mesh_t::Point(in->pos[3 * v], in->pos[3 * v + 1], in->pos[3 * v + 2]));
    for (uint32_t t = 0; t < in->n_triangles; ++t) {
        const uint32_t *tv = in->tri + 3 * (size_t)t;
        if (tv[0] >= in->n_vertices || tv[1] >= in->n_vertices || tv[2] >= in->n_vertices)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "decimate: triangle %u indexes a "
                            "vertex out of range",
                            t);
        if (!m.add_face(m.vertex_handle(tv[0]), m.vertex_handle(tv[1]), m.vertex_handle(tv[2]))
                 .is_valid())
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "decimate: triangle %u (%u %u %u) makes the mesh non-manifold", t,
                            tv[0], tv[1], tv[2]);
    }
    m.request_face_normals();
    m.update_face_normals();
    OpenMesh::VPropHandleT<unsigned char> plan;
    m.add_property(plan);
    for (auto v : m.vertices())
        m.property(plan, v) = PLAN_INTERIOR;
    const auto chains = border_chains(m, in->corner);

    OpenMesh::Decimater::DecimaterT<mesh_t> dec(m);
    OpenMesh::Decimater::ModQuadricT<mesh_t>::Handle quadric;
    OpenMesh::Decimater::ModHausdorffT<mesh_t>::Handle hausdorff;
    OpenMesh::Decimater::ModNormalFlippingT<mesh_t>::Handle flipping;
    mod_border_plan<mesh_t>::Handle border;
    dec.add(quadric);
    dec.add(hausdorff);
    dec.add(flipping);
    dec.add(border);
    dec.module(flipping).set_max_normal_deviation(60.0);
    dec.module(border).set_plan(plan);
    if (!dec.initialize())
        return sw__fail(status, SW_ERR_INTERNAL, "decimate: the decimater did not initialise");
    std::vector<uint32_t> tri;
    for (int32_t k = 0; k < in->n_levels; ++k) {
        const double tol = in->tolerance[k];
        plan_borders(m, chains, tol, plan);
        dec.module(hausdorff).set_tolerance(tol);
        dec.decimate(0);
        tri.clear();
        for (auto f : m.faces()) {
            if (m.status(f).deleted())
                continue;
            for (auto v : m.fv_range(f))
                tri.push_back((uint32_t)v.idx());
        }
        if (fn(ctx, k, tri.data(), (uint32_t)(tri.size() / 3)))
            break;
    }
    sw__status_ok(status);
    return SW_OK;
}

} // namespace

extern "C" sw_result sw_lod_static_decimate(const sw_lod_decimate_input *in,
                                            sw_lod_decimate_level_fn fn, void *ctx,
                                            sw_status *status)
{
    try {
        return run(in, fn, ctx, status);
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "decimate: %u triangles", in->n_triangles);
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "decimate: %s", e.what());
    }
}

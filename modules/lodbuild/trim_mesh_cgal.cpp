/* SPDX-License-Identifier: MIT */
// CGAL shim: the constrained Delaunay triangulation of a face's parameter domain (Kumar et al.
// 1997 §4.3: trimming curves are borders of the mesh). Exact predicates with inexact
// constructions: crossing constraints are split at a computed intersection point. No exception
// escapes.
#include "sw_lod_trim_mesh.h"
#include "sw_status_util.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <new>
#include <vector>

namespace
{

struct vertex_info {
    uint32_t tag = SW_LOD_CDT_NO_TAG;
    uint32_t index = 0; // position in the last snapshot
    size_t id = 0;      // the id that made the vertex: of points given twice, the first one tags
};

using kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using vbase = CGAL::Triangulation_vertex_base_with_info_2<vertex_info, kernel>;
using fbase = CGAL::Constrained_triangulation_face_base_2<kernel>;
using tds = CGAL::Triangulation_data_structure_2<vbase, fbase>;
using cdt_t = CGAL::Constrained_Delaunay_triangulation_2<kernel, tds, CGAL::Exact_predicates_tag>;

} // namespace

struct sw_lod_cdt {
    cdt_t t;
    std::vector<cdt_t::Vertex_handle> handles; // by id
};

extern "C" sw_result sw_lod_cdt_create(sw_lod_cdt **out, sw_status *status)
{
    *out = nullptr;
    try {
        *out = new sw_lod_cdt();
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cdt: %s", e.what());
    }
    sw__status_ok(status);
    return SW_OK;
}

extern "C" void sw_lod_cdt_free(sw_lod_cdt *cdt)
{
    delete cdt;
}

extern "C" sw_result sw_lod_cdt_insert_points(sw_lod_cdt *cdt, const double *uv,
                                              const uint32_t *tags, uint32_t n, uint32_t *ids,
                                              sw_status *status)
{
    for (uint32_t k = 0; k < n; ++k)
        if (!std::isfinite(uv[2 * k]) || !std::isfinite(uv[2 * k + 1]))
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "cdt: point %u is not finite", k);
    try {
        // Points come in raster order (a grid, then refinement points by triangle). Inserted so,
        // each one lands beside a long front of thin triangles and its flips propagate along it:
        // quadratic time, measured as ~90 % of hammer.brep's static-LOD build in CGAL's
        // propagating_flip. A Hilbert order (CGAL's spatial_sort) keeps every insertion local.
        std::vector<kernel::Point_2> points;
        points.reserve(n);
        for (uint32_t k = 0; k < n; ++k)
            points.emplace_back(uv[2 * k], uv[2 * k + 1]);
        std::vector<std::size_t> order(n);
        for (uint32_t k = 0; k < n; ++k)
            order[k] = k;
        using sort_traits =
            CGAL::Spatial_sort_traits_adapter_2<kernel,
                                                CGAL::Pointer_property_map<kernel::Point_2>::type>;
        CGAL::spatial_sort(order.begin(), order.end(),
                           sort_traits(CGAL::make_property_map(points)));
        const size_t first = cdt->handles.size();
        cdt->handles.resize(first + n);
        cdt_t::Face_handle hint;
        for (std::size_t k : order) {
            const size_t before = cdt->t.number_of_vertices(), id = first + k;
            cdt_t::Vertex_handle v = cdt->t.insert(points[k], hint);
            // The array's order decides the tag of a point given twice, as it did before the
            // sort: a vertex of an earlier call keeps its tag, in this call the first id wins.
            const bool made = cdt->t.number_of_vertices() != before;
            if (made || (v->info().id >= first && id < v->info().id)) {
                v->info().tag = tags[k];
                v->info().id = id;
            }
            hint = v->face();
            ids[k] = (uint32_t)id;
            cdt->handles[id] = v;
        }
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cdt: %u points", n);
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "cdt: inserting points: %s", e.what());
    }
    sw__status_ok(status);
    return SW_OK;
}

extern "C" sw_result sw_lod_cdt_insert_constraints(sw_lod_cdt *cdt, const uint32_t *pairs,
                                                   uint32_t n_pairs, sw_status *status)
{
    const size_t nh = cdt->handles.size();
    for (uint32_t k = 0; k < 2 * n_pairs; ++k)
        if (pairs[k] >= nh)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "cdt: constraint id %u of %zu",
                            pairs[k], nh);
    try {
        for (uint32_t k = 0; k < n_pairs; ++k) {
            cdt_t::Vertex_handle a = cdt->handles[pairs[2 * k]], b = cdt->handles[pairs[2 * k + 1]];
            if (a != b)
                cdt->t.insert_constraint(a, b);
        }
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cdt: %u constraints", n_pairs);
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "cdt: inserting constraints: %s", e.what());
    }
    sw__status_ok(status);
    return SW_OK;
}

extern "C" sw_result sw_lod_cdt_snapshot(sw_lod_cdt *cdt, sw_lod_cdt_mesh *out, sw_status *status)
{
    *out = sw_lod_cdt_mesh{};
    const size_t nv = cdt->t.number_of_vertices(), nf = cdt->t.number_of_faces();
    if (nv > UINT32_MAX / 4 || nf > UINT32_MAX / 4)
        return sw__fail(status, SW_ERR_LIMIT, "cdt: %zu vertices, %zu triangles", nv, nf);
    out->uv = static_cast<double *>(std::malloc((nv ? nv : 1) * 2 * sizeof(double)));
    out->tag = static_cast<uint32_t *>(std::malloc((nv ? nv : 1) * sizeof(uint32_t)));
    out->tri = static_cast<uint32_t *>(std::malloc((nf ? nf : 1) * 3 * sizeof(uint32_t)));
    if (!out->uv || !out->tag || !out->tri) {
        sw_lod_cdt_mesh_free(out);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "cdt: snapshot of %zu vertices", nv);
    }
    uint32_t i = 0;
    for (auto v = cdt->t.finite_vertices_begin(); v != cdt->t.finite_vertices_end(); ++v, ++i) {
        v->info().index = i;
        out->uv[2 * i] = v->point().x();
        out->uv[2 * i + 1] = v->point().y();
        out->tag[i] = v->info().tag;
    }
    out->n_vertices = i;
    uint32_t t = 0;
    for (auto f = cdt->t.finite_faces_begin(); f != cdt->t.finite_faces_end(); ++f, ++t)
        for (int c = 0; c < 3; ++c)
            out->tri[3 * t + c] = f->vertex(c)->info().index;
    out->n_triangles = t;
    sw__status_ok(status);
    return SW_OK;
}

extern "C" void sw_lod_cdt_mesh_free(sw_lod_cdt_mesh *m)
{
    if (!m)
        return;
    std::free(m->uv);
    std::free(m->tag);
    std::free(m->tri);
    *m = sw_lod_cdt_mesh{};
}

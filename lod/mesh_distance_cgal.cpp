/* SPDX-License-Identifier: MIT */
// CGAL shim: distance from points to a triangle mesh by an AABB tree (exact closest point per
// triangle in double precision). No exception escapes.
#include "sw_lod_mesh_distance.h"
#include "sw_status_util.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <exception>
#include <new>
#include <vector>

namespace
{
using kernel = CGAL::Simple_cartesian<double>;
using triangle = kernel::Triangle_3;
using primitive = CGAL::AABB_triangle_primitive<kernel, std::vector<triangle>::const_iterator>;
using tree_t = CGAL::AABB_tree<CGAL::AABB_traits<kernel, primitive>>;
} // namespace

struct sw_lod_mesh_distance {
    std::vector<triangle> tris;
    tree_t tree;
};

extern "C" sw_result sw_lod_mesh_distance_create(const double *pos, const uint32_t *tri,
                                                 uint32_t n_triangles, sw_lod_mesh_distance **out,
                                                 sw_status *status)
{
    *out = nullptr;
    if (n_triangles == 0)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "mesh distance: no triangles");
    sw_lod_mesh_distance *d = nullptr;
    try {
        d = new sw_lod_mesh_distance();
        d->tris.reserve(n_triangles);
        for (uint32_t t = 0; t < n_triangles; ++t) {
            const double *a = pos + 3 * (size_t)tri[3 * t], *b = pos + 3 * (size_t)tri[3 * t + 1],
                         *c = pos + 3 * (size_t)tri[3 * t + 2];
            d->tris.emplace_back(kernel::Point_3(a[0], a[1], a[2]),
                                 kernel::Point_3(b[0], b[1], b[2]),
                                 kernel::Point_3(c[0], c[1], c[2]));
        }
        d->tree.insert(d->tris.cbegin(), d->tris.cend());
        d->tree.build();
        d->tree.accelerate_distance_queries();
    } catch (const std::bad_alloc &) {
        delete d;
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh distance: %u triangles", n_triangles);
    } catch (const std::exception &e) {
        delete d;
        return sw__fail(status, SW_ERR_INTERNAL, "mesh distance: %s", e.what());
    }
    *out = d;
    sw__status_ok(status);
    return SW_OK;
}

extern "C" void sw_lod_mesh_distance_free(sw_lod_mesh_distance *d)
{
    delete d;
}

extern "C" double sw_lod_mesh_distance_query(const sw_lod_mesh_distance *d, const double p[3])
{
    return std::sqrt(d->tree.squared_distance(kernel::Point_3(p[0], p[1], p[2])));
}

/* SPDX-License-Identifier: MIT */
// CGAL shim: distance from points to a triangle mesh by an AABB tree (exact closest point per
// triangle in double precision). No exception escapes.
#include "sw_lod_mesh_distance.h"
#include "sw_status_util.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/squared_distance_3.h>

#include <algorithm>
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

namespace
{
using point = kernel::Point_3;
using tri_iter = std::vector<triangle>::const_iterator;

/* A corner of a piece: its position, its distance to the mesh and the mesh triangle nearest. */
struct corner {
    point p;
    double dist;
    tri_iter nearest;
};

struct piece {
    corner v[3];
    int32_t depth;
};

struct bounder {
    const sw_lod_mesh_distance *d;
    double rel, abs_floor;
    int32_t max_depth;
    sw_lod_mesh_bound out;

    /* the closest points are computed in double: a distance is raised by a few ulps of the
     * coordinates it came from */
    static double rounding(const point &p)
    {
        return 1e-14 * (std::fabs(p.x()) + std::fabs(p.y()) + std::fabs(p.z()) + 1e-300);
    }

    corner at(const point &p)
    {
        const auto hit = d->tree.closest_point_and_primitive(p);
        const double dist = std::sqrt(CGAL::squared_distance(p, hit.first)) + rounding(p);
        out.lower = std::max(out.lower, dist);
        return corner{p, dist, hit.second};
    }

    static point mid(const point &a, const point &b)
    {
        return point(0.5 * (a.x() + b.x()), 0.5 * (a.y() + b.y()), 0.5 * (a.z() + b.z()));
    }

    /* min over the corners' nearest triangles C of max over the corners of dist(corner, C) */
    static double convex_bound(const piece &t)
    {
        double best = INFINITY;
        for (int c = 0; c < 3; ++c) {
            const triangle &tc = *t.v[c].nearest;
            double worst = 0.0;
            for (int k = 0; k < 3 && worst < best; ++k)
                worst = std::max(worst, std::sqrt(CGAL::squared_distance(t.v[k].p, tc)) +
                                            rounding(t.v[k].p));
            best = std::min(best, worst);
        }
        return best;
    }

    static double lipschitz_bound(const piece &t)
    {
        double edge = 0.0, nearest = INFINITY;
        for (int k = 0; k < 3; ++k) {
            edge = std::max(edge, std::sqrt(CGAL::squared_distance(t.v[k].p, t.v[(k + 1) % 3].p)));
            nearest = std::min(nearest, t.v[k].dist);
        }
        return nearest + edge;
    }

    double accept_below() const
    {
        /* the floor is added to the lower side only: added to upper, accepted pieces could
         * raise upper by a floor each */
        return std::max(out.upper, (1.0 + rel) * out.lower + abs_floor);
    }

    void certify(const piece &top)
    {
        std::vector<piece> stack{top};
        while (!stack.empty()) {
            const piece t = stack.back();
            stack.pop_back();
            const double ub = std::min(convex_bound(t), lipschitz_bound(t));
            const bool accepted = ub <= accept_below();
            if (accepted || t.depth >= max_depth) {
                out.upper = std::max(out.upper, ub);
                out.pieces++;
                out.capped += !accepted;
                continue;
            }
            const corner m01 = at(mid(t.v[0].p, t.v[1].p)), m12 = at(mid(t.v[1].p, t.v[2].p)),
                         m20 = at(mid(t.v[2].p, t.v[0].p));
            const int32_t dn = t.depth + 1;
            stack.push_back(piece{{t.v[0], m01, m20}, dn});
            stack.push_back(piece{{m01, t.v[1], m12}, dn});
            stack.push_back(piece{{m20, m12, t.v[2]}, dn});
            stack.push_back(piece{{m01, m12, m20}, dn});
        }
    }
};
} // namespace

static void bound_all(bounder &b, const double *pos, const uint32_t *tri, uint32_t n_triangles)
{
    std::vector<piece> tops;
    tops.reserve(n_triangles);
    /* every triangle's corners and centroid first, so that the acceptance threshold starts near
     * h and the certification splits only where the distance is largest */
    for (uint32_t t = 0; t < n_triangles; ++t) {
        piece top;
        top.depth = 0;
        for (int k = 0; k < 3; ++k) {
            const double *x = pos + 3 * (size_t)tri[3 * t + k];
            top.v[k] = b.at(point(x[0], x[1], x[2]));
        }
        const point &a = top.v[0].p, &bb = top.v[1].p, &c = top.v[2].p;
        b.at(point((a.x() + bb.x() + c.x()) / 3.0, (a.y() + bb.y() + c.y()) / 3.0,
                   (a.z() + bb.z() + c.z()) / 3.0));
        tops.push_back(top);
    }
    for (const piece &top : tops)
        b.certify(top);
    b.out.upper = std::max(b.out.upper, b.out.lower);
}

extern "C" sw_result sw_lod_mesh_distance_bound(const sw_lod_mesh_distance *d, const double *pos,
                                                const uint32_t *tri, uint32_t n_triangles,
                                                double rel, double abs_floor, int32_t max_depth,
                                                sw_lod_mesh_bound *out, sw_status *status)
{
    bounder b{d, rel, abs_floor, max_depth, sw_lod_mesh_bound{0.0, 0.0, 0, 0}};
    *out = b.out;
    try {
        bound_all(b, pos, tri, n_triangles);
    } catch (const std::bad_alloc &) {
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "mesh distance bound: %u triangles",
                        n_triangles);
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_INTERNAL, "mesh distance bound: %s", e.what());
    }
    *out = b.out;
    sw__status_ok(status);
    return SW_OK;
}

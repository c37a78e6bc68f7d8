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
#include <map>
#include <new>
#include <utility>
#include <vector>

namespace
{
using kernel = CGAL::Simple_cartesian<double>;
using triangle = kernel::Triangle_3;
using primitive = CGAL::AABB_triangle_primitive<kernel, std::vector<triangle>::const_iterator>;
using tree_t = CGAL::AABB_tree<CGAL::AABB_traits<kernel, primitive>>;
} // namespace

namespace
{
/* A mesh lying in a plane up to `height` (the largest |distance| of its vertices from it): its
 * triangles in the plane's (u, v) coordinates and the edges that may bound their union. The union
 * R's boundary lies on edges not shared by exactly two triangles on opposite sides (an edge with
 * triangles on both sides is inside R, and so is a vertex all of whose edges are: the triangles
 * around it then close up), so a connected set that meets none of those edges and has one point
 * inside R lies wholly inside R. */
struct planar {
    bool valid = false;
    double origin[3], normal[3], u[3], v[3];
    double height = 0.0;
    double margin = 0.0;          /* (u, v) distance within which a test counts as touching */
    std::vector<double> uv;       /* 2 per vertex */
    std::vector<uint32_t> tri;    /* 3 per triangle */
    std::vector<uint32_t> edges;  /* 2 per boundary edge */
    std::vector<double> edge_box; /* 4 per boundary edge: u0, v0, u1, v1 */
};
} // namespace

struct sw_lod_mesh_distance {
    std::vector<triangle> tris;
    tree_t tree;
    planar plane;
};

namespace
{
double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Orientation of c against the line a -> b, scaled by |b - a|: a signed distance. */
double side_of(const double *a, const double *b, const double *c)
{
    const double ex = b[0] - a[0], ey = b[1] - a[1], len = std::hypot(ex, ey);
    return len > 0.0 ? (ex * (c[1] - a[1]) - ey * (c[0] - a[0])) / len : 0.0;
}

/* The plane of the largest triangle; false when the mesh is not planar within 1e-6 of its box
 * diagonal (the bound then gains nothing from it). */
bool fit_plane(const double *pos, uint32_t n_v, const uint32_t *tri, uint32_t n_t, planar &pl)
{
    double best = 0.0, lo[3] = {INFINITY, INFINITY, INFINITY},
           hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n_v; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], pos[3 * i + k]);
            hi[k] = std::max(hi[k], pos[3 * i + k]);
        }
    for (uint32_t t = 0; t < n_t; ++t) {
        const double *a = pos + 3 * (size_t)tri[3 * t], *b = pos + 3 * (size_t)tri[3 * t + 1],
                     *c = pos + 3 * (size_t)tri[3 * t + 2];
        const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                     e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double area = std::sqrt(dot3(n, n));
        if (area > best) {
            best = area;
            for (int k = 0; k < 3; ++k) {
                pl.normal[k] = n[k] / area;
                pl.origin[k] = a[k];
            }
        }
    }
    const double diag =
        std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(best > 0.0) || !std::isfinite(diag))
        return false;
    pl.height = 0.0;
    for (uint32_t i = 0; i < n_v; ++i) {
        const double d[3] = {pos[3 * i] - pl.origin[0], pos[3 * i + 1] - pl.origin[1],
                             pos[3 * i + 2] - pl.origin[2]};
        pl.height = std::max(pl.height, std::fabs(dot3(d, pl.normal)));
    }
    if (!(pl.height <= 1e-6 * diag))
        return false;
    /* (u, v): any orthonormal pair across the normal */
    const int k = std::fabs(pl.normal[0]) < 0.6 ? 0 : 1;
    double a[3] = {0.0, 0.0, 0.0};
    a[k] = 1.0;
    const double along = dot3(a, pl.normal);
    for (int i = 0; i < 3; ++i)
        pl.u[i] = a[i] - along * pl.normal[i];
    const double lu = std::sqrt(dot3(pl.u, pl.u));
    for (int i = 0; i < 3; ++i)
        pl.u[i] /= lu;
    pl.v[0] = pl.normal[1] * pl.u[2] - pl.normal[2] * pl.u[1];
    pl.v[1] = pl.normal[2] * pl.u[0] - pl.normal[0] * pl.u[2];
    pl.v[2] = pl.normal[0] * pl.u[1] - pl.normal[1] * pl.u[0];
    double far = 0.0;
    for (int i = 0; i < 3; ++i)
        far = std::max({far, std::fabs(lo[i]), std::fabs(hi[i])});
    /* the (u, v) coordinates and the predicates below round at ~1e-16 of the coordinates, and
     * so do the heights, whose bound the distances' rounding allowance (1e-14) covers */
    pl.margin = 1e-12 * (diag + far);
    pl.height += 1e-14 * 3.0 * far;
    return true;
}

void project(const planar &pl, const double p[3], double out[2])
{
    const double d[3] = {p[0] - pl.origin[0], p[1] - pl.origin[1], p[2] - pl.origin[2]};
    out[0] = dot3(d, pl.u);
    out[1] = dot3(d, pl.v);
}

/* The edges that may bound the union of the triangles (see planar). */
void find_boundary(planar &pl)
{
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> third; /* edge -> opposite */
    const size_t n_t = pl.tri.size() / 3;
    for (size_t t = 0; t < n_t; ++t)
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = pl.tri[3 * t + e], b = pl.tri[3 * t + (e + 1) % 3];
            third[{std::min(a, b), std::max(a, b)}].push_back(pl.tri[3 * t + (e + 2) % 3]);
        }
    for (const auto &[edge, opp] : third) {
        const double *a = &pl.uv[2 * (size_t)edge.first], *b = &pl.uv[2 * (size_t)edge.second];
        bool inner = opp.size() == 2;
        if (inner) {
            const double s0 = side_of(a, b, &pl.uv[2 * (size_t)opp[0]]),
                         s1 = side_of(a, b, &pl.uv[2 * (size_t)opp[1]]);
            inner = (s0 > pl.margin && s1 < -pl.margin) || (s0 < -pl.margin && s1 > pl.margin);
        }
        if (inner)
            continue;
        pl.edges.push_back(edge.first);
        pl.edges.push_back(edge.second);
        pl.edge_box.insert(pl.edge_box.end(), {std::min(a[0], b[0]), std::min(a[1], b[1]),
                                               std::max(a[0], b[0]), std::max(a[1], b[1])});
    }
}

void make_planar(const double *pos, const uint32_t *tri, uint32_t n_t, planar &pl)
{
    uint32_t n_v = 0;
    for (size_t i = 0; i < 3 * (size_t)n_t; ++i)
        n_v = std::max(n_v, tri[i] + 1);
    if (!fit_plane(pos, n_v, tri, n_t, pl))
        return;
    pl.uv.resize(2 * (size_t)n_v);
    for (uint32_t i = 0; i < n_v; ++i)
        project(pl, pos + 3 * (size_t)i, &pl.uv[2 * (size_t)i]);
    pl.tri.assign(tri, tri + 3 * (size_t)n_t);
    find_boundary(pl);
    pl.valid = true;
}

/* 1 when segment a-b and triangle t (2D) are at least `margin` apart along one of their edges'
 * normals (separating axes of two convex sets); 0 means they may touch. */
bool apart(const double *a, const double *b, const double t[3][2], double margin)
{
    const double *seg[2] = {a, b};
    double axes[4][2] = {{-(b[1] - a[1]), b[0] - a[0]}};
    for (int e = 0; e < 3; ++e) {
        const double *p = t[e], *q = t[(e + 1) % 3];
        axes[e + 1][0] = -(q[1] - p[1]);
        axes[e + 1][1] = q[0] - p[0];
    }
    for (const auto &n : axes) {
        const double len = std::hypot(n[0], n[1]);
        if (!(len > 0.0))
            continue;
        double s_lo = INFINITY, s_hi = -INFINITY, t_lo = INFINITY, t_hi = -INFINITY;
        for (const double *p : seg) {
            const double x = (n[0] * p[0] + n[1] * p[1]) / len;
            s_lo = std::min(s_lo, x);
            s_hi = std::max(s_hi, x);
        }
        for (int k = 0; k < 3; ++k) {
            const double x = (n[0] * t[k][0] + n[1] * t[k][1]) / len;
            t_lo = std::min(t_lo, x);
            t_hi = std::max(t_hi, x);
        }
        if (s_hi < t_lo - margin || t_hi < s_lo - margin)
            return true;
    }
    return false;
}

/* 1 when p lies inside triangle t (2D) by more than margin from each of its sides. */
bool inside_by(const double p[2], const double t[3][2], double margin)
{
    const double orient = side_of(t[0], t[1], t[2]);
    if (!(std::fabs(orient) > margin))
        return false;
    for (int e = 0; e < 3; ++e) {
        const double s = side_of(t[e], t[(e + 1) % 3], p);
        if (!(orient > 0.0 ? s > margin : s < -margin))
            return false;
    }
    return true;
}
} // namespace

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
        make_planar(pos, tri, n_triangles, d->plane);
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

    /* A certificate for a piece T of a planar tree mesh M (see planar) whose image in M's plane
     * lies inside the union R of M's triangles there. T's corners may lie on R's boundary (a
     * decimated level keeps its rim's vertices), so the test is made on T shrunk about its
     * centroid c by a factor 1 - s, T', kept 10 margins off T's sides: c strictly inside the
     * triangle of M nearest to it, and no edge that may bound R touching T'. Then every point p'
     * of T' stands over a point q of M, |p' - q| <= |height of p'| + M's height (the first
     * largest at a corner: the height is affine over T), and a point p of T is within
     * s |p - c| of its p' in T'. Inside R the distance to M is flat, so this bounds a piece
     * spanning many triangles of M at once, where the convex bound (one triangle) would split it
     * until each piece lies over one. INFINITY: not shown. */
    double planar_bound(const piece &t, const corner &centroid) const
    {
        const planar &pl = d->plane;
        if (!pl.valid)
            return INFINITY;
        double q[3][2], h = 0.0, reach = 0.0; /* reach: the largest |corner - c| in space */
        const double cx[3] = {centroid.p.x(), centroid.p.y(), centroid.p.z()};
        double c[2];
        project(pl, cx, c);
        for (int k = 0; k < 3; ++k) {
            const double x[3] = {t.v[k].p.x(), t.v[k].p.y(), t.v[k].p.z()},
                         off[3] = {x[0] - pl.origin[0], x[1] - pl.origin[1], x[2] - pl.origin[2]},
                         r[3] = {x[0] - cx[0], x[1] - cx[1], x[2] - cx[2]};
            project(pl, x, q[k]);
            h = std::max(h, std::fabs(dot3(off, pl.normal)) + rounding(t.v[k].p));
            reach = std::max(reach, std::sqrt(dot3(r, r)));
        }
        /* c's distance to T's nearest side line (its image's): T' = c + (1 - s)(T - c) keeps
         * s of it from T's sides */
        double inner = INFINITY;
        for (int k = 0; k < 3; ++k)
            inner = std::min(inner, std::fabs(side_of(q[k], q[(k + 1) % 3], c)));
        if (!(inner > 100.0 * pl.margin))
            return INFINITY;
        const double s = 10.0 * pl.margin / inner;
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 2; ++a) {
                q[k][a] = c[a] + (1.0 - s) * (q[k][a] - c[a]);
                lo[a] = std::min(lo[a], q[k][a] - pl.margin);
                hi[a] = std::max(hi[a], q[k][a] + pl.margin);
            }
        if (!one_point_inside(t, centroid, s))
            return INFINITY;
        for (size_t e = 0; e < pl.edges.size() / 2; ++e) {
            const double *eb = &pl.edge_box[4 * e];
            if (eb[2] < lo[0] || eb[0] > hi[0] || eb[3] < lo[1] || eb[1] > hi[1])
                continue;
            if (!apart(&pl.uv[2 * (size_t)pl.edges[2 * e]], &pl.uv[2 * (size_t)pl.edges[2 * e + 1]],
                       q, pl.margin))
                return INFINITY;
        }
        return h + pl.height + s * reach * (1.0 + 1e-12);
    }

    /* 1 when a point of T' (T shrunk by 1 - s about its centroid) lies strictly inside the
     * image of its nearest triangle of M: the centroid, else (on a side of M's triangles, as
     * on a regular grid) one of three points toward T's corners. */
    bool one_point_inside(const piece &t, const corner &centroid, double s) const
    {
        const planar &pl = d->plane;
        for (int k = -1; k < 3; ++k) {
            point p = centroid.p;
            tri_iter nearest = centroid.nearest;
            if (k >= 0) {
                const point &v = t.v[k].p;
                const double f = 0.5 * (1.0 - s); /* halfway to the corner, inside T' */
                p = point(p.x() + f * (v.x() - p.x()), p.y() + f * (v.y() - p.y()),
                          p.z() + f * (v.z() - p.z()));
                nearest = d->tree.closest_point_and_primitive(p).second;
            }
            const size_t near = (size_t)(nearest - d->tris.cbegin());
            double tc[3][2], x[2];
            for (int j = 0; j < 3; ++j) {
                tc[j][0] = pl.uv[2 * (size_t)pl.tri[3 * near + j]];
                tc[j][1] = pl.uv[2 * (size_t)pl.tri[3 * near + j] + 1];
            }
            const double px[3] = {p.x(), p.y(), p.z()};
            project(pl, px, x);
            if (inside_by(x, tc, pl.margin))
                return true;
        }
        return false;
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
    std::vector<corner> centroids;
    tops.reserve(n_triangles);
    centroids.reserve(n_triangles);
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
        centroids.push_back(
            b.at(point((a.x() + bb.x() + c.x()) / 3.0, (a.y() + bb.y() + c.y()) / 3.0,
                       (a.z() + bb.z() + c.z()) / 3.0)));
        tops.push_back(top);
    }
    for (size_t t = 0; t < tops.size(); ++t) {
        const double flat = b.planar_bound(tops[t], centroids[t]);
        if (flat <= b.accept_below()) {
            b.out.upper = std::max(b.out.upper, flat);
            b.out.pieces++;
            continue;
        }
        b.certify(tops[t]);
    }
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

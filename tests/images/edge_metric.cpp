/* SPDX-License-Identifier: MIT */
/* Edge pixels of depth images and their displacement through a Euclidean distance transform
 * (Felzenszwalb & Huttenlocher 2012); see edge_metric.hpp. */
#include "edge_metric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sw_test
{

namespace
{

/* Depth step from pixel (x, y) one further in direction (dx, dy), or NaN if it leaves the frame
 * or the neighbour is background. */
double step(const float *depth, int w, int h, int x, int y, int dx, int dy)
{
    int x1 = x + dx, y1 = y + dy;
    if (x < 0 || y < 0 || x >= w || y >= h || x1 < 0 || y1 < 0 || x1 >= w || y1 >= h)
        return NAN;
    double a = depth[(size_t)y * w + x], b = depth[(size_t)y1 * w + x1];
    return std::isfinite(a) && std::isfinite(b) ? b - a : NAN;
}

/* Is pixel (x, y) the near side of a depth discontinuity towards (x+dx, y+dy)? */
bool depth_edge(const float *depth, int w, int h, int x, int y, int dx, int dy,
                const edge_params &p)
{
    double jump = step(depth, w, h, x, y, dx, dy);
    double z = depth[(size_t)y * w + x];
    if (!(jump > p.rel * z))
        return false;
    /* The smooth depth slope on either side of the pair; a side leaving the surface has none. */
    double before = std::fabs(step(depth, w, h, x - dx, y - dy, dx, dy));
    double after = std::fabs(step(depth, w, h, x + dx, y + dy, dx, dy));
    double slope = std::fmin(std::isnan(before) ? INFINITY : before,
                             std::isnan(after) ? INFINITY : after);
    return !std::isfinite(slope) || jump > p.grad * slope;
}

bool is_edge(const float *depth, int w, int h, int x, int y, const edge_params &p)
{
    static const int dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    if (!std::isfinite(depth[(size_t)y * w + x]))
        return false;
    for (const auto &d : dirs) {
        int x1 = x + d[0], y1 = y + d[1];
        if (x1 < 0 || y1 < 0 || x1 >= w || y1 >= h)
            continue;
        if (!std::isfinite(depth[(size_t)y1 * w + x1]) || depth_edge(depth, w, h, x, y, d[0], d[1], p))
            return true;
    }
    return false;
}

/* 1D squared distance transform of f (n samples, stride) in place; v, z scratch. */
void dt_1d(float *f, int n, size_t stride, std::vector<int> &v, std::vector<double> &z,
           std::vector<double> &g)
{
    const double inf = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i)
        g[(size_t)i] = f[(size_t)i * stride];
    int k = -1;
    for (int q = 0; q < n; ++q) {
        if (!std::isfinite(g[(size_t)q]))
            continue;
        double s = -inf;
        while (k >= 0) {
            int r = v[(size_t)k];
            s = ((g[(size_t)q] + (double)q * q) - (g[(size_t)r] + (double)r * r)) / (2.0 * (q - r));
            if (s > z[(size_t)k])
                break;
            --k;
        }
        ++k;
        v[(size_t)k] = q;
        z[(size_t)k] = k == 0 ? -inf : s;
        z[(size_t)k + 1] = inf;
    }
    if (k < 0)
        return; /* nothing finite: the line stays at +INF */
    int j = 0;
    for (int q = 0; q < n; ++q) {
        while (z[(size_t)j + 1] < q)
            ++j;
        int r = v[(size_t)j];
        f[(size_t)q * stride] = (float)((double)(q - r) * (q - r) + g[(size_t)r]);
    }
}

double percentile(std::vector<double> &sorted, double q)
{
    if (sorted.empty())
        return 0.0;
    size_t i = (size_t)std::ceil(q * (double)sorted.size());
    return sorted[std::min(sorted.size() - 1, i > 0 ? i - 1 : 0)];
}

/* Both images show the same surface at (x, y), nearer than z by more than tol. */
bool agreed_nearer(const float *ours, const float *ref, int w, int h, int x, int y, double z,
                   double tol)
{
    if (x < 0 || y < 0 || x >= w || y >= h)
        return false;
    double a = ours[(size_t)y * w + x], b = ref[(size_t)y * w + x];
    return std::isfinite(a) && std::isfinite(b) && std::fabs(a - b) <= tol && a < z - tol;
}

bool is_crack(const float *ours, const float *ref, int w, int h, int x, int y, double rel)
{
    static const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    double r = ref[(size_t)y * w + x], z = ours[(size_t)y * w + x];
    if (!std::isfinite(r))
        return false;
    double tol = rel * r;
    if (!(z > r + tol))
        return false;
    for (const auto &d : dirs) {
        bool fwd = false, back = false;
        for (int a = 1; a <= 2; ++a) {
            fwd = fwd || agreed_nearer(ours, ref, w, h, x + a * d[0], y + a * d[1], z, tol);
            back = back || agreed_nearer(ours, ref, w, h, x - a * d[0], y - a * d[1], z, tol);
        }
        if (fwd && back)
            return true;
    }
    return false;
}

} // namespace

std::vector<uint8_t> crack_pixels(const float *ours, const float *ref, int w, int h, double rel)
{
    std::vector<uint8_t> c((size_t)w * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            c[(size_t)y * w + x] = is_crack(ours, ref, w, h, x, y, rel);
    return c;
}

void clear_near(std::vector<uint8_t> &marks, const std::vector<uint8_t> &mask, int w, int h)
{
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!mask[(size_t)y * w + x])
                continue;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if (x + dx >= 0 && y + dy >= 0 && x + dx < w && y + dy < h)
                        marks[(size_t)(y + dy) * w + x + dx] = 0;
        }
}

std::vector<uint8_t> edge_pixels(const float *depth, int w, int h, const edge_params &p)
{
    std::vector<uint8_t> e((size_t)w * h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            e[(size_t)y * w + x] = is_edge(depth, w, h, x, y, p);
    return e;
}

std::vector<float> distance_transform(const std::vector<uint8_t> &marks, int w, int h)
{
    std::vector<float> d(marks.size());
    for (size_t i = 0; i < marks.size(); ++i)
        d[i] = marks[i] ? 0.0f : INFINITY;
    int n = std::max(w, h);
    std::vector<int> v((size_t)n);
    std::vector<double> z((size_t)n + 1), g((size_t)n);
    for (int x = 0; x < w; ++x)
        dt_1d(&d[(size_t)x], h, (size_t)w, v, z, g);
    for (int y = 0; y < h; ++y)
        dt_1d(&d[(size_t)y * w], w, 1, v, z, g);
    for (float &f : d)
        f = std::sqrt(f);
    return d;
}

displacement measure(const std::vector<uint8_t> &from, const std::vector<uint8_t> &to, int w,
                     int h, std::vector<uint8_t> *far_px)
{
    std::vector<float> dt = distance_transform(to, w, h);
    std::vector<double> ds;
    displacement r;
    if (far_px)
        far_px->assign(from.size(), 0);
    for (size_t i = 0; i < from.size(); ++i) {
        if (!from[i])
            continue;
        double d = dt[i];
        ds.push_back(d);
        r.within1 += d <= 1.0;
        if (far_px && d > 1.0)
            (*far_px)[i] = 1;
    }
    std::sort(ds.begin(), ds.end());
    r.n = (long)ds.size();
    r.p50 = percentile(ds, 0.5);
    r.p99 = percentile(ds, 0.99);
    r.p999 = percentile(ds, 0.999);
    r.max = ds.empty() ? 0.0 : ds.back();
    return r;
}

} // namespace sw_test

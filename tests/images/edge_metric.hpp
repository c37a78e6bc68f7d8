/* SPDX-License-Identifier: MIT */
/* The image tests' edge metric: silhouette and depth-edge pixels of a depth image (coverage
 * boundary; depth discontinuities), an exact Euclidean distance transform (Felzenszwalb &
 * Huttenlocher 2012, "Distance transforms of sampled functions", lower envelope of parabolas),
 * and the displacement of one edge set against another as percentiles.
 */
#ifndef SW_TEST_EDGE_METRIC_HPP
#define SW_TEST_EDGE_METRIC_HPP

#include <cstdint>
#include <vector>

namespace sw_test
{

/* Thresholds of a depth discontinuity between 4-neighbours at depths z < z': the jump z' - z
 * must exceed rel * z and grad * (the smaller of the depth steps on either side of the pair),
 * so a surface seen at a grazing angle, whose depth grows steeply but smoothly, is no edge. */
struct edge_params {
    double rel = 0.02;
    double grad = 3.0;
};

/* Marks (1) covered pixels (finite depth) next to an uncovered 4-neighbour in the frame, and the
 * near side of each depth discontinuity. depth: w*h, row-major, +INF = background. */
std::vector<uint8_t> edge_pixels(const float *depth, int w, int h, const edge_params &p);

/* Crack pixels of `ours` against `ref` (tested elsewhere, so left out here): ours sees farther
 * than the reference (or background) by more than rel * depth, through a gap at most 3 px wide —
 * along some axis or diagonal, within 2 px on both sides, both images agree on a surface nearer
 * than what ours sees in the gap. A silhouette or depth edge that moved is one-sided (what ours
 * sees continues outward), so it is not taken for a crack. */
std::vector<uint8_t> crack_pixels(const float *ours, const float *ref, int w, int h, double rel);

/* Clears the marks within one pixel (8-neighbourhood) of a masked pixel. */
void clear_near(std::vector<uint8_t> &marks, const std::vector<uint8_t> &mask, int w, int h);

/* Distance in pixels from every pixel to the nearest marked pixel (+INF when none is marked). */
std::vector<float> distance_transform(const std::vector<uint8_t> &marks, int w, int h);

struct displacement {
    long n = 0;           /* edge pixels measured */
    long within1 = 0;     /* at distance <= 1 */
    double p50 = 0, p99 = 0, p999 = 0, max = 0;
    double frac_within1() const { return n ? (double)within1 / (double)n : 1.0; }
};

/* Distances of the pixels marked in `from` to the nearest pixel marked in `to`. When `far_px`
 * is not NULL it receives the pixels of `from` farther than 1 px. */
displacement measure(const std::vector<uint8_t> &from, const std::vector<uint8_t> &to, int w,
                     int h, std::vector<uint8_t> *far_px);

} // namespace sw_test

#endif

/* SPDX-License-Identifier: MIT */
/* bench/scaling: the plot of a scaling run, hand-written SVG — two panels over a logarithmic
 * x axis of surfaces N: frame time (median and p99, ms) and memory (peak RSS and the scene's own
 * bytes, MB). tools/splinewalk/profile_report.c's SVG is a per-frame stacked chart over a linear
 * frame axis, which does not fit.
 */
#ifndef BS_SCALING_SVG_H
#define BS_SCALING_SVG_H

#include <stdint.h>
#include <stdio.h>

typedef struct bs_point {
    double n;                 /* surfaces (x, > 0) */
    double median_ms, p99_ms; /* top panel */
    double rss_mb, scene_mb;  /* bottom panel */
} bs_point;

/* Writes the SVG of points[0..n) (n >= 1, increasing x); `title` is escaped. Returns 0, or -1 on
 * a write error. */
int bs_write_svg(FILE *f, const bs_point *points, uint32_t n, const char *title);

#endif

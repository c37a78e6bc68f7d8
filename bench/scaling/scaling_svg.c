/* SPDX-License-Identifier: MIT */
/* bench/scaling: the scaling plot (see scaling_svg.h). */
#include "scaling_svg.h"

#include <math.h>

enum { W = 720, PANEL_H = 260, LEFT = 70, RIGHT = 20, TOP = 40, GAP = 60, BOTTOM = 50 };

typedef struct axis {
    double lx0, lx1; /* log10 of the x range (whole decades) */
    double ymax;     /* linear y from 0 */
    int top;         /* panel's top pixel */
} axis;

static double x_px(const axis *a, double n)
{
    return LEFT + (log10(n) - a->lx0) / (a->lx1 - a->lx0) * (W - LEFT - RIGHT);
}

static double y_px(const axis *a, double v)
{
    return a->top + PANEL_H - v / a->ymax * PANEL_H;
}

/* 1, 2 or 5 times a power of ten, at least v / 5: about five grid lines. */
static double grid_step(double v)
{
    double p = pow(10.0, floor(log10(v / 5.0))), m = v / 5.0 / p;
    return p * (m <= 1.0 ? 1.0 : m <= 2.0 ? 2.0 : m <= 5.0 ? 5.0 : 10.0);
}

static void xml_text(FILE *f, const char *s)
{
    for (; *s; ++s) {
        if (*s == '<')
            fputs("&lt;", f);
        else if (*s == '>')
            fputs("&gt;", f);
        else if (*s == '&')
            fputs("&amp;", f);
        else
            fputc(*s, f);
    }
}

static void panel_axes(FILE *f, const axis *a, const char *ylabel)
{
    double step = grid_step(a->ymax);
    for (double y = 0.0; y <= a->ymax * 1.0001; y += step)
        fprintf(f,
                "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>"
                "<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\" font-size=\"11\">%g</text>\n",
                LEFT, y_px(a, y), W - RIGHT, y_px(a, y), LEFT - 6, y_px(a, y) + 4, y);
    for (double d = a->lx0; d <= a->lx1 + 1e-9; d += 1.0) {
        double x = x_px(a, pow(10.0, d));
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/>"
                "<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\" font-size=\"11\">10^%g</text>\n",
                x, a->top, x, a->top + PANEL_H, x, a->top + PANEL_H + 16, d);
    }
    fprintf(f,
            "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#444\"/>\n"
            "<text x=\"16\" y=\"%d\" font-size=\"12\" transform=\"rotate(-90 16 %d)\" "
            "text-anchor=\"middle\">%s</text>\n",
            LEFT, a->top, W - LEFT - RIGHT, PANEL_H, a->top + PANEL_H / 2, a->top + PANEL_H / 2,
            ylabel);
}

static void line(FILE *f, const axis *a, const bs_point *p, uint32_t n, int which,
                 const char *colour, const char *name, int legend_row)
{
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", colour);
    for (uint32_t i = 0; i < n; ++i) {
        const double v[4] = {p[i].median_ms, p[i].p99_ms, p[i].rss_mb, p[i].scene_mb};
        fprintf(f, "%.1f,%.1f ", x_px(a, p[i].n), y_px(a, v[which]));
    }
    fputs("\"/>\n", f);
    for (uint32_t i = 0; i < n; ++i) {
        const double v[4] = {p[i].median_ms, p[i].p99_ms, p[i].rss_mb, p[i].scene_mb};
        fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", x_px(a, p[i].n),
                y_px(a, v[which]), colour);
    }
    int ly = a->top + 14 + 16 * legend_row;
    fprintf(f,
            "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"/>"
            "<text x=\"%d\" y=\"%d\" font-size=\"11\">%s</text>\n",
            LEFT + 10, ly - 4, LEFT + 30, ly - 4, colour, LEFT + 36, ly, name);
}

static double max_of(const bs_point *p, uint32_t n, int a, int b)
{
    double m = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        const double v[4] = {p[i].median_ms, p[i].p99_ms, p[i].rss_mb, p[i].scene_mb};
        m = fmax(m, fmax(v[a], v[b]));
    }
    return m > 0.0 ? m * 1.1 : 1.0;
}

int bs_write_svg(FILE *f, const bs_point *p, uint32_t n, const char *title)
{
    axis a = {floor(log10(p[0].n)), ceil(log10(p[n - 1].n)), 0.0, TOP};
    if (a.lx1 <= a.lx0)
        a.lx1 = a.lx0 + 1.0;
    int h = TOP + 2 * PANEL_H + GAP + BOTTOM;
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
            "<text x=\"%d\" y=\"22\" font-size=\"14\">",
            W, h, W, h, LEFT);
    xml_text(f, title);
    fputs("</text>\n", f);
    a.ymax = max_of(p, n, 0, 1);
    panel_axes(f, &a, "frame time (ms)");
    line(f, &a, p, n, 0, "#4c8bd6", "median", 0);
    line(f, &a, p, n, 1, "#e15759", "p99", 1);
    a.top = TOP + PANEL_H + GAP;
    a.ymax = max_of(p, n, 2, 3);
    panel_axes(f, &a, "memory (MB)");
    line(f, &a, p, n, 2, "#59a14f", "peak RSS (child VmHWM delta)", 0);
    line(f, &a, p, n, 3, "#8e6bbf", "scene bytes (sw_scene_info.memory_bytes)", 1);
    fprintf(f,
            "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" font-size=\"12\">surfaces N "
            "(log scale)</text>\n</svg>\n",
            (W + LEFT) / 2, h - 8);
    return ferror(f) ? -1 : 0;
}

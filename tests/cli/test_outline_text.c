/* SPDX-License-Identifier: MIT */
/* The outline text format (tools/splinewalk/outline_text.c) against facts computed here:
 * - relative and absolute lines, H / V, implicit repeats after M and L, Z back to the start:
 *   the loops' control points, bit for bit;
 * - every loop closes bit-exactly (each curve ends where the next begins), and an open subpath is
 *   closed by a line, as SVG fills it;
 * - elliptical arcs (SVG 1.1 F.6.5): for each combination of the two flags, rotated, with radii
 *   too small (scaled up by SVG's rule): every piece is a rational quadratic of at most 90 degrees
 *   whose points (sampled at 33 parameters) lie on one ellipse of the arc's rotation and axis
 *   ratio, to 1e-12 of its size; it ends at the given point exactly; the pieces turn the way the
 *   sweep flag says; the large-arc flag picks the arc over 180 degrees (four pieces of a circle
 *   through two points one radius apart) or under (one);
 * - placement: origin, x-axis, y-axis into the row-major transform (z column their unit normal);
 * - `label` lines: the quoted text with its escapes, size, screen, align, font, defaults;
 * - mistakes are refused with FILE:LINE:COLUMN: a missing number, an unsupported command, "inf"
 *   and "0x10" as numbers, 1e999, a second `outline` without `end`, a missing `end`, path data
 *   outside a block, a NUL byte, a colour outside [0, 1], parallel axes, an empty file.
 * Planted while writing it: the centre's sign rule inverted (the other centre: the arc stays on a
 * valid ellipse, but large and small arcs swap): the piece counts fail; the closing line left out:
 * "does not close" fails for every loop. */
#include "outline_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_failures;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            printf("FAIL (line %d): ", __LINE__);                                                  \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

static int parse(const char *text, sw_outline_doc *doc, char *err, size_t n)
{
    return sw_outline_parse(text, strlen(text), "t.txt", doc, err, n);
}

static void point_of(const sw_trim_curve *c, double t, double out[2])
{
    /* de Casteljau in homogeneous form */
    double h[8][3];
    for (uint32_t i = 0; i < c->count; i++) {
        const double w = c->weights ? c->weights[i] : 1.0;
        h[i][0] = w * c->points[2 * i];
        h[i][1] = w * c->points[2 * i + 1];
        h[i][2] = w;
    }
    for (uint32_t lev = 1; lev < c->count; lev++)
        for (uint32_t i = 0; i + lev < c->count; i++)
            for (int k = 0; k < 3; k++)
                h[i][k] = (1 - t) * h[i][k] + t * h[i + 1][k];
    out[0] = h[0][0] / h[0][2];
    out[1] = h[0][1] / h[0][2];
}

static void end_point(const sw_trim_curve *c, int at_end, double out[2])
{
    const uint32_t i = at_end ? c->count - 1 : 0;
    out[0] = c->points[2 * i];
    out[1] = c->points[2 * i + 1];
}

/* Every loop of every item closes bit-exactly. */
static void check_closed(const sw_outline_doc *doc, const char *what)
{
    for (size_t i = 0; i < doc->n_items; i++)
        for (uint32_t l = 0; l < doc->items[i].shape.loop_count; l++) {
            const sw_trim_loop *lp = &doc->items[i].shape.loops[l];
            for (uint32_t k = 0; k < lp->curve_count; k++) {
                double e[2], s[2];
                end_point(&lp->curves[k], 1, e);
                end_point(&lp->curves[(k + 1) % lp->curve_count], 0, s);
                CHECK(e[0] == s[0] && e[1] == s[1],
                      "%s: item %zu loop %u does not close after curve %u: (%.17g, %.17g) vs "
                      "(%.17g, %.17g)",
                      what, i, l, k, e[0], e[1], s[0], s[1]);
            }
        }
}

static void test_lines(void)
{
    sw_outline_doc doc;
    char err[256];
    const char *t = "# comment\n"
                    "outline name a color 0.5 0.25 0 origin 1 2 3 x-axis 0 1 0 y-axis 0 0 2\n"
                    "  m 1 1 l 2 0 v 2 h -2 z   # a square\n"
                    "  M 10 10 20 10 20,20\n" /* implicit line-tos, open: closed by a line */
                    "end\n";
    CHECK(parse(t, &doc, err, sizeof err) == 0, "lines: %s", err);
    if (g_failures)
        return;
    CHECK(doc.n_items == 1 && doc.items[0].shape.loop_count == 2, "lines: %zu items", doc.n_items);
    const sw_outline_item *it = &doc.items[0];
    CHECK(!strcmp(it->name, "a") && it->line == 2, "name '%s', line %d", it->name, it->line);
    CHECK(it->color[0] == 0.5f && it->color[1] == 0.25f && it->color[2] == 0 && it->color[3] == 1,
          "colour");
    const double xf[12] = {0, 0, 1, 1, 1, 0, 0, 2, 0, 2, 0, 3};
    CHECK(!memcmp(it->transform, xf, sizeof xf), "transform");
    const sw_trim_loop *sq = &it->shape.loops[0];
    const double want[4][2] = {{1, 1}, {3, 1}, {3, 3}, {1, 3}};
    CHECK(sq->curve_count == 4, "square: %u curves", sq->curve_count);
    for (uint32_t k = 0; k < 4 && k < sq->curve_count; k++) {
        double s[2];
        end_point(&sq->curves[k], 0, s);
        CHECK(sq->curves[k].degree == 1 && s[0] == want[k][0] && s[1] == want[k][1],
              "square side %u starts at (%g, %g)", k, s[0], s[1]);
    }
    const sw_trim_loop *tri = &it->shape.loops[1];
    CHECK(tri->curve_count == 3, "open subpath: %u curves (two and the closing line)",
          tri->curve_count);
    check_closed(&doc, "lines");
    sw_outline_doc_free(&doc);
}

/* One arc from (x1, y1): its pieces on the ellipse (centre and radii solved here from the end
 * points for the unrotated case after undoing the rotation), turning as the flags say. */
static void check_arc(double rx, double ry, double rot, int large, int sweep, double x2, double y2)
{
    char text[256], err[256];
    snprintf(text, sizeof text, "outline\nM 0.5 0.25 A %g %g %g %d %d %g %g Z\nend\n", rx, ry, rot,
             large, sweep, x2, y2);
    sw_outline_doc doc;
    CHECK(parse(text, &doc, err, sizeof err) == 0, "arc: %s", err);
    if (doc.n_items != 1)
        return;
    const sw_trim_loop *lp = &doc.items[0].shape.loops[0];
    const double phi = rot * M_PI / 180;
    /* In the ellipse's own frame (rotated back by phi, v scaled by rx / ry) the arc is a circle:
     * its centre and radius from three samples, every other sample checked against them. */
    double pts[200][2];
    int n = 0;
    double turn = 0.0;
    for (uint32_t k = 0; k < lp->curve_count; k++) {
        const sw_trim_curve *c = &lp->curves[k];
        if (c->degree != 2)
            break;
        CHECK(c->weights && c->weights[1] >= cos(M_PI / 4) - 1e-15,
              "arc piece %u over 90 degrees (weight %g)", k, c->weights ? c->weights[1] : 1);
        for (int s = 0; s <= 32 && n < 200; s++) {
            double q[2];
            point_of(c, s / 32.0, q);
            const double u = cos(phi) * q[0] + sin(phi) * q[1],
                         v = -sin(phi) * q[0] + cos(phi) * q[1];
            pts[n][0] = u;
            pts[n][1] = v * rx / ry; /* now a circle */
            n++;
        }
        double a[2], e[2];
        end_point(c, 0, a);
        end_point(c, 1, e);
        double m[2];
        point_of(c, 0.5, m);
        turn += (m[0] - a[0]) * (e[1] - a[1]) - (m[1] - a[1]) * (e[0] - a[0]);
    }
    CHECK(n >= 3, "arc: no conic pieces");
    if (n < 3) {
        sw_outline_doc_free(&doc);
        return;
    }
    /* circumcentre of the first, middle and last samples */
    const double *A = pts[0], *B = pts[n / 2], *C = pts[n - 1];
    const double d = 2 * (A[0] * (B[1] - C[1]) + B[0] * (C[1] - A[1]) + C[0] * (A[1] - B[1]));
    const double a2 = A[0] * A[0] + A[1] * A[1], b2 = B[0] * B[0] + B[1] * B[1],
                 c2 = C[0] * C[0] + C[1] * C[1];
    const double cx = (a2 * (B[1] - C[1]) + b2 * (C[1] - A[1]) + c2 * (A[1] - B[1])) / d,
                 cy = (a2 * (C[0] - B[0]) + b2 * (A[0] - C[0]) + c2 * (B[0] - A[0])) / d;
    const double r = hypot(A[0] - cx, A[1] - cy);
    double worst = 0;
    for (int i = 0; i < n; i++)
        worst = fmax(worst, fabs(hypot(pts[i][0] - cx, pts[i][1] - cy) - r));
    CHECK(worst <= 1e-12 * fmax(1, r), "arc (%g %g %g %d %d): samples off the ellipse by %g", rx,
          ry, rot, large, sweep, worst);
    /* sweep 1: positive angle direction (counter-clockwise with y up) */
    CHECK((turn > 0) == (sweep == 1), "arc (%d %d): turns the wrong way", large, sweep);
    uint32_t n_arc = 0;
    while (n_arc < lp->curve_count && lp->curves[n_arc].degree == 2)
        n_arc++;
    double end[2] = {NAN, NAN};
    if (n_arc)
        end_point(&lp->curves[n_arc - 1], 1, end);
    CHECK(end[0] == x2 && end[1] == y2, "arc ends at (%.17g, %.17g), not (%g, %g)", end[0], end[1],
          x2, y2);
    check_closed(&doc, "arc");
    sw_outline_doc_free(&doc);
}

static void test_arcs(void)
{
    for (int large = 0; large <= 1; large++)
        for (int sweep = 0; sweep <= 1; sweep++) {
            check_arc(2, 1, 30, large, sweep, 1.5, 1.75);
            check_arc(0.1, 0.05, -70, large, sweep, 3, -1); /* radii scaled up (SVG) */
        }
    /* the large-arc flag: the large arc of a circle through two points 1 apart, radius 1, has
     * three or four pieces (over 180 degrees), the small one one */
    char err[256];
    sw_outline_doc a, b;
    CHECK(parse("outline\nM 0 0 A 1 1 0 1 1 1 0 Z\nend\n", &a, err, sizeof err) == 0, "%s", err);
    CHECK(parse("outline\nM 0 0 A 1 1 0 0 1 1 0 Z\nend\n", &b, err, sizeof err) == 0, "%s", err);
    CHECK(a.n_items == 1 && a.items[0].shape.loops[0].curve_count == 4 + 1, "large arc: %u curves",
          a.n_items ? a.items[0].shape.loops[0].curve_count : 0);
    CHECK(b.n_items == 1 && b.items[0].shape.loops[0].curve_count == 1 + 1, "small arc: %u curves",
          b.n_items ? b.items[0].shape.loops[0].curve_count : 0);
    sw_outline_doc_free(&a);
    sw_outline_doc_free(&b);
}

static void test_labels(void)
{
    sw_outline_doc doc;
    char err[256];
    const char *t = "outline\nM 0 0 L 1 0 L 0 1 Z\nend\n"
                    "label \"A \\\"b\\\" \\\\ c\" size 12.5 screen align end font \"/x y.ttf\" "
                    "origin 1 2 3\n"
                    "label \"plain\"\n";
    CHECK(parse(t, &doc, err, sizeof err) == 0, "labels: %s", err);
    if (doc.n_items != 3)
        return;
    const sw_outline_item *a = &doc.items[1], *b = &doc.items[2];
    CHECK(!doc.items[0].is_label && a->is_label && b->is_label, "kinds");
    CHECK(!strcmp(a->label.text, "A \"b\" \\ c"), "text '%s'", a->label.text);
    CHECK(a->label.size == 12.5 && a->label.screen_size == 1 && a->label.align == 2,
          "size %g screen %d align %d", a->label.size, a->label.screen_size, a->label.align);
    CHECK(a->label.font_path && !strcmp(a->label.font_path, "/x y.ttf"), "font");
    CHECK(a->transform[3] == 1 && a->transform[7] == 2 && a->transform[11] == 3, "origin");
    CHECK(a->shape.loop_count == 0 && a->line == 4, "a label has no loops (line %d)", a->line);
    CHECK(!strcmp(b->label.text, "plain") && b->label.size == 1.0 && !b->label.screen_size &&
              b->label.align == 0 && !b->label.font_path,
          "defaults");
    sw_outline_doc_free(&doc);
}

static void expect_error(const char *text, size_t len, const char *where, const char *needle)
{
    sw_outline_doc doc;
    char err[256];
    int bad = sw_outline_parse(text, len, "t.txt", &doc, err, sizeof err);
    CHECK(bad && doc.n_items == 0, "accepted: %s", needle);
    CHECK(strstr(err, where) == err, "'%s': message '%s' does not begin with '%s'", needle, err,
          where);
    CHECK(strstr(err, needle), "message '%s' lacks '%s'", err, needle);
    sw_outline_doc_free(&doc);
}

#define BAD(text, where, needle) expect_error(text, strlen(text), where, needle)

static void test_errors(void)
{
    BAD("outline\nM 0 0 L 1\nend\n", "t.txt:2:10:", "expected a number");
    BAD("outline\nM 0 0 S 1 1 2 2\nend\n", "t.txt:2:", "unsupported path command 'S'");
    BAD("outline\nM 0 0 L inf 1\nend\n", "t.txt:2:", "expected a number");
    BAD("outline\nM 0 0 L 0x10 1\nend\n", "t.txt:2:", "expected a");
    BAD("outline\nM 0 0 L 1e999 1\nend\n", "t.txt:2:", "out of range");
    BAD("outline\nM 0 0 L 1 1\noutline\n", "t.txt:3:", "missing 'end'");
    BAD("outline\nM 0 0 L 1 1 L 0 1\n", "t.txt:3:", "has no 'end'");
    BAD("M 0 0 L 1 1\n", "t.txt:1:", "outside an 'outline'");
    BAD("outline color 2 0 0\nM 0 0 L 1 1\nend\n", "t.txt:1:", "outside [0, 1]");
    BAD("outline x-axis 1 0 0 y-axis 2 0 0\nM 0 0 L 1 1\nend\n", "t.txt:1:", "parallel");
    BAD("outline\nL 0 0\nend\n", "t.txt:2:", "must begin with M");
    BAD("outline\nend\n", "t.txt:2:", "has no path");
    BAD("", "t.txt:1:", "no outline");
    BAD("outline bogus 1\nM 0 0 L 1 1\nend\n", "t.txt:1:", "unknown option 'bogus'");
    BAD("outline\nM 0 0 A 1 1 0 2 0 1 1\nend\n", "t.txt:2:", "flag");
    BAD("label \"abc\n", "t.txt:1:", "closing");
    BAD("label \"a\" align top\n", "t.txt:1:", "align 'top'");
    BAD("label \"a\" size -1\n", "t.txt:1:", "positive");
    BAD("label \"a\" size 0\n", "t.txt:1:", "positive");
    BAD("label \"\\q\"\n", "t.txt:1:", "escapes");
    BAD("label plain\n", "t.txt:1:", "double-quoted");
    const char nul[] = "outline\nM 0 0\0L 1 1\nend\n";
    expect_error(nul, sizeof nul - 1, "t.txt:", "NUL");
}

int main(void)
{
    test_lines();
    test_arcs();
    test_labels();
    test_errors();
    printf("outline text: %d failure(s)\n", g_failures);
    return g_failures != 0;
}

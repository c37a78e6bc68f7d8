/* SPDX-License-Identifier: MIT */
/* Glyph strings (the text module's outlines, modules/text/text_freetype.c, drawn by the outline
 * path gpu/curves.c) against exact area coverage computed here in double precision, at zooms x1
 * to x1000: no resolution limit.
 *
 * The string "Santana g&@ 08" in DejaVu Sans (quadratic TrueType outlines, holes in a, g, &, @,
 * 0, 8), em height 28 px at x1 (the whole string, ~237 px wide), rotated 0.07 rad, with a sub-pixel
 * offset, red over a dark blue 256 x 256 target; x10, x100 and x1000 about a point on the edge of
 * the 'g''s bowl. The reference: each piece flattened in pixel space until its control points are
 * within 1e-3 px of its chord, then each pixel square's area by Green's theorem
 * (tests/gpu/curves_reference.h), contours signed as the font orients them (outer and inner
 * opposite: their sum is the coverage where contours do not overlap, as in this font).
 *
 * Pass, at every zoom: along edges mean coverage error <= 2/255 and every pixel more than 1 px
 * from a corner within 12/255 (Santana's edges, as for any outline); the edge width, the pixels
 * of fractional coverage per pixel of edge length, stays within [0.5, 2] px and within 1.5x of
 * its x1 value at every zoom (a texture's edge would widen with the zoom). Also: every contour the
 * module gives closes bit-exactly and has area; a character the font lacks is counted.
 *
 * What it catches: with `plant` the renderer runs with the implicit form's sign flipped (every
 * curved piece fills its hull or nothing: 255/255 errors along every curve); a module that drops
 * its closing lines or scales by the wrong em fails the closure or the coverage. */
#include "curves_reference.h"
#include "sw_curves.h"
#include "sw_gpu.h"
#include "sw_hooks.h"
#include "sw_sg_text.h"

#include <GL/glcorearb.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 256
#define H 256
#define EM_PX 28.0
#define ROT 0.07

sw_result sw__text_freetype_outline(const char *font_path, const char *utf8, size_t len,
                                    sw_sg_text_outline *out, sw_status *status);

static int g_fail;

/* ---- the outline as the 2D path's loops ---------------------------------------------------- */

typedef struct glyphs {
    sw_sg_text_outline t;
    sw_sg_curve *curves;
    double *data; /* knots and homogeneous control points */
    sw__curves_loop *loops;
} glyphs;

static int make_glyphs(const char *text, glyphs *g)
{
    memset(g, 0, sizeof *g);
    sw_status st = {0};
    if (sw__text_freetype_outline(NULL, text, strlen(text), &g->t, &st) != SW_OK) {
        printf("FAIL: the text module: %s\n", st.message);
        return 0;
    }
    g->curves = calloc(g->t.n_pieces, sizeof *g->curves);
    g->data = calloc(g->t.n_pieces, 20 * sizeof *g->data);
    g->loops = calloc(g->t.n_contours, sizeof *g->loops);
    for (size_t i = 0; i < g->t.n_pieces; i++) {
        const sw_sg_text_piece *q = &g->t.pieces[i];
        double *k = g->data + 20 * i, *c = k + 8;
        for (uint32_t j = 0; j <= q->degree; j++) {
            k[j] = 0.0;
            k[q->degree + 1 + j] = 1.0;
            c[3 * j] = q->p[j][0];
            c[3 * j + 1] = q->p[j][1];
            c[3 * j + 2] = 1.0;
        }
        g->curves[i] = (sw_sg_curve){(int32_t)q->degree, (int32_t)q->degree + 1, 3, k, c};
    }
    for (uint32_t l = 0; l < g->t.n_contours; l++) {
        size_t first = l ? g->t.contour_end[l - 1] : 0;
        g->loops[l] = (sw__curves_loop){g->curves + first, (uint32_t)(g->t.contour_end[l] - first)};
    }
    return 1;
}

static void free_glyphs(glyphs *g)
{
    sw_sg_text_outline_free(&g->t);
    free(g->curves);
    free(g->data);
    free(g->loops);
}

/* Every contour closes bit-exactly and has area. */
static void check_contours(const glyphs *g)
{
    for (uint32_t l = 0; l < g->t.n_contours; l++) {
        size_t first = l ? g->t.contour_end[l - 1] : 0, end = g->t.contour_end[l];
        double area = 0;
        for (size_t i = first; i < end; i++) {
            const sw_sg_text_piece *q = &g->t.pieces[i],
                                   *n = &g->t.pieces[i + 1 < end ? i + 1 : first];
            if (q->p[q->degree][0] != n->p[0][0] || q->p[q->degree][1] != n->p[0][1]) {
                printf("FAIL: contour %u does not close after piece %zu\n", l, i);
                g_fail++;
            }
            for (uint32_t k = 0; k < q->degree; k++)
                area += q->p[k][0] * q->p[k + 1][1] - q->p[k + 1][0] * q->p[k][1];
        }
        if (!(fabs(area) > 1e-12)) {
            printf("FAIL: contour %u has no area\n", l);
            g_fail++;
        }
    }
}

/* ---- the reference ------------------------------------------------------------------------- */

static void to_px(const double v[6], const double p[2], double out[2])
{
    out[0] = v[0] * p[0] + v[1] * p[1] + v[2];
    out[1] = v[3] * p[0] + v[4] * p[1] + v[5];
}

/* Coverage and the edge length inside the target (px). */
static double reference(const glyphs *g, const double v[6], double *cov)
{
    memset(cov, 0, sizeof(double) * W * H);
    double length = 0;
    for (uint32_t l = 0; l < g->t.n_contours; l++) {
        size_t first = l ? g->t.contour_end[l - 1] : 0;
        ref_poly pl = {0};
        for (size_t i = first; i < g->t.contour_end[l]; i++) {
            const sw_sg_text_piece *q = &g->t.pieces[i];
            double h[12];
            for (uint32_t k = 0; k <= q->degree; k++) {
                to_px(v, q->p[k], h + 3 * k);
                h[3 * k + 2] = 1.0;
            }
            ref_flatten_bezier(h, (int)q->degree, &pl, 0);
        }
        for (size_t k = 0; k < pl.n; k++) {
            const double *a = pl.p[k], *b = pl.p[(k + 1) % pl.n];
            if (a[0] >= 1 && a[0] <= W - 1 && a[1] >= 1 && a[1] <= H - 1 && b[0] >= 1 &&
                b[0] <= W - 1 && b[1] >= 1 && b[1] <= H - 1)
                length += hypot(b[0] - a[0], b[1] - a[1]);
        }
        ref_area_accumulate(&pl, 1.0, W, H, cov);
        free(pl.p);
    }
    for (int i = 0; i < W * H; i++)
        cov[i] = fmin(fabs(cov[i]), 1.0);
    return length;
}

/* ---- one zoom ---------------------------------------------------------------------------------
 */

static double run_zoom(sw__curves_renderer *r, sw__curves_shape *shape, const glyphs *g,
                       double zoom, const double focus[2], GLuint fbo, double *edge_width)
{
    const double s = EM_PX * zoom, c = cos(ROT), sn = sin(ROT);
    double v[6] = {s * c, -s * sn, 0, s * sn, s * c, 0};
    const double centre[2] = {zoom == 1 ? 0.5 * g->t.advance : focus[0],
                              zoom == 1 ? 0.35 : focus[1]};
    v[2] = W / 2 + 0.37 - (v[0] * centre[0] + v[1] * centre[1]);
    v[5] = H / 2 + 0.21 - (v[3] * centre[0] + v[4] * centre[1]);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, W, H);
    glClearColor(0, 0, 0.25f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    sw__curves_view view = {{v[0], v[1], v[2], v[3], v[4], v[5]}, W, H};
    const float red[4] = {1, 0, 0, 1};
    sw_status st = {0};
    if (sw__curves_draw(r, shape, &view, red, fbo, &st) != SW_OK) {
        printf("FAIL: draw: %s\n", st.message);
        g_fail++;
        return 1;
    }
    static unsigned char px[W * H * 4];
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
    static double cov[W * H];
    const double length = reference(g, v, cov);
    double sum = 0, mx = 0;
    size_t n_edge = 0, n_corner = 0, fractional = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            const double got = px[4 * (j * W + i)] / 255.0, want = cov[j * W + i];
            const double err = fabs(got - want);
            fractional += got > 0.02 && got < 0.98;
            int near = 0;
            for (size_t k = 0; k < shape->n_corners && !near; k++) {
                double q[2];
                to_px(v, shape->corners[k], q);
                near = hypot(i + 0.5 - q[0], j + 0.5 - q[1]) <= 1.0;
            }
            if (near) {
                n_corner++;
                continue;
            }
            if ((want > 1e-9 && want < 1 - 1e-9) || (got > 0 && got < 1)) {
                n_edge++;
                sum += err;
            }
            mx = fmax(mx, err);
        }
    const double mean = n_edge ? sum / n_edge : 0;
    *edge_width = length > 0 ? fractional / length : 0;
    printf("  zoom x%-5g  edge px %5zu  mean %5.2f/255  max %6.2f/255  | %3zu px near corners | "
           "edge length %7.1f px, edge width %.2f px\n",
           zoom, n_edge, 255 * mean, 255 * mx, n_corner, length, *edge_width);
    if (!(mean <= 2.0 / 255 && mx <= 12.0 / 255 && n_edge > 0))
        g_fail++;
    return 0;
}

int main(int argc, char **argv)
{
    const int plant = argc > 1 && !strcmp(argv[1], "plant");
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        printf("FAIL: %s\n", st.message);
        return 1;
    }
    sw__curves_renderer *r = NULL;
    if (sw__curves_renderer_create(&r, &st) != SW_OK) {
        printf("FAIL: %s\n", st.message);
        return 1;
    }
    if (plant)
        sw__curves_renderer_set_fault(r, 1);
    glyphs g;
    if (!make_glyphs("Santana g&@ 08", &g))
        return 1;
    check_contours(&g);
    glyphs missing;
    if (make_glyphs("a\xe4\xb8\x80z", &missing)) { /* U+4E00: not in DejaVu Sans */
        if (missing.t.missing != 1 || missing.t.glyphs != 3) {
            printf("FAIL: %u of %u characters counted missing (1 of 3 expected)\n",
                   missing.t.missing, missing.t.glyphs);
            g_fail++;
        }
        free_glyphs(&missing);
    }
    printf("\"Santana g&@ 08\": %u glyphs, %u contours, %zu pieces, advance %.3f em\n", g.t.glyphs,
           g.t.n_contours, g.t.n_pieces, g.t.advance);
    sw__curves_shape *shape = NULL;
    if (sw__curves_shape_create(g.loops, g.t.n_contours, EM_PX, &shape, &st) != SW_OK) {
        printf("FAIL: shape: %s\n", st.message);
        return 1;
    }
    GLuint fbo, rb;
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    /* the focus: a point on the bowl of the 'g' (the 9th character): the middle of its first
     * contour's first curved piece */
    double focus[2] = {0.5 * g.t.advance, 0.35};
    for (size_t i = 0; i < g.t.n_pieces; i++)
        if (g.t.pieces[i].degree == 2 && g.t.pieces[i].p[0][0] > 0.55 * g.t.advance) {
            const sw_sg_text_piece *q = &g.t.pieces[i];
            focus[0] = 0.25 * q->p[0][0] + 0.5 * q->p[1][0] + 0.25 * q->p[2][0];
            focus[1] = 0.25 * q->p[0][1] + 0.5 * q->p[1][1] + 0.25 * q->p[2][1];
            break;
        }
    static const double zooms[5] = {1, 10, 100, 1000, 0.5};
    double width[5];
    for (int z = 0; z < 5; z++)
        run_zoom(r, shape, &g, zooms[z], focus, fbo, &width[z]);
    for (int z = 0; z < 4; z++)
        if (!(width[z] >= 0.5 && width[z] <= 2.0 && width[z] <= 1.5 * width[0] &&
              width[z] >= width[0] / 1.5)) {
            printf("FAIL: edge width %.2f px at x%g (x1: %.2f px)\n", width[z], zooms[z], width[0]);
            g_fail++;
        }
    printf("glyph string: %s\n", g_fail ? "FAIL" : "ok");
    sw__curves_shape_free(shape);
    free_glyphs(&g);
    sw__curves_renderer_free(r);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    sw_gpu_context_free(ctx);
    return g_fail != 0;
}

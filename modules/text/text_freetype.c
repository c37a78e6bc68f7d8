/* SPDX-License-Identifier: MIT */
/* The text module's glyph outlines (sw_sg_text.h) through FreeType: a line of UTF-8 text laid out
 * with the font's advances and kerning, each glyph's outline read unscaled and unhinted in font
 * units (FT_LOAD_NO_SCALE: the exact curves the font stores) and decomposed into lines,
 * quadratic (TrueType) and cubic (CFF) Béziers (FT_Outline_Decompose, which restores TrueType's
 * implied on-curve points), then divided by the font's units per em.
 *
 * Fill rule: the label path fills even-odd, while fonts fill non-zero. The two agree wherever a
 * glyph's contours do not overlap, as in the static fonts of Debian's font packages; a variable
 * font's or a composite glyph's overlapping contours would show their overlap as a hole.
 *
 * A FreeType library object per call: FreeType's objects are not shared between threads, and a
 * label is made once, when its node is added. */
#include "sw_hooks.h"
#include "sw_safe_read.h"
#include "sw_sg_text.h"
#include "sw_status_util.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <math.h>
#include <string.h>

#ifndef SW_TEXT_DEFAULT_FONT
#define SW_TEXT_DEFAULT_FONT "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
#endif
#define MAX_FONT_BYTES (256ull << 20)
#define MAX_CHARACTERS 4096u

typedef struct builder {
    sw_sg_text_outline *out;
    size_t cap_pieces, cap_contours;
    double scale;     /* em per font unit */
    double origin[2]; /* the glyph's origin on the line (em) */
    double cur[2];    /* the pen, em */
    size_t contour_first;
    int oom;
} builder;

static void to_em(const builder *b, const FT_Vector *v, double out[2])
{
    out[0] = b->origin[0] + b->scale * (double)v->x;
    out[1] = b->origin[1] + b->scale * (double)v->y;
}

static int push_piece(builder *b, uint32_t degree, const double (*p)[2])
{
    if (degree == 1 && p[0][0] == p[1][0] && p[0][1] == p[1][1])
        return 0; /* no length */
    sw_sg_text_outline *o = b->out;
    if (!sw__grow((void **)&o->pieces, &b->cap_pieces, o->n_pieces + 1, sizeof *o->pieces)) {
        b->oom = 1;
        return 1;
    }
    sw_sg_text_piece *q = &o->pieces[o->n_pieces++];
    q->degree = degree;
    memcpy(q->p[0], b->cur, sizeof q->p[0]); /* bit-exact joins: from where the last one ended */
    for (uint32_t k = 1; k <= degree; k++)
        memcpy(q->p[k], p[k], sizeof q->p[k]);
    memcpy(b->cur, p[degree], sizeof b->cur);
    return 0;
}

/* Twice the signed area of the contour's control polygon: zero for a contour without area (a
 * point, a hairline), which the label path would refuse. */
static double contour_area(const sw_sg_text_outline *o, size_t first, size_t end)
{
    double a = 0.0;
    for (size_t i = first; i < end; i++) {
        const sw_sg_text_piece *q = &o->pieces[i];
        for (uint32_t k = 0; k < q->degree; k++)
            a += q->p[k][0] * q->p[k + 1][1] - q->p[k + 1][0] * q->p[k][1];
    }
    return a;
}

/* Ends the contour being built: closed (the last piece ends at the first's start, exactly) and
 * kept when it has area, dropped otherwise. */
static void end_contour(builder *b)
{
    sw_sg_text_outline *o = b->out;
    if (b->oom || o->n_pieces == b->contour_first)
        return;
    const double *start = o->pieces[b->contour_first].p[0];
    if (b->cur[0] != start[0] || b->cur[1] != start[1]) {
        const double line[2][2] = {{0, 0}, {start[0], start[1]}};
        push_piece(b, 1, line);
    }
    const double em_area = fabs(contour_area(o, b->contour_first, o->n_pieces));
    if (b->oom || o->n_pieces - b->contour_first < 2 || !(em_area > 1e-12)) {
        o->n_pieces = b->contour_first;
        return;
    }
    if (!sw__grow((void **)&o->contour_end, &b->cap_contours, o->n_contours + 1,
                  sizeof *o->contour_end)) {
        b->oom = 1;
        return;
    }
    o->contour_end[o->n_contours++] = o->n_pieces;
    b->contour_first = o->n_pieces;
}

static int move_to(const FT_Vector *to, void *user)
{
    builder *b = user;
    end_contour(b);
    to_em(b, to, b->cur);
    b->contour_first = b->out->n_pieces;
    return b->oom;
}

static int line_to(const FT_Vector *to, void *user)
{
    builder *b = user;
    double p[2][2];
    to_em(b, to, p[1]);
    return push_piece(b, 1, (const double(*)[2])p) || b->oom;
}

static int conic_to(const FT_Vector *c, const FT_Vector *to, void *user)
{
    builder *b = user;
    double p[3][2];
    to_em(b, c, p[1]);
    to_em(b, to, p[2]);
    return push_piece(b, 2, (const double(*)[2])p) || b->oom;
}

static int cubic_to(const FT_Vector *c1, const FT_Vector *c2, const FT_Vector *to, void *user)
{
    builder *b = user;
    double p[4][2];
    to_em(b, c1, p[1]);
    to_em(b, c2, p[2]);
    to_em(b, to, p[3]);
    return push_piece(b, 3, (const double(*)[2])p) || b->oom;
}

/* The next code point of well-formed UTF-8 (no overlong forms, surrogates or values past
 * U+10FFFF); 0 at a malformed sequence. */
static size_t utf8_next(const unsigned char *s, size_t len, uint32_t *cp)
{
    if (len == 0)
        return 0;
    if (s[0] < 0x80) {
        *cp = s[0];
        return 1;
    }
    int n = s[0] >= 0xF0 && s[0] <= 0xF4 ? 4 : s[0] >= 0xE0 ? 3 : s[0] >= 0xC2 ? 2 : 0;
    if (n == 0 || (s[0] >= 0xF8) || (size_t)n > len)
        return 0;
    uint32_t v = s[0] & (0x7F >> n);
    for (int k = 1; k < n; k++) {
        if ((s[k] & 0xC0) != 0x80)
            return 0;
        v = (v << 6) | (s[k] & 0x3F);
    }
    static const uint32_t least[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (v < least[n] || v > 0x10FFFF || (v >= 0xD800 && v <= 0xDFFF))
        return 0;
    *cp = v;
    return (size_t)n;
}

static sw_result open_face(FT_Library lib, const char *path, FT_Face *face, sw_status *status)
{
    sw_result r = sw__in_check(path, MAX_FONT_BYTES, "font", status);
    if (r != SW_OK)
        return r;
    if (FT_New_Face(lib, path, 0, face) != 0)
        return sw__fail(status, SW_ERR_FORMAT, "%s: not a font FreeType reads", path);
    if (!FT_IS_SCALABLE(*face) || (*face)->units_per_EM == 0) {
        FT_Done_Face(*face);
        return sw__fail(status, SW_ERR_FORMAT, "%s: not a scalable (outline) font", path);
    }
    return SW_OK;
}

/* Places the characters of utf8 one after another, their outlines into b->out. */
static sw_result lay_out(FT_Face face, const char *path, const char *utf8, size_t len, builder *b,
                         sw_status *status)
{
    const FT_Outline_Funcs funcs = {move_to, line_to, conic_to, cubic_to, 0, 0};
    const unsigned char *s = (const unsigned char *)utf8;
    FT_UInt prev = 0;
    for (size_t at = 0; at < len;) {
        uint32_t cp = 0;
        size_t n = utf8_next(s + at, len - at, &cp);
        if (n == 0)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "text: byte %zu: not UTF-8", at);
        if (cp < 0x20 || cp == 0x7F)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                            "text: byte %zu: control character U+%04X (one line of text)", at, cp);
        if (++b->out->glyphs > MAX_CHARACTERS)
            return sw__fail(status, SW_ERR_LIMIT, "text: more than %u characters", MAX_CHARACTERS);
        at += n;
        FT_UInt gi = FT_Get_Char_Index(face, cp);
        b->out->missing += gi == 0;
        if (prev && gi && FT_HAS_KERNING(face)) {
            FT_Vector k;
            if (FT_Get_Kerning(face, prev, gi, FT_KERNING_UNSCALED, &k) == 0)
                b->origin[0] += b->scale * (double)k.x;
        }
        if (FT_Load_Glyph(face, gi, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP) != 0)
            return sw__fail(status, SW_ERR_FORMAT, "%s: glyph %u (U+%04X) cannot be loaded", path,
                            gi, cp);
        FT_GlyphSlot g = face->glyph;
        if (g->format == FT_GLYPH_FORMAT_OUTLINE) {
            b->contour_first = b->out->n_pieces;
            if (FT_Outline_Decompose(&g->outline, &funcs, b) != 0 && !b->oom)
                return sw__fail(status, SW_ERR_FORMAT, "%s: glyph %u (U+%04X): bad outline", path,
                                gi, cp);
            end_contour(b);
        }
        if (b->oom)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "text: out of memory");
        b->origin[0] += b->scale * (double)g->advance.x; /* unscaled: font units */
        prev = gi;
    }
    b->out->advance = b->origin[0];
    return SW_OK;
}

sw_result sw__text_freetype_outline(const char *font_path, const char *utf8, size_t len,
                                    sw_sg_text_outline *out, sw_status *status);
sw_result sw__text_freetype_outline(const char *font_path, const char *utf8, size_t len,
                                    sw_sg_text_outline *out, sw_status *status)
{
    memset(out, 0, sizeof *out);
    const char *path = font_path ? font_path : SW_TEXT_DEFAULT_FONT;
    FT_Library lib;
    if (FT_Init_FreeType(&lib) != 0)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "text: FreeType could not start");
    FT_Face face = NULL;
    sw_result r = open_face(lib, path, &face, status);
    if (r == SW_OK) {
        builder b = {.out = out, .scale = 1.0 / (double)face->units_per_EM};
        r = lay_out(face, path, utf8, len, &b, status);
        FT_Done_Face(face);
    }
    FT_Done_FreeType(lib);
    if (r != SW_OK) {
        sw__free(out->pieces);
        sw__free(out->contour_end);
        memset(out, 0, sizeof *out);
    }
    return r;
}

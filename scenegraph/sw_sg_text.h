/* SPDX-License-Identifier: MIT */
/* Text as outlines: the hook through which the text module (modules/text, FreeType) turns a line
 * of text into its glyphs' outlines, for the label nodes (sw_nodes.h SW_NODE_LABEL), which draw
 * them as planar outlines (Santana's curves, gpu/sw_curves.h). Never installed. */
#ifndef SW_SG_TEXT_H
#define SW_SG_TEXT_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One piece of a glyph's outline: a polynomial Bézier curve of degree 1 (a line), 2 (TrueType's
 * quadratic) or 3 (CFF's cubic), control points p[0..degree]. */
typedef struct sw_sg_text_piece {
    uint32_t degree;
    double p[4][2];
} sw_sg_text_piece;

/* A line of text's glyph outlines in em units (1 = the font's em), the baseline on y = 0, the
 * first glyph's origin at x = 0. Each contour is closed: every piece starts where the one before
 * ends and the last ends where the first starts, bit for bit; contours without area are left
 * out. Arrays sw__malloc'd (the core's allocator): free with sw_sg_text_outline_free. */
typedef struct sw_sg_text_outline {
    sw_sg_text_piece *pieces;
    size_t n_pieces;
    size_t *contour_end; /* contour k: pieces [contour_end[k - 1], contour_end[k]) */
    uint32_t n_contours;
    double advance;   /* the pen's advance over the whole line (em) */
    uint32_t glyphs;  /* characters placed */
    uint32_t missing; /* of them, characters the font has no glyph for (drawn as its .notdef) */
} sw_sg_text_outline;

/* font_path NULL: the module's default font. utf8: len bytes. Errors as sw_sg_text_outline. */
typedef sw_result (*sw_sg_text_fn)(const char *font_path, const char *utf8, size_t len,
                                   sw_sg_text_outline *out, sw_status *status);

/* Installs the text module's outline function (NULL: none). Any thread. */
SW_MODULE_ABI void sw_sg_text_install(sw_sg_text_fn fn);

/* The installed function's outline of utf8 (*out zeroed first, and on failure). Errors:
 * SW_ERR_UNSUPPORTED (no text module installed: sw_text_install), and the module's:
 * SW_ERR_INVALID_ARGUMENT (not UTF-8, with the byte offset; a control character), SW_ERR_NOT_FOUND
 * / SW_ERR_NOT_REGULAR_FILE / SW_ERR_LIMIT (the font file), SW_ERR_FORMAT (not a font FreeType
 * reads, or a glyph it cannot load), SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_text_outline_make(const char *font_path, const char *utf8, size_t len,
                                  sw_sg_text_outline *out, sw_status *status);
void sw_sg_text_outline_free(sw_sg_text_outline *out); /* NULL allowed */

#ifdef __cplusplus
}
#endif
#endif

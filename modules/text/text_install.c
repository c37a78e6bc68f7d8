/* SPDX-License-Identifier: MIT */
/* The text module's entry point: FreeType's glyph outlines (modules/text/text_freetype.c)
 * installed into the core's text hook (scenegraph/sw_sg_text.h), which label nodes use. */
#include "sw_sg_text.h"

#include <splinewalk/sw_text.h>

sw_result sw__text_freetype_outline(const char *font_path, const char *utf8, size_t len,
                                    sw_sg_text_outline *out, sw_status *status);

sw_result sw_text_install(void)
{
    sw_sg_text_install(sw__text_freetype_outline);
    return SW_OK;
}

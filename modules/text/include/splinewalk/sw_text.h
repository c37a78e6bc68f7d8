/* SPDX-License-Identifier: MIT */
/* splinewalk's text module (libsplinewalk_text; pkg-config splinewalk-text; CMake
 * splinewalk::text): the glyph outlines of TrueType and OpenType fonts through FreeType (FTL or
 * GPL-2), for label nodes (sw_nodes.h SW_NODE_LABEL). Without it, adding a label fails with
 * SW_ERR_UNSUPPORTED saying so. */
#ifndef SPLINEWALK_SW_TEXT_H
#define SPLINEWALK_SW_TEXT_H

#include <splinewalk/sw_result.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Hands the glyph outlines to the core. Any thread, any number of times. Returns SW_OK. */
SW_MODULE_API sw_result sw_text_install(void);

#ifdef __cplusplus
}
#endif
#endif

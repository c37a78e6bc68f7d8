/* SPDX-License-Identifier: MIT */
/* splinewalk's defaults: what a zero field of a frame description (sw_frame_desc, sw_nodes.h's and
 * sw_immediate.h's frames, the tools' options) means. One place, so that the library, the command
 * line and the documentation agree. */
#ifndef SPLINEWALK_SW_DEFAULTS_H
#define SPLINEWALK_SW_DEFAULTS_H

#define SW_DEFAULT_WIDTH 1280    /* frame width in pixels, with SW_DEFAULT_HEIGHT */
#define SW_DEFAULT_HEIGHT 720    /* frame height in pixels */
#define SW_DEFAULT_ERROR_PX 0.5  /* screen-space error bound ε_img in pixels */
#define SW_DEFAULT_FOVY_DEG 40.0 /* vertical field of view of a camera, and of the fitted presets  \
                                  */

#endif

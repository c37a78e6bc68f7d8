/* SPDX-License-Identifier: MIT */
/* splinewalk's defaults: what a zero field of a frame description (sw_frame_desc, sw_nodes.h's and
 * sw_immediate.h's frames, the tools' options) means. One place, so that the library, the command
 * line and the documentation agree. */
#ifndef SPLINEWALK_SW_DEFAULTS_H
#define SPLINEWALK_SW_DEFAULTS_H

#define SW_DEFAULT_WIDTH 1280   /* frame width in pixels, with SW_DEFAULT_HEIGHT */
#define SW_DEFAULT_HEIGHT 720   /* frame height in pixels */
#define SW_DEFAULT_ERROR_PX 0.5 /* screen-space error bound ε_img in pixels */
/* vertical field of view of a camera, and of the fitted presets */
#define SW_DEFAULT_FOVY_DEG 40.0

/* The floors of the view every front end is held to (sw_renderer_draw, sw_renderer_prepare,
 * sw_camera_matrices, node cameras, camera paths, the frame itself): a field of view below
 * SW_FOVY_MIN_DEG degrees or a screen-space error below SW_ERROR_MIN_PX pixels is refused with
 * SW_ERR_INVALID_ARGUMENT. Below them the refinement a frame asks for outgrows what the
 * arithmetic resolves: at fovy 0.01 deg a pixel of a 720-row frame spans 2.4e-7 rad, 4 float ulps
 * (2^-24 x 4) of a camera-relative position, so the GPU's float evaluation alone costs a quarter
 * of a pixel; ε_img 0.01 px asks for 50 x the triangles of the default 0.5 px. fovy >= 0.5
 * degrees and ε_img >= 0.05 px render within the bounds of every refinement loop. */
#define SW_FOVY_MIN_DEG 0.01
#define SW_ERROR_MIN_PX 0.01
/* The largest |coordinate| of a camera's eye, target and up, as of a scene's geometry: farther
 * out a double resolves less than the frame needs and the view basis's squares overflow. */
#define SW_CAMERA_COORD_MAX 1e30

#endif

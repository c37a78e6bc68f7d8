/* SPDX-License-Identifier: MIT */
/* splinewalk's image module (libsplinewalk_image; pkg-config splinewalk-image; CMake
 * splinewalk::image): frames written as OpenEXR through OpenImageIO (BSD-3-Clause): half RGBA
 * plus a float Z channel (eye-space depth). The core writes .png frames by itself; with this
 * module installed, sw_frame_desc.output_path may also end in .exr. */
#ifndef SPLINEWALK_SW_IMAGE_H
#define SPLINEWALK_SW_IMAGE_H

#include <splinewalk/sw_result.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Hands the .exr encoder to the core. Any thread, any number of times. Without it a frame whose
 * output_path ends in .exr fails with SW_ERR_UNSUPPORTED saying so. Returns SW_OK. */
SW_MODULE_API sw_result sw_image_install(void);

#ifdef __cplusplus
}
#endif
#endif

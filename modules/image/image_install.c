/* SPDX-License-Identifier: MIT */
/* The image module's entry point: OpenImageIO's .exr encoder (modules/image/image_oiio.cpp)
 * installed into the core's image writer (sw_gpu.h). */
#include "sw_gpu.h"

#include <splinewalk/sw_image.h>

sw_result sw_image_install(void)
{
    sw_gpu_image_encoder_install(sw_gpu_image_encode_oiio);
    return SW_OK;
}

/* SPDX-License-Identifier: MIT */
/* PNG encoding in the core, through stb_image_write (Debian's libstb-dev, a header compiled in
 * here): frames are written without OpenImageIO, so the core links no image library. Its
 * allocations go through the project's allocator hooks, so the bytes it returns are sw__free'd. */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"

#include <limits.h>
#include <pthread.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STBI_WRITE_NO_STDIO
#define STBIW_MALLOC(size) sw__malloc(size)
#define STBIW_REALLOC(ptr, size) sw__realloc(ptr, size)
#define STBIW_FREE(ptr) sw__free(ptr)
/* third-party code: its own warnings are not ours to fix (kept off to the end of this file:
 * "declared static but never defined" is reported there) */
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

/* stb's defaults (deflate level 8, each row's filter chosen among five) took 52 ms for a
 * 1280 x 720 frame here; level 5 (stb's lowest) with the "up" filter on every row takes 29 ms for
 * 1 % more bytes (rendered frames change little from row to row). Set once, before any encode
 * reads them. */
static pthread_once_t g_settings_once = PTHREAD_ONCE_INIT;

static void set_speed(void)
{
    stbi_write_png_compression_level = 5;
    stbi_write_force_png_filter = 2;
}

int sw__gpu_png_encode(const uint8_t *rgba, int32_t width, int32_t height, void **bytes,
                       size_t *size)
{
    *bytes = NULL;
    *size = 0;
    if (width < 1 || height < 1 || width > INT_MAX / 4)
        return 0;
    pthread_once(&g_settings_once, set_speed);
    int len = 0;
    unsigned char *png = stbi_write_png_to_mem(rgba, width * 4, width, height, 4, &len);
    if (!png || len <= 0) {
        sw__free(png);
        return 0;
    }
    *bytes = png;
    *size = (size_t)len;
    return 1;
}

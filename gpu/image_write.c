/* SPDX-License-Identifier: MIT */
/* Frame images to files (sw_gpu.h, sw_gpu_image_write): PNG encoded here, other types by the
 * installed encoder (the image module's OpenImageIO), every file then written by the project's
 * one writer (sw_safe_write.h), which replaces the target whole or not at all. */
#include "sw_gpu.h"
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_safe_write.h"
#include "sw_status_util.h"

#include <stdatomic.h>
#include <string.h>

static _Atomic(sw_gpu_image_encode_fn) g_encoder;

void sw_gpu_image_encoder_install(sw_gpu_image_encode_fn encode)
{
    atomic_store_explicit(&g_encoder, encode, memory_order_release);
}

/* The lower-case extension of path's file name without the dot, "" when it has none. */
static void lower_extension(const char *path, char *ext, size_t cap)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash : path, '.');
    size_t n = 0;
    if (dot)
        for (const char *c = dot + 1; *c && n + 1 < cap; ++c)
            ext[n++] = (char)(*c >= 'A' && *c <= 'Z' ? *c - 'A' + 'a' : *c);
    ext[n] = '\0';
}

static sw_result encode(const sw_gpu_image *img, const char *path, const char *ext, void **bytes,
                        size_t *size, sw_status *status)
{
    if (strcmp(ext, "png") == 0)
        return sw__gpu_png_encode(img->rgba, img->width, img->height, bytes, size)
                   ? SW_OK
                   : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory encoding the PNG",
                              path);
    if (strcmp(ext, "exr") != 0)
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "%s: unsupported image type '.%s' (use .png or .exr)", path, ext);
    const sw_gpu_image_encode_fn enc = atomic_load_explicit(&g_encoder, memory_order_acquire);
    if (!enc)
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "%s: writing .exr needs the image module (libsplinewalk_image: call "
                        "sw_image_install), which this program has not installed; .png needs "
                        "nothing",
                        path);
    return enc(img, path, ext, bytes, size, status);
}

sw_result sw_gpu_image_write(const sw_gpu_image *img, const char *path, sw_status *status)
{
    char ext[16];
    lower_extension(path, ext, sizeof ext);
    if (!ext[0])
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "%s: the image file name has no extension: end it in .png or .exr", path);
    if (!img->rgba || img->width < 1 || img->height < 1)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: empty image", path);
    void *bytes = NULL;
    size_t size = 0;
    sw_result r = encode(img, path, ext, &bytes, &size, status);
    if (r == SW_OK)
        r = sw__write_file(path, bytes, size, 0, status);
    sw__free(bytes);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

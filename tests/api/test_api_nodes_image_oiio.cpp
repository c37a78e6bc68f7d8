/* SPDX-License-Identifier: MIT */
// tests/api: reading a frame back for the node tests' pixel comparisons — a thin C++ shim over
// OpenImageIO (the project's image library); no exception leaves it.
#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <cstring>

#include "api_test_image.h"

unsigned char *sw_test_read_rgba(const char *path, int *width, int *height)
{
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in)
            return nullptr;
        const OIIO::ImageSpec &spec = in->spec();
        size_t n = (size_t)spec.width * (size_t)spec.height * 4;
        unsigned char *rgba = (unsigned char *)std::malloc(n);
        if (!rgba)
            return nullptr;
        std::memset(rgba, 255, n);
        int nc = spec.nchannels < 4 ? spec.nchannels : 4;
        if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, rgba, 4)) {
            std::free(rgba);
            return nullptr;
        }
        *width = spec.width;
        *height = spec.height;
        return rgba;
    } catch (...) {
        return nullptr;
    }
}

double sw_test_differing_percent(const char *a, const char *b)
{
    int wa = 0, ha = 0, wb = 0, hb = 0;
    unsigned char *pa = sw_test_read_rgba(a, &wa, &ha), *pb = sw_test_read_rgba(b, &wb, &hb);
    double percent = 100.0;
    if (pa && pb && wa == wb && ha == hb && wa > 0) {
        size_t n = (size_t)wa * (size_t)ha, differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += std::memcmp(pa + 4 * i, pb + 4 * i, 4) != 0;
        percent = 100.0 * (double)differ / (double)n;
    }
    std::free(pa);
    std::free(pb);
    return percent;
}

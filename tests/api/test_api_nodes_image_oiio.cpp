// tests/api: reading a frame back for the node tests' pixel comparisons — a thin C++ shim over
// OpenImageIO (the project's image library); no exception leaves it.
#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <cstring>

extern "C" unsigned char *sw_test_read_rgba(const char *path, int *width, int *height);

// RGBA8, top row first; NULL when the file cannot be read. The caller frees it with free().
extern "C" unsigned char *sw_test_read_rgba(const char *path, int *width, int *height)
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

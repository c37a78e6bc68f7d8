/* SPDX-License-Identifier: MIT */
// sw_png_diff A.png B.png MAX_PERCENT: how many pixels of two frames differ (any channel by any
// amount, or a different size), for the consumer test's "at most 0.1 % of pixels differ". A thin
// C++ shim over OpenImageIO (the project's image library, CONVENTIONS.md); no exception leaves it.
// Exit status: 0 within the limit, 1 beyond it (or sizes differ), 2 an unreadable image or usage.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace
{

struct image {
    int width = 0, height = 0;
    std::vector<unsigned char> rgba; // 4 channels, 8 bits, top row first
};

bool read_rgba(const char *path, image &img)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        std::fprintf(stderr, "sw_png_diff: %s: %s\n", path, OIIO::geterror().c_str());
        return false;
    }
    const OIIO::ImageSpec &spec = in->spec();
    img.width = spec.width;
    img.height = spec.height;
    img.rgba.assign((size_t)spec.width * (size_t)spec.height * 4, 255);
    // Frames are RGBA; an RGB file keeps alpha 255. Channels beyond 4 are not compared.
    int nc = spec.nchannels < 4 ? spec.nchannels : 4;
    bool ok = in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, img.rgba.data(), 4);
    if (!ok)
        std::fprintf(stderr, "sw_png_diff: %s: %s\n", path, in->geterror().c_str());
    in->close();
    return ok;
}

int compare(const char *path_a, const char *path_b, double max_percent)
{
    image a, b;
    if (!read_rgba(path_a, a) || !read_rgba(path_b, b))
        return 2;
    if (a.width != b.width || a.height != b.height) {
        std::printf("%s is %dx%d, %s is %dx%d: differ\n", path_a, a.width, a.height, path_b,
                    b.width, b.height);
        return 1;
    }
    size_t n = (size_t)a.width * (size_t)a.height, differ = 0;
    for (size_t i = 0; i < n; ++i) {
        bool same = true;
        for (size_t c = 0; c < 4; ++c)
            same = same && a.rgba[4 * i + c] == b.rgba[4 * i + c];
        differ += same ? 0 : 1;
    }
    double percent = n ? 100.0 * (double)differ / (double)n : 0.0;
    bool pass = percent <= max_percent;
    std::printf("%s vs %s: %zu of %zu pixels differ (%.4f %%, limit %g %%): %s\n", path_a, path_b,
                differ, n, percent, max_percent, pass ? "same" : "DIFFERENT");
    return pass ? 0 : 1;
}

} // namespace

int main(int argc, char **argv)
{
    char *end = nullptr;
    double limit = argc == 4 ? std::strtod(argv[3], &end) : -1.0;
    if (argc != 4 || *end != '\0' || !(limit >= 0.0) || !(limit <= 100.0)) {
        std::fprintf(stderr, "usage: sw_png_diff A.png B.png MAX_PERCENT\n");
        return 2;
    }
    try {
        return compare(argv[1], argv[2], limit);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sw_png_diff: %s\n", e.what());
    } catch (...) {
        std::fprintf(stderr, "sw_png_diff: unknown error\n");
    }
    return 2;
}

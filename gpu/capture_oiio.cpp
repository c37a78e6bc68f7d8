/* SPDX-License-Identifier: MIT */
// Frame images out through OpenImageIO: PNG (RGBA8) or OpenEXR (half RGBA plus a float Z channel
// when the frame has depth). Encoded to memory (an OIIO IOVecOutput proxy), then handed to the
// project's one writer (sw_safe_write.h), which replaces the target whole or not at all: OIIO's
// own file writes do not report a full disk. A thin C++ shim: no exception leaves it.
#include "sw_gpu.h"
#include "sw_safe_write.h"
#include "sw_status_util.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace
{

using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

std::string lower_extension(const std::string &path)
{
    size_t dot = path.find_last_of('.');
    size_t slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        return "";
    std::string e = path.substr(dot + 1);
    for (char &c : e)
        c = (char)((c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c);
    return e;
}

// Encodes the image into `bytes` (nothing touches the disk here).
sw_result write_spec(const std::string &format, std::vector<unsigned char> &bytes,
                     const ImageSpec &spec, TypeDesc type, const void *data, const char *path,
                     sw_status *status)
{
    auto out = ImageOutput::create(format);
    if (!out)
        return sw__fail(status, SW_ERR_IO, "%s: OpenImageIO has no %s writer: %s", path,
                        format.c_str(), OIIO::geterror().c_str());
    OIIO::Filesystem::IOVecOutput vec(bytes);
    if (!out->supports("ioproxy") || !out->set_ioproxy(&vec))
        return sw__fail(status, SW_ERR_INTERNAL,
                        "%s: OpenImageIO's %s writer cannot encode to memory", path,
                        format.c_str());
    if (!out->open(path, spec))
        return sw__fail(status, SW_ERR_IO, "%s: cannot start the %s encoder: %s", path,
                        format.c_str(), out->geterror().c_str());
    bool ok = out->write_image(type, data);
    std::string err = ok ? std::string() : out->geterror();
    if (!out->close() && ok) {
        ok = false;
        err = out->geterror();
    }
    if (!ok)
        return sw__fail(status, SW_ERR_IO, "%s: encoding failed: %s", path, err.c_str());
    return SW_OK;
}

sw_result write_png(const sw_gpu_image *img, std::vector<unsigned char> &bytes, const char *path,
                    sw_status *status)
{
    ImageSpec spec(img->width, img->height, 4, TypeDesc::UINT8);
    spec.attribute("png:compressionLevel", 1);
    return write_spec("png", bytes, spec, TypeDesc::UINT8, img->rgba, path, status);
}

// OpenEXR files carry a capture date (capDate), which OpenImageIO sets to the current second
// unless the spec has a DateTime. With SOURCE_DATE_EPOCH set (the reproducible-builds
// convention: seconds since 1970, UTC) that time is written instead, so the same frame gives
// the same bytes on every run; otherwise the date stays the real capture time.
void reproducible_date(ImageSpec &spec)
{
    const char *epoch = std::getenv("SOURCE_DATE_EPOCH");
    if (!epoch || !*epoch)
        return;
    char *end = nullptr;
    errno = 0;
    long long seconds = std::strtoll(epoch, &end, 10);
    if (errno != 0 || *end != '\0' || seconds < 0)
        return; // not a date: keep the real one rather than invent one
    std::time_t t = (std::time_t)seconds;
    std::tm utc;
    char text[32];
    if (!gmtime_r(&t, &utc) || !std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &utc))
        return;
    spec.attribute("DateTime", text);
}

sw_result write_exr(const sw_gpu_image *img, std::vector<unsigned char> &bytes, const char *path,
                    sw_status *status)
{
    int nc = img->depth ? 5 : 4;
    ImageSpec spec(img->width, img->height, nc, TypeDesc::HALF);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.channelformats.assign(4, TypeDesc::HALF);
    if (img->depth) {
        spec.channelnames.push_back("Z");
        spec.channelformats.push_back(TypeDesc::FLOAT);
        spec.z_channel = 4;
    }
    reproducible_date(spec);
    size_t n = (size_t)img->width * (size_t)img->height;
    std::vector<float> px(n * (size_t)nc);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c)
            px[i * (size_t)nc + (size_t)c] = (float)img->rgba[i * 4 + (size_t)c] / 255.0f;
        if (img->depth)
            px[i * (size_t)nc + 4] = img->depth[i];
    }
    return write_spec("openexr", bytes, spec, TypeDesc::FLOAT, px.data(), path, status);
}

} // namespace

extern "C" sw_result sw_gpu_image_write(const sw_gpu_image *img, const char *path,
                                        sw_status *status)
{
    try {
        std::string p(path), ext = lower_extension(p);
        bool png = ext == "png", exr = ext == "exr";
        if (ext.empty())
            return sw__fail(status, SW_ERR_UNSUPPORTED,
                            "%s: the image file name has no extension: end it in .png or .exr",
                            path);
        if (!png && !exr)
            return sw__fail(status, SW_ERR_UNSUPPORTED,
                            "%s: unsupported image type '.%s' (use .png or .exr)", path,
                            ext.c_str());
        if (!img->rgba || img->width < 1 || img->height < 1)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: empty image", path);
        std::vector<unsigned char> bytes;
        sw_result r =
            png ? write_png(img, bytes, path, status) : write_exr(img, bytes, path, status);
        if (r == SW_OK)
            r = sw__write_file(path, bytes.data(), bytes.size(), 0, status);
        if (r == SW_OK)
            sw__status_ok(status);
        return r;
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_IO, "%s: %s", path, e.what());
    } catch (...) {
        return sw__fail(status, SW_ERR_IO, "%s: unknown error writing the image", path);
    }
}

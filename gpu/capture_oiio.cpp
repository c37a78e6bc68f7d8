/* SPDX-License-Identifier: MIT */
// Frame images out through OpenImageIO: PNG (RGBA8) or OpenEXR (half RGBA plus a float Z channel
// when the frame has depth). Written to a temporary name beside the target and renamed over it
// (ARCHITECTURE.md: file safety). A thin C++ shim: no exception leaves it.
#include "sw_gpu.h"
#include "sw_status_util.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <unistd.h>
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

sw_result write_spec(const std::string &format, const std::string &tmp, const ImageSpec &spec,
                     TypeDesc type, const void *data, const char *path, sw_status *status)
{
    auto out = ImageOutput::create(format);
    if (!out)
        return sw__fail(status, SW_ERR_IO, "%s: OpenImageIO has no %s writer: %s", path,
                        format.c_str(), OIIO::geterror().c_str());
    if (!out->open(tmp, spec))
        return sw__fail(status, SW_ERR_IO, "%s: cannot create %s: %s", path, tmp.c_str(),
                        out->geterror().c_str());
    bool ok = out->write_image(type, data);
    std::string err = ok ? std::string() : out->geterror();
    if (!out->close() && ok) {
        ok = false;
        err = out->geterror();
    }
    if (!ok)
        return sw__fail(status, SW_ERR_IO, "%s: writing failed: %s", path, err.c_str());
    return SW_OK;
}

sw_result write_png(const sw_gpu_image *img, const std::string &tmp, const char *path,
                    sw_status *status)
{
    ImageSpec spec(img->width, img->height, 4, TypeDesc::UINT8);
    spec.attribute("png:compressionLevel", 1);
    return write_spec("png", tmp, spec, TypeDesc::UINT8, img->rgba, path, status);
}

sw_result write_exr(const sw_gpu_image *img, const std::string &tmp, const char *path,
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
    size_t n = (size_t)img->width * (size_t)img->height;
    std::vector<float> px(n * (size_t)nc);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c)
            px[i * (size_t)nc + (size_t)c] = (float)img->rgba[i * 4 + (size_t)c] / 255.0f;
        if (img->depth)
            px[i * (size_t)nc + 4] = img->depth[i];
    }
    return write_spec("openexr", tmp, spec, TypeDesc::FLOAT, px.data(), path, status);
}

} // namespace

extern "C" sw_result sw_gpu_image_write(const sw_gpu_image *img, const char *path,
                                        sw_status *status)
{
    try {
        std::string p(path), ext = lower_extension(p);
        bool png = ext == "png", exr = ext == "exr";
        if (!png && !exr)
            return sw__fail(status, SW_ERR_UNSUPPORTED,
                            "%s: unsupported image type '.%s' (use .png or .exr)", path,
                            ext.c_str());
        if (!img->rgba || img->width < 1 || img->height < 1)
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: empty image", path);
        std::string tmp = p + ".tmp-" + std::to_string((long)getpid());
        sw_result r = png ? write_png(img, tmp, path, status) : write_exr(img, tmp, path, status);
        if (r == SW_OK && std::rename(tmp.c_str(), p.c_str()) != 0)
            r = sw__fail(status, SW_ERR_IO, "%s: cannot rename %s over it: %s", path, tmp.c_str(),
                         std::strerror(errno));
        if (r != SW_OK)
            std::remove(tmp.c_str());
        else
            sw__status_ok(status);
        return r;
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_IO, "%s: %s", path, e.what());
    } catch (...) {
        return sw__fail(status, SW_ERR_IO, "%s: unknown error writing the image", path);
    }
}

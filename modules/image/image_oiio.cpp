/* SPDX-License-Identifier: MIT */
// The image module's encoder (sw_gpu.h, sw_gpu_image_encode_oiio): OpenEXR through OpenImageIO,
// half RGBA plus a float Z channel when the frame has depth, encoded to memory (an OIIO
// IOVecOutput proxy); sw_gpu_image_write hands the bytes to the project's one writer
// (sw_safe_write.h), since OIIO's own file writes do not report a full disk. A thin C++ shim: no
// exception leaves it.
#include "sw_gpu.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstring>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace
{

using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

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

extern "C" sw_result sw_gpu_image_encode_oiio(const sw_gpu_image *img, const char *path,
                                              const char *ext, void **bytes, size_t *size,
                                              sw_status *status)
{
    *bytes = nullptr;
    *size = 0;
    try {
        if (std::string(ext) != "exr")
            return sw__fail(status, SW_ERR_UNSUPPORTED, "%s: the image module writes .exr, not .%s",
                            path, ext);
        std::vector<unsigned char> encoded;
        sw_result r = write_exr(img, encoded, path, status);
        if (r != SW_OK)
            return r;
        void *out = sw__malloc(encoded.empty() ? 1 : encoded.size());
        if (!out)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        std::memcpy(out, encoded.data(), encoded.size());
        *bytes = out;
        *size = encoded.size();
        return SW_OK;
    } catch (const std::exception &e) {
        return sw__fail(status, SW_ERR_IO, "%s: %s", path, e.what());
    } catch (...) {
        return sw__fail(status, SW_ERR_IO, "%s: unknown error encoding the image", path);
    }
}

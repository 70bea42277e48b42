#include "encode/Encoder.h"

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstring>

#include <OpenImageIO/imageio.h>
#include <png.h>
#include <turbojpeg.h>

#include "core/Error.h"

namespace gis {

std::vector<std::uint8_t> encodeJpeg(const std::uint8_t* rgba, int width, int height, int quality) {
    tjhandle handle = tjInitCompress();
    if (!handle) throw Error("encode: tjInitCompress failed");
    unsigned char* jpeg = nullptr;
    unsigned long size = 0;
    int rc = tjCompress2(handle, rgba, width, 0, height, TJPF_RGBA, &jpeg, &size, TJSAMP_420,
                         std::clamp(quality, 1, 100), TJFLAG_FASTDCT);
    std::vector<std::uint8_t> out;
    if (rc == 0) out.assign(jpeg, jpeg + size);
    std::string error = rc == 0 ? "" : tjGetErrorStr2(handle);
    tjFree(jpeg);
    tjDestroy(handle);
    if (rc != 0) throw Error("encode: JPEG compression failed: " + error);
    return out;
}

namespace {
void pngWrite(png_structp png, png_bytep data, png_size_t length) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + length);
}
void pngFlush(png_structp) {}
} // namespace

std::vector<std::uint8_t> encodePng(const std::uint8_t* rgba, int width, int height) {
    std::vector<std::uint8_t> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) throw Error("encode: png_create_write_struct failed");
    png_infop info = png_create_info_struct(png);
    std::vector<std::uint8_t> row(static_cast<size_t>(width) * 3);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw Error("encode: PNG encoding failed");
    }
    png_set_write_fn(png, &out, pngWrite, pngFlush);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 6);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* src = rgba + static_cast<size_t>(y) * static_cast<size_t>(width) * 4;
        for (int x = 0; x < width; ++x) std::memcpy(&row[static_cast<size_t>(x) * 3], src + x * 4, 3);
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

namespace {
std::string lowerExtension(const std::string& path) {
    auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return {};
    std::string ext = path.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}
} // namespace

bool imageFileNeedsLinear(const std::string& path) { return lowerExtension(path) == "exr"; }

void writeImageFile(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba8,
                    const std::vector<float>& linear, const std::vector<std::pair<std::string, std::string>>& metadata) {
    const std::string ext = lowerExtension(path);
    if (ext != "png" && ext != "jpg" && ext != "jpeg" && ext != "exr")
        throw InputError(path, "unsupported image extension '." + ext + "': use .png, .jpg or .exr");
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(path, "cannot create an image writer: " + OIIO::geterror());
    const bool exr = ext == "exr";
    if (exr && linear.size() != static_cast<size_t>(width) * static_cast<size_t>(height) * 4)
        throw Error("encode: EXR output needs the linear frame");
    const int channels = exr ? 4 : 3;
    OIIO::ImageSpec spec(width, height, channels, exr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (exr) spec.attribute("compression", "zip");
    if (ext == "jpg" || ext == "jpeg") spec.attribute("Compression", "jpeg:92");
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    if (!out->open(path, spec)) throw InputError(path, "cannot open for writing: " + out->geterror());
    bool ok;
    if (exr) {
        ok = out->write_image(OIIO::TypeDesc::FLOAT, linear.data());
    } else {
        std::vector<std::uint8_t> rgb(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
        for (size_t i = 0, n = rgb.size() / 3; i < n; ++i) std::memcpy(&rgb[i * 3], &rgba8[i * 4], 3);
        ok = out->write_image(OIIO::TypeDesc::UINT8, rgb.data());
    }
    if (!ok || !out->close()) throw InputError(path, "write failed: " + out->geterror());
}

} // namespace gis

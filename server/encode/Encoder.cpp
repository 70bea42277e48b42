// Encoders and image files: see Encoder.h. PNG, JPEG and WebP bytes come from our own calls into
// libpng, libjpeg-turbo and libwebp; only EXR goes through OpenImageIO.
#include "encode/Encoder.h"

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>
#include <png.h>
#include <turbojpeg.h>
#include <webp/encode.h>

#include "core/EmbeddedFiles.h"
#include "core/Error.h"

namespace gis {

namespace {
std::string lowerExtension(const std::string& path) {
    auto dot = path.find_last_of('.');
    if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return {};
    std::string ext = path.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}
} // namespace

ImageCodec parseImageCodec(const std::string& name, const std::string& where) {
    std::string known;
    for (const CodecInfo& c : imageCodecs()) {
        if (name == c.name) return c.id;
        known += (known.empty() ? "" : ", ") + c.name;
    }
    throw InputError(where, "unknown image format '" + name + "' (known: " + known + ")");
}

const char* codecName(ImageCodec codec) {
    return codecInfo(codec).name.c_str();
}

const char* codecMimeType(ImageCodec codec) {
    return codecInfo(codec).mimeType.c_str();
}

std::optional<ImageCodec> codecForPath(const std::string& path) {
    const std::string ext = lowerExtension(path);
    for (const CodecInfo& c : imageCodecs())
        if (std::find(c.extensions.begin(), c.extensions.end(), ext) != c.extensions.end()) return c.id;
    return std::nullopt;
}

std::string codecExtensionList() {
    std::string out;
    for (const CodecInfo& c : imageCodecs()) out += (out.empty() ? "." : ", .") + c.extensions.front();
    return out;
}

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

bool isAscii(const std::string& s) {
    return std::all_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
}
} // namespace

namespace {
// libpng reports errors with longjmp: this frame holds no C++ object, so nothing is skipped or
// clobbered when it jumps back here.
bool writePng(png_structp png, png_infop info, const std::uint8_t* rgba, int width, int height,
              png_textp text, int textCount, std::uint8_t* row) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    // Fixed settings: the bytes are part of the contract (gi-render and the API must agree).
    png_set_compression_level(png, 6);
    if (textCount > 0) png_set_text(png, info, text, textCount);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* src = rgba + static_cast<size_t>(y) * static_cast<size_t>(width) * 4;
        for (int x = 0; x < width; ++x) std::memcpy(&row[static_cast<size_t>(x) * 3], src + x * 4, 3);
        png_write_row(png, row);
    }
    png_write_end(png, nullptr);
    return true;
}
} // namespace

std::vector<std::uint8_t> encodePng(const std::uint8_t* rgba, int width, int height,
                                    const ImageMetadata& text) {
    std::vector<std::uint8_t> out;
    std::vector<std::uint8_t> row(static_cast<size_t>(width) * 3);
    std::vector<png_text> chunks(text.size());
    for (size_t i = 0; i < text.size(); ++i) {
        png_text& t = chunks[i];
        std::memset(&t, 0, sizeof t);
        // tEXt is Latin-1; UTF-8 (scene paths, JSON with non-ASCII names) needs iTXt.
        t.compression = isAscii(text[i].second) ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
        t.key = const_cast<char*>(text[i].first.c_str());
        t.text = const_cast<char*>(text[i].second.c_str());
        t.text_length = text[i].second.size();
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) throw Error("encode: png_create_write_struct failed");
    png_infop info = png_create_info_struct(png);
    bool ok = false;
    if (info) {
        png_set_write_fn(png, &out, pngWrite, pngFlush);
        ok = writePng(png, info, rgba, width, height, chunks.data(), static_cast<int>(chunks.size()),
                      row.data());
    }
    png_destroy_write_struct(&png, &info);
    if (!ok) throw Error("encode: PNG encoding failed");
    return out;
}

namespace {
std::vector<std::uint8_t> encodeWebpWith(const std::uint8_t* rgba, int width, int height, bool lossless,
                                         int quality) {
    WebPConfig config;
    if (!WebPConfigInit(&config)) throw Error("encode: libwebp version mismatch");
    config.lossless = lossless ? 1 : 0;
    config.quality = lossless ? 75.0f : static_cast<float>(std::clamp(quality, 1, 100));
    config.thread_level = 0; // the multi-threaded encoder's output could depend on scheduling
    if (!WebPValidateConfig(&config)) throw Error("encode: invalid WebP configuration");

    WebPPicture picture;
    if (!WebPPictureInit(&picture)) throw Error("encode: libwebp version mismatch");
    picture.width = width;
    picture.height = height;
    picture.use_argb = lossless ? 1 : 0; // lossless encodes ARGB; lossy converts to YUV once
    WebPMemoryWriter writer;
    WebPMemoryWriterInit(&writer);
    picture.writer = WebPMemoryWrite;
    picture.custom_ptr = &writer;
    // RGBX import ignores the fourth byte: the frame is opaque, so no alpha plane is written.
    bool ok = WebPPictureImportRGBX(&picture, rgba, width * 4) != 0;
    ok = ok && WebPEncode(&config, &picture) != 0;
    const int error = picture.error_code;
    WebPPictureFree(&picture);
    std::vector<std::uint8_t> out;
    if (ok) out.assign(writer.mem, writer.mem + writer.size);
    WebPMemoryWriterClear(&writer);
    if (!ok) throw Error("encode: WebP encoding failed (libwebp error " + std::to_string(error) + ")");
    return out;
}
} // namespace

std::vector<std::uint8_t> encodeWebp(const std::uint8_t* rgba, int width, int height, int quality) {
    return encodeWebpWith(rgba, width, height, false, quality);
}

std::vector<std::uint8_t> encodeWebpLossless(const std::uint8_t* rgba, int width, int height) {
    return encodeWebpWith(rgba, width, height, true, 0);
}

const std::vector<CodecInfo>& imageCodecs() {
    static const std::vector<CodecInfo> table = [] {
        // Each codec's encoder, by the name protocol/codecs.json gives it.
        using Encode = decltype(CodecInfo::encode);
        const std::map<std::string, Encode> encoders = {
            {"jpeg", [](const std::uint8_t* rgba, int w, int h, int quality, bool,
                        const ImageMetadata&) { return encodeJpeg(rgba, w, h, quality); }},
            {"png", [](const std::uint8_t* rgba, int w, int h, int, bool,
                       const ImageMetadata& text) { return encodePng(rgba, w, h, text); }},
            {"webp",
             [](const std::uint8_t* rgba, int w, int h, int quality, bool exact, const ImageMetadata&) {
                 return exact ? encodeWebpLossless(rgba, w, h) : encodeWebp(rgba, w, h, quality);
             }},
        };
        const auto text = findEmbedded(embedded::codecs(), "codecs.json");
        GIS_ASSERT_MSG(text.has_value(), "protocol/codecs.json is not embedded");
        std::vector<CodecInfo> rows;
        const nlohmann::json doc = nlohmann::json::parse(*text); // kept: the loop reads into it
        for (const auto& row : doc.at("codecs")) {
            CodecInfo c{static_cast<ImageCodec>(row.at("id").get<int>()),
                        row.at("name").get<std::string>(),
                        row.at("mime").get<std::string>(),
                        row.at("extensions").get<std::vector<std::string>>(),
                        row.at("lossy").get<bool>(),
                        row.at("lossless").get<bool>(),
                        nullptr};
            const auto encoder = encoders.find(c.name);
            GIS_ASSERT_MSG(encoder != encoders.end(), "protocol/codecs.json names codec '" + c.name +
                                                          "', which Encoder.cpp cannot encode");
            c.encode = encoder->second;
            rows.push_back(std::move(c));
        }
        GIS_ASSERT_MSG(!rows.empty(), "protocol/codecs.json lists no codecs");
        return rows;
    }();
    return table;
}

const CodecInfo& codecInfo(ImageCodec codec) {
    for (const CodecInfo& c : imageCodecs())
        if (c.id == codec) return c;
    GIS_ASSERT_MSG(false,
                   "codec " + std::to_string(static_cast<int>(codec)) + " has no row in imageCodecs()");
    std::abort();
}

std::vector<std::uint8_t> encodeImage(ImageCodec codec, const std::uint8_t* rgba, int width, int height,
                                      int quality, const ImageMetadata& pngText, bool exact) {
    return codecInfo(codec).encode(rgba, width, height, quality, exact, pngText);
}

bool imageFileNeedsLinear(const std::string& path) {
    return lowerExtension(path) == "exr";
}

void writeBinaryFile(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(path, "cannot open for writing");
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    f.close();
    if (!f) throw InputError(path, "write failed");
}

void writeImageFile(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba8,
                    const std::vector<float>& linear, const ImageMetadata& metadata, int quality) {
    const std::string ext = lowerExtension(path);
    if (auto codec = codecForPath(path)) {
        if (rgba8.size() != static_cast<size_t>(width) * static_cast<size_t>(height) * 4)
            throw Error("encode: image size does not match the RGBA8 frame");
        writeBinaryFile(path, encodeImage(*codec, rgba8.data(), width, height, quality, metadata));
        return;
    }
    if (ext != "exr")
        throw InputError(path, "unsupported image extension '." + ext + "': use " + codecExtensionList() +
                                   " or .exr");
    if (linear.size() != static_cast<size_t>(width) * static_cast<size_t>(height) * 4)
        throw Error("encode: EXR output needs the linear frame");
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(path, "cannot create an image writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    if (!out->open(path, spec)) throw InputError(path, "cannot open for writing: " + out->geterror());
    if (!out->write_image(OIIO::TypeDesc::FLOAT, linear.data()) || !out->close())
        throw InputError(path, "write failed: " + out->geterror());
}

} // namespace gis

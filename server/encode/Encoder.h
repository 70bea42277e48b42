// Frame encoding: JPEG through libjpeg-turbo (the streaming path), PNG through libpng (lossless
// stills), WebP through libwebp (lossy or lossless), and image files. Every tone-mapped file goes
// through these encoders, never through a library that adds timestamps or its own metadata, so the
// same frame gives the same bytes from gi-render and from the HTTP API.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace gis {

/// The codecs of encoded frames; the values are the codec byte of the binary frame header
/// (protocol/PROTOCOL.md).
enum class ImageCodec : std::uint8_t { Jpeg = 1, Png = 2, Webp = 3 };

/// Text chunks of a PNG file, (keyword, text) in order. Keywords: 1..79 printable Latin-1 characters.
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

/// Everything about one codec, one row of protocol/codecs.json (embedded) paired with its encoder: the
/// encoder, the CLI's file names, the protocol's and the API's names and the HTTP type all read it;
/// the protocol schemas' codec lists and the client's header table are generated from the same file
/// (client/tools/update-schemas.mjs) and checked (tests/unit/encode/CodecTableTest.cpp).
struct CodecInfo {
    ImageCodec id;                       ///< also the binary frame header's codec byte
    std::string name;                    ///< "jpeg": hello.codecs, snapshot.codec, the API's format
    std::string mimeType;                ///< "image/jpeg"
    std::vector<std::string> extensions; ///< lower case, without the dot; the first is the one suggested
    bool lossy;                          ///< encodes at a quality 1..100 (what the stream uses)
    bool lossless;                       ///< can encode without loss (what a snapshot may ask for)
    /// RGBA8 rows top to bottom -> bytes. `quality` for lossy encoding; `exact` asks for the lossless
    /// mode of a codec that has both; `text` for codecs with text chunks (PNG).
    std::vector<std::uint8_t> (*encode)(const std::uint8_t* rgba, int width, int height, int quality,
                                        bool exact, const ImageMetadata& text);
};

/// Every codec, in the order of their ids.
const std::vector<CodecInfo>& imageCodecs();
const CodecInfo& codecInfo(ImageCodec codec);

/// A codec by its name (exactly). Throws InputError(where, ...) listing the names.
ImageCodec parseImageCodec(const std::string& name, const std::string& where = {});
/// "jpeg", "png", "webp".
const char* codecName(ImageCodec codec);
/// "image/jpeg", "image/png", "image/webp".
const char* codecMimeType(ImageCodec codec);
/// The codec a file name's extension calls for (any case); nullopt otherwise.
std::optional<ImageCodec> codecForPath(const std::string& path);
/// ".png, .jpg, .webp" (the suggested extensions), for messages about file names.
std::string codecExtensionList();

/// Quality of the lossy codecs when nobody asks for another: the HTTP API's default and what image
/// files written by writeImageFile use, so that both give the same bytes.
constexpr int kDefaultImageQuality = 90;

/// RGBA8 rows top to bottom -> JPEG (alpha dropped). quality in [1, 100]. Throws gis::Error.
std::vector<std::uint8_t> encodeJpeg(const std::uint8_t* rgba, int width, int height, int quality);
/// RGBA8 rows top to bottom -> PNG (RGB, alpha dropped: frames are opaque). `text` becomes tEXt
/// chunks (iTXt for text that is not ASCII) before the image data. The bytes depend only on the
/// arguments: no time chunk, fixed compression settings. Throws gis::Error.
std::vector<std::uint8_t> encodePng(const std::uint8_t* rgba, int width, int height,
                                    const ImageMetadata& text = {});
/// RGBA8 rows top to bottom -> lossy WebP (RGB, alpha dropped) at quality 1..100 (clamped).
/// Deterministic (single-threaded encoder). Throws gis::Error.
std::vector<std::uint8_t> encodeWebp(const std::uint8_t* rgba, int width, int height, int quality);
/// RGBA8 rows top to bottom -> lossless WebP (RGB, alpha dropped). Throws gis::Error.
std::vector<std::uint8_t> encodeWebpLossless(const std::uint8_t* rgba, int width, int height);

/// Encodes with `codec` (its row's encode): JPEG and WebP lossy at `quality` (1..100, clamped), PNG
/// lossless with `pngText` (ignored by the other codecs); with `exact`, WebP's lossless mode. Throws
/// gis::Error.
std::vector<std::uint8_t> encodeImage(ImageCodec codec, const std::uint8_t* rgba, int width, int height,
                                      int quality, const ImageMetadata& pngText = {}, bool exact = false);

/// Writes a tone-mapped RGBA8 image or linear radiance, chosen by the file extension:
///  - .png: encodePng with `metadata` as text chunks;
///  - .jpg/.jpeg and .webp: encodeJpeg and encodeWebp (lossy) at `quality` (metadata dropped);
///  - .exr: linear radiance from `linear` (RGBA float) through OpenImageIO, `metadata` in the header.
/// The first three write exactly the bytes encodeImage returns. Throws gis::InputError naming the path
/// for unknown extensions or I/O errors.
void writeImageFile(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgba8,
                    const std::vector<float>& linear, const ImageMetadata& metadata = {},
                    int quality = kDefaultImageQuality);

/// Writes `bytes` to `path` as they are (binary). Throws gis::InputError naming the path.
void writeBinaryFile(const std::string& path, const std::vector<std::uint8_t>& bytes);

/// True when `path` ends in an extension writeImageFile needs linear data for (.exr).
bool imageFileNeedsLinear(const std::string& path);

} // namespace gis

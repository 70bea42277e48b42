// Encoders (encode/Encoder.h): codec names, deterministic PNG bytes with text chunks, WebP lossy and
// lossless, and image files carrying exactly the encoder's bytes. Decoding goes through OpenImageIO.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include "core/Error.h"
#include "encode/Encoder.h"

namespace {

constexpr int kW = 37, kH = 23; // odd sizes: row padding and chroma subsampling edges

std::vector<std::uint8_t> testImage() {
    std::vector<std::uint8_t> rgba(static_cast<size_t>(kW) * kH * 4);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            std::uint8_t* p = &rgba[(static_cast<size_t>(y) * kW + x) * 4];
            p[0] = static_cast<std::uint8_t>(x * 255 / (kW - 1));
            p[1] = static_cast<std::uint8_t>(y * 255 / (kH - 1));
            p[2] = static_cast<std::uint8_t>((x * 7 + y * 13) % 256);
            p[3] = static_cast<std::uint8_t>(x * 3); // must be ignored: frames are opaque
        }
    return rgba;
}

std::string tempPath(const std::string& name) {
    // CTest runs the cases in parallel processes: names carry the process id.
    return (std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name)).string();
}

std::vector<std::uint8_t> readBytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// Decodes `bytes` (written to a file named like `name`) to RGB8; empty on failure.
std::vector<std::uint8_t> decode(const std::vector<std::uint8_t>& bytes, const std::string& name, int& w,
                                 int& h, int& channels) {
    const std::string path = tempPath(name);
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    w = in->spec().width;
    h = in->spec().height;
    channels = in->spec().nchannels;
    std::vector<std::uint8_t> all(static_cast<size_t>(w) * h * channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, all.data())) return {};
    in->close();
    std::filesystem::remove(path);
    std::vector<std::uint8_t> rgb(static_cast<size_t>(w) * h * 3);
    for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = all[i * channels + std::min(c, channels - 1)];
    return rgb;
}

std::vector<std::uint8_t> rgbOf(const std::vector<std::uint8_t>& rgba) {
    std::vector<std::uint8_t> rgb;
    for (size_t i = 0; i < rgba.size(); i += 4) rgb.insert(rgb.end(), rgba.begin() + i, rgba.begin() + i + 3);
    return rgb;
}

double meanAbsDifference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) sum += std::abs(int(a[i]) - int(b[i]));
    return sum / static_cast<double>(a.size());
}

/// `text` at `offset` of `data`, byte for byte.
bool bytesAt(const std::vector<std::uint8_t>& data, size_t offset, const std::string& text) {
    if (data.size() < offset + text.size()) return false;
    for (size_t i = 0; i < text.size(); ++i)
        if (data[offset + i] != static_cast<unsigned char>(text[i])) return false;
    return true;
}

bool containsBytes(const std::vector<std::uint8_t>& data, const std::string& text) {
    return std::search(data.begin(), data.end(), text.begin(), text.end()) != data.end();
}

TEST(Encoder, CodecNames) {
    for (auto c : {gis::ImageCodec::Jpeg, gis::ImageCodec::Png, gis::ImageCodec::Webp})
        EXPECT_EQ(gis::parseImageCodec(gis::codecName(c)), c);
    EXPECT_EQ(static_cast<int>(gis::ImageCodec::Jpeg), 1); // the frame header's codec byte
    EXPECT_EQ(static_cast<int>(gis::ImageCodec::Png), 2);
    EXPECT_EQ(static_cast<int>(gis::ImageCodec::Webp), 3);
    EXPECT_STREQ(gis::codecMimeType(gis::ImageCodec::Jpeg), "image/jpeg");
    EXPECT_STREQ(gis::codecMimeType(gis::ImageCodec::Png), "image/png");
    EXPECT_STREQ(gis::codecMimeType(gis::ImageCodec::Webp), "image/webp");
    try {
        gis::parseImageCodec("gif", "/format");
        FAIL() << "gif accepted";
    } catch (const gis::InputError& e) {
        EXPECT_EQ(e.where(), "/format");
        for (const char* name : {"jpeg", "png", "webp"})
            EXPECT_NE(e.reason().find(name), std::string::npos) << e.reason();
    }
    EXPECT_EQ(gis::codecForPath("a/b.PNG"), gis::ImageCodec::Png);
    EXPECT_EQ(gis::codecForPath("x.jpg"), gis::ImageCodec::Jpeg);
    EXPECT_EQ(gis::codecForPath("x.jpeg"), gis::ImageCodec::Jpeg);
    EXPECT_EQ(gis::codecForPath("x.webp"), gis::ImageCodec::Webp);
    EXPECT_FALSE(gis::codecForPath("x.exr").has_value());
    EXPECT_FALSE(gis::codecForPath("dir.png/x").has_value());
}

TEST(Encoder, PngIsLosslessDeterministicAndCarriesText) {
    const auto rgba = testImage();
    const gis::ImageMetadata text = {{"gi:scene", "builtin:cornell"}, {"gi:note", "gr\xc3\xbc\xc3\x9f"}};
    const auto a = gis::encodePng(rgba.data(), kW, kH, text);
    const auto b = gis::encodePng(rgba.data(), kW, kH, text);
    EXPECT_EQ(a, b);
    ASSERT_GT(a.size(), 8u);
    EXPECT_TRUE(bytesAt(a, 0, "\x89PNG\r\n\x1a\n"));
    EXPECT_TRUE(containsBytes(a, "tEXtgi:scene")) << "ASCII text as tEXt";
    EXPECT_TRUE(containsBytes(a, "iTXtgi:note")) << "UTF-8 text as iTXt";
    EXPECT_FALSE(containsBytes(a, "tIME")) << "no time chunk: the bytes must not depend on the clock";
    EXPECT_NE(a, gis::encodePng(rgba.data(), kW, kH)) << "text chunks are optional";

    int w = 0, h = 0, channels = 0;
    const auto rgb = decode(a, "enc.png", w, h, channels);
    EXPECT_EQ(w, kW);
    EXPECT_EQ(h, kH);
    EXPECT_EQ(channels, 3);
    EXPECT_EQ(rgb, rgbOf(rgba));
}

TEST(Encoder, WebpLosslessRoundTrips) {
    const auto rgba = testImage();
    const auto bytes = gis::encodeWebpLossless(rgba.data(), kW, kH);
    ASSERT_GT(bytes.size(), 16u);
    EXPECT_TRUE(bytesAt(bytes, 0, "RIFF"));
    EXPECT_TRUE(bytesAt(bytes, 8, "WEBP"));
    EXPECT_TRUE(bytesAt(bytes, 12, "VP8L"));
    EXPECT_EQ(bytes, gis::encodeWebpLossless(rgba.data(), kW, kH));
    int w = 0, h = 0, channels = 0;
    const auto rgb = decode(bytes, "enc_lossless.webp", w, h, channels);
    EXPECT_EQ(w, kW);
    EXPECT_EQ(h, kH);
    EXPECT_EQ(rgb, rgbOf(rgba));
}

TEST(Encoder, WebpLossyFollowsQuality) {
    const auto rgba = testImage();
    const auto high = gis::encodeWebp(rgba.data(), kW, kH, 95);
    const auto low = gis::encodeWebp(rgba.data(), kW, kH, 5);
    EXPECT_TRUE(bytesAt(high, 0, "RIFF"));
    EXPECT_TRUE(bytesAt(high, 8, "WEBPVP8 ")) << "lossy, no alpha chunk";
    EXPECT_EQ(high, gis::encodeWebp(rgba.data(), kW, kH, 95));
    EXPECT_LT(low.size(), high.size());
    int w = 0, h = 0, channels = 0;
    const auto rgb = decode(high, "enc_lossy.webp", w, h, channels);
    EXPECT_EQ(w, kW);
    EXPECT_EQ(h, kH);
    ASSERT_EQ(rgb.size(), rgbOf(rgba).size());
    EXPECT_LT(meanAbsDifference(rgb, rgbOf(rgba)), 12.0);
}

TEST(Encoder, EncodeImageDispatches) {
    const auto rgba = testImage();
    const auto jpeg = gis::encodeImage(gis::ImageCodec::Jpeg, rgba.data(), kW, kH, 80);
    EXPECT_EQ(jpeg, gis::encodeJpeg(rgba.data(), kW, kH, 80));
    EXPECT_EQ(jpeg[0], 0xFF);
    EXPECT_EQ(jpeg[1], 0xD8);
    EXPECT_EQ(gis::encodeImage(gis::ImageCodec::Png, rgba.data(), kW, kH, 80, {{"k", "v"}}),
              gis::encodePng(rgba.data(), kW, kH, {{"k", "v"}}));
    EXPECT_EQ(gis::encodeImage(gis::ImageCodec::Webp, rgba.data(), kW, kH, 80),
              gis::encodeWebp(rgba.data(), kW, kH, 80));
}

TEST(Encoder, ImageFilesHoldTheEncodersBytes) {
    const auto rgba = testImage();
    const gis::ImageMetadata meta = {{"gi:technique", "none"}};
    const std::string png = tempPath("enc_file.png"), webp = tempPath("enc_file.webp"),
                      jpg = tempPath("enc_file.JPG");
    gis::writeImageFile(png, kW, kH, rgba, {}, meta);
    gis::writeImageFile(webp, kW, kH, rgba, {}, meta);
    gis::writeImageFile(jpg, kW, kH, rgba, {}, meta, 70);
    EXPECT_EQ(readBytes(png), gis::encodePng(rgba.data(), kW, kH, meta));
    EXPECT_EQ(readBytes(webp), gis::encodeWebp(rgba.data(), kW, kH, gis::kDefaultImageQuality));
    EXPECT_EQ(readBytes(jpg), gis::encodeJpeg(rgba.data(), kW, kH, 70));
    for (const auto& p : {png, webp, jpg}) std::filesystem::remove(p);
    EXPECT_THROW(gis::writeImageFile(tempPath("enc_file.bmp"), kW, kH, rgba, {}), gis::InputError);
    EXPECT_THROW(gis::writeImageFile("/nonexistent-dir/x.png", kW, kH, rgba, {}), gis::InputError);
}

} // namespace

// The codec table is protocol/codecs.json paired with Encoder.cpp's encoders: names, types and file
// extensions derive from it, and the protocol's schemas and the client's frame-header table (written
// from the same file by client/tools/update-schemas.mjs) must list exactly its codecs, so a row added
// without regenerating them fails here, naming the file.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "encode/Encoder.h"

namespace gis {
namespace {

std::string readSource(const std::string& relative) {
    std::ifstream in(std::string(GIS_SOURCE_DIR) + "/" + relative, std::ios::binary);
    EXPECT_TRUE(in) << relative;
    return std::string(std::istreambuf_iterator<char>(in), {});
}

std::set<std::string> enumOf(const nlohmann::json& schema) {
    std::set<std::string> names;
    for (const auto& v : schema.at("enum")) names.insert(v.get<std::string>());
    return names;
}

std::set<std::string> names(bool (*keep)(const CodecInfo&)) {
    std::set<std::string> out;
    for (const CodecInfo& c : imageCodecs())
        if (keep(c)) out.insert(c.name);
    return out;
}

TEST(CodecTable, TheRowsAreProtocolCodecsJson) {
    const auto file = nlohmann::json::parse(readSource("protocol/codecs.json"))["codecs"];
    ASSERT_EQ(file.size(), imageCodecs().size());
    for (std::size_t i = 0; i < file.size(); ++i) {
        const CodecInfo& c = imageCodecs()[i];
        EXPECT_EQ(file[i]["id"], static_cast<int>(c.id));
        EXPECT_EQ(file[i]["name"], c.name);
        EXPECT_EQ(file[i]["mime"], c.mimeType);
        EXPECT_EQ(file[i]["extensions"], c.extensions);
        EXPECT_EQ(file[i]["lossy"], c.lossy);
        EXPECT_EQ(file[i]["lossless"], c.lossless);
        EXPECT_NE(c.encode, nullptr);
    }
    // The codecs the code names exist.
    EXPECT_EQ(codecInfo(ImageCodec::Jpeg).name, "jpeg");
    EXPECT_EQ(codecInfo(ImageCodec::Png).name, "png");
    EXPECT_EQ(codecInfo(ImageCodec::Webp).name, "webp");
}

TEST(CodecTable, NamesTypesAndExtensionsComeFromTheRows) {
    std::set<int> ids;
    for (const CodecInfo& c : imageCodecs()) {
        EXPECT_TRUE(ids.insert(static_cast<int>(c.id)).second) << c.name << ": ids are unique";
        EXPECT_EQ(parseImageCodec(c.name), c.id);
        EXPECT_EQ(codecName(c.id), c.name);
        EXPECT_EQ(codecMimeType(c.id), c.mimeType);
        EXPECT_TRUE(c.lossy || c.lossless) << c.name;
        ASSERT_FALSE(c.extensions.empty()) << c.name;
        for (const std::string& ext : c.extensions) {
            EXPECT_EQ(codecForPath("frame." + ext), c.id) << ext;
            std::string upper = ext;
            std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
            EXPECT_EQ(codecForPath("dir.d/FRAME." + upper), c.id) << upper;
        }
    }
    EXPECT_EQ(codecForPath("frame.exr"), std::nullopt);
    EXPECT_EQ(codecForPath("dir.png/frame"), std::nullopt);
    EXPECT_EQ(codecExtensionList(), ".jpg, .png, .webp");
    EXPECT_THROW(parseImageCodec("gif", "/format"), InputError);
    try {
        parseImageCodec("gif", "/format");
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "/format: unknown image format 'gif' (known: jpeg, png, webp)");
    }
}

TEST(CodecTable, EveryRowEncodesItsOwnFormat) {
    const std::vector<std::uint8_t> rgba(16 * 8 * 4, 128);
    for (const CodecInfo& c : imageCodecs()) {
        for (bool exact : {false, true}) {
            const std::vector<std::uint8_t> bytes = encodeImage(c.id, rgba.data(), 16, 8, 80, {}, exact);
            ASSERT_GT(bytes.size(), 12u) << c.name;
            const std::string head(bytes.begin(), bytes.begin() + 12);
            if (c.id == ImageCodec::Jpeg) {
                EXPECT_EQ(head.substr(0, 3), "\xFF\xD8\xFF");
            }
            if (c.id == ImageCodec::Png) {
                EXPECT_EQ(head.substr(1, 3), "PNG");
            }
            if (c.id == ImageCodec::Webp) {
                EXPECT_EQ(head.substr(8, 4), "WEBP");
                // VP8L is the lossless bitstream, VP8 the lossy one.
                const std::string chunk(bytes.begin() + 12, bytes.begin() + 16);
                EXPECT_EQ(chunk, exact ? "VP8L" : "VP8 ");
            }
        }
    }
}

TEST(CodecTable, ProtocolSchemasListExactlyTheTablesCodecs) {
    const auto all = names([](const CodecInfo&) { return true; });
    const auto lossless = names([](const CodecInfo& c) { return c.lossless; });
    const auto hello = nlohmann::json::parse(readSource("protocol/schema/hello.json"));
    EXPECT_EQ(enumOf(hello["properties"]["codecs"]["items"]), all)
        << "protocol/schema/hello.json: codecs lists every codec (then run client/tools/update-schemas.mjs)";
    const auto snapshot = nlohmann::json::parse(readSource("protocol/schema/snapshot.json"));
    EXPECT_EQ(enumOf(snapshot["properties"]["codec"]), lossless)
        << "protocol/schema/snapshot.json: codec lists the lossless codecs";
    const auto request = nlohmann::json::parse(readSource("protocol/http/render_request.json"));
    EXPECT_EQ(enumOf(request["properties"]["format"]), all)
        << "protocol/http/render_request.json: format lists every codec";
}

TEST(CodecTable, TheClientCarriesTheCurrentTable) {
    // client/schemas.js: export const CODEC_TABLE = Object.freeze([...]); (one line, generated)
    const std::string js = readSource("client/schemas.js");
    const std::string marker = "export const CODEC_TABLE = Object.freeze(";
    const auto at = js.find(marker);
    ASSERT_NE(at, std::string::npos)
        << "client/schemas.js has no CODEC_TABLE: run node client/tools/update-schemas.mjs";
    const auto end = js.find(");", at);
    const auto table = nlohmann::json::parse(js.substr(at + marker.size(), end - at - marker.size()));
    EXPECT_EQ(table, nlohmann::json::parse(readSource("protocol/codecs.json"))["codecs"])
        << "client/schemas.js differs from protocol/codecs.json: run node client/tools/update-schemas.mjs";
}

} // namespace
} // namespace gis

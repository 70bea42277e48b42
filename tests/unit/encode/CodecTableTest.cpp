// The codec table (imageCodecs) is the one place a codec is described: names, types and file
// extensions derive from it, and the protocol's schemas and the client's frame-header table must list
// exactly its codecs, so adding a row without them fails here, naming the file to change.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <regex>
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

TEST(CodecTable, NamesTypesAndExtensionsComeFromTheRows) {
    std::set<int> ids;
    for (const CodecInfo& c : imageCodecs()) {
        EXPECT_TRUE(ids.insert(static_cast<int>(c.id)).second) << c.name << ": ids are unique";
        EXPECT_EQ(parseImageCodec(c.name), c.id);
        EXPECT_STREQ(codecName(c.id), c.name);
        EXPECT_STREQ(codecMimeType(c.id), c.mimeType);
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

TEST(CodecTable, ClientDecodesEveryCodecByItsHeaderByte) {
    // client/protocol.js: export const CODECS = Object.freeze({ 1: 'jpeg', 2: 'png', 3: 'webp' });
    const std::string js = readSource("client/protocol.js");
    std::smatch table;
    ASSERT_TRUE(
        std::regex_search(js, table, std::regex(R"(export const CODECS = Object\.freeze\(\{([^}]*)\}\))")))
        << "client/protocol.js has no CODECS table";
    std::map<int, std::string> client;
    const std::string body = table[1];
    const std::regex entry(R"((\d+)\s*:\s*'([a-z0-9]+)')");
    for (auto it = std::sregex_iterator(body.begin(), body.end(), entry); it != std::sregex_iterator(); ++it)
        client[std::stoi((*it)[1])] = (*it)[2];
    std::map<int, std::string> server;
    for (const CodecInfo& c : imageCodecs()) server[static_cast<int>(c.id)] = c.name;
    EXPECT_EQ(client, server) << "client/protocol.js: CODECS maps each header byte to the table's name";
}

} // namespace
} // namespace gis

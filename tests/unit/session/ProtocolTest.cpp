// The shared vectors in protocol/vectors: valid ones pass, invalid ones fail with an error code.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "session/ProtocolMessages.h"

namespace fs = std::filesystem;

namespace {
std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}
std::vector<fs::path> vectors(const char* kind) {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(fs::path(GIS_SOURCE_DIR) / "protocol/vectors" / kind))
        if (e.path().extension() == ".json") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}
} // namespace

TEST(Protocol, ValidVectorsAreAccepted) {
    auto files = vectors("valid");
    ASSERT_GE(files.size(), 9u);
    for (const auto& f : files) {
        try {
            auto msg = gis::parseClientMessage(readFile(f));
            EXPECT_TRUE(msg.contains("type")) << f;
        } catch (const gis::ProtocolError& e) {
            ADD_FAILURE() << f << ": " << e.code << " " << e.message;
        }
    }
}

TEST(Protocol, InvalidVectorsAreRejectedWithACode) {
    auto files = vectors("invalid");
    ASSERT_GE(files.size(), 10u);
    for (const auto& f : files) {
        try {
            gis::parseClientMessage(readFile(f));
            ADD_FAILURE() << f << " was accepted";
        } catch (const gis::ProtocolError& e) {
            EXPECT_FALSE(e.code.empty()) << f;
            EXPECT_FALSE(e.message.empty()) << f;
        }
    }
}

TEST(Protocol, ErrorsCarryCodeAndPointer) {
    try {
        gis::parseClientMessage(R"({"type":"resize","size":[8,8]})");
        FAIL();
    } catch (const gis::ProtocolError& e) {
        EXPECT_EQ(e.code, "invalid_message");
        EXPECT_EQ(e.where, "/size/0");
        EXPECT_EQ(e.request, "resize");
    }
    try {
        gis::parseClientMessage("{not json");
        FAIL();
    } catch (const gis::ProtocolError& e) {
        EXPECT_EQ(e.code, "invalid_json");
    }
    try {
        gis::parseClientMessage(R"({"type":"teleport"})");
        FAIL();
    } catch (const gis::ProtocolError& e) {
        EXPECT_EQ(e.code, "unknown_type");
    }
    auto m = gis::errorMessage({"invalid_message", "bad", "/x", "camera"});
    EXPECT_EQ(m["type"], "error");
    EXPECT_EQ(m["where"], "/x");
}

TEST(Protocol, FrameHeaderLayout) {
    std::vector<std::uint8_t> payload = {0xFF, 0xD8, 0xFF, 0xD9};
    auto m = gis::makeFrameMessage(0x01020304u, 640, 480, gis::FrameCodec::Jpeg, payload);
    ASSERT_EQ(m.size(), gis::kFrameHeaderSize + payload.size());
    EXPECT_EQ(std::string(m.begin(), m.begin() + 4), "GIFR");
    EXPECT_EQ(m[4], 0x04);
    EXPECT_EQ(m[7], 0x01);
    EXPECT_EQ(m[8] | (m[9] << 8), 640);
    EXPECT_EQ(m[10] | (m[11] << 8), 480);
    EXPECT_EQ(m[12], 1);
    EXPECT_EQ(m[16], 0xFF);
}

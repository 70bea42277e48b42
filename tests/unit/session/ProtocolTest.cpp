// The shared vectors in protocol/vectors: valid ones pass, invalid ones fail with an error code.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/JsonSchema.h"
#include "session/ProtocolMessages.h"
#include "session/Session.h"

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
    auto m = gis::makeFrameMessage(0x01020304u, 640, 480, gis::ImageCodec::Jpeg, payload);
    ASSERT_EQ(m.size(), gis::kFrameHeaderSize + payload.size());
    EXPECT_EQ(std::string(m.begin(), m.begin() + 4), "GIFR");
    EXPECT_EQ(m[4], 0x04);
    EXPECT_EQ(m[7], 0x01);
    EXPECT_EQ(m[8] | (m[9] << 8), 640);
    EXPECT_EQ(m[10] | (m[11] << 8), 480);
    EXPECT_EQ(m[12], 1);
    EXPECT_EQ(m[16], 0xFF);
}

TEST(Protocol, EverySchemaIsAClientMessageTypeAndViceVersa) {
    std::vector<std::string> schemas;
    for (const auto& e : fs::directory_iterator(fs::path(GIS_SOURCE_DIR) / "protocol/schema"))
        if (e.path().extension() == ".json") schemas.push_back(e.path().stem().string());
    std::sort(schemas.begin(), schemas.end());
    auto types = gis::clientMessageTypes();
    std::sort(types.begin(), types.end());
    EXPECT_EQ(schemas, types);
}

TEST(Protocol, FrameHeaderCarriesTheWebpCode) {
    auto m = gis::makeFrameMessage(7, 16, 16, gis::ImageCodec::Webp, {1, 2, 3});
    EXPECT_EQ(m[12], 3);
    EXPECT_EQ(m.size(), gis::kFrameHeaderSize + 3);
}

// Found by the protocol fuzzer: the JSON parser's message quotes the byte it stopped at, and an
// invalid UTF-8 byte there made errorMessage(...).dump() throw (a terminate in the server's callback).
TEST(Protocol, ErrorsQuotingInvalidUtf8StaySerialisable) {
    const std::string text = "{\"type\":\"technique\",\"name\":\"rsm_gather\"\xfd\n";
    try {
        (void)gis::parseClientMessage(text);
        FAIL() << "accepted malformed JSON";
    } catch (const gis::ProtocolError& e) {
        EXPECT_EQ(e.code, "invalid_json");
        std::string dumped;
        EXPECT_NO_THROW(dumped = gis::errorMessage(e).dump());
        EXPECT_NE(dumped.find("\\\\xFD"), std::string::npos) << dumped;
    }
    EXPECT_EQ(gis::validUtf8("caf\xc3\xa9 \xe2\x82\xac"), "caf\xc3\xa9 \xe2\x82\xac"); // valid UTF-8 kept
    EXPECT_EQ(gis::validUtf8("a\xc3"), "a\\xC3");                                      // truncated
    EXPECT_EQ(gis::validUtf8("\xc0\xaf"), "\\xC0\\xAF");                               // overlong
    EXPECT_EQ(gis::validUtf8("\xed\xa0\x80"), "\\xED\\xA0\\x80");                      // surrogate
}

TEST(Protocol, EveryServerMessageHasASchemaAndViceVersa) {
    std::vector<std::string> schemas;
    for (const auto& e : fs::directory_iterator(fs::path(GIS_SOURCE_DIR) / "protocol/schema/server"))
        if (e.path().extension() == ".json") schemas.push_back(e.path().stem().string());
    std::sort(schemas.begin(), schemas.end());
    auto types = gis::serverMessageTypes();
    std::sort(types.begin(), types.end());
    EXPECT_EQ(schemas, types);
}

TEST(Protocol, TheMessageTableSaysWhoSendsAndWhoAnswers) {
    std::vector<std::string> viewers, connection;
    for (const auto& m : gis::clientMessages()) {
        if (m.viewers) viewers.push_back(m.type);
        if (m.connection) connection.push_back(m.type);
    }
    std::sort(viewers.begin(), viewers.end());
    std::sort(connection.begin(), connection.end());
    EXPECT_EQ(viewers, (std::vector<std::string>{"ack", "hello", "ping", "snapshot"}));
    EXPECT_EQ(connection, (std::vector<std::string>{"ack", "hello", "ping"}));
    ASSERT_NE(gis::findClientMessage("camera"), nullptr);
    EXPECT_FALSE(gis::findClientMessage("camera")->viewers);
    EXPECT_EQ(gis::findClientMessage("welcome"), nullptr) << "a server message";
}

TEST(Protocol, ServerMessagesAreCheckedAgainstTheirSchemas) {
    EXPECT_EQ(gis::checkServerMessage(gis::errorMessage({"busy", "the server is full", "", "hello"})), "");
    EXPECT_EQ(gis::checkServerMessage({{"type", "pong"}, {"t", 3.5}}), "");
    EXPECT_NE(gis::checkServerMessage({{"type", "pong"}, {"t", "soon"}}), "");
    EXPECT_EQ(gis::checkServerMessage({{"type", "progress"},
                                       {"state", "loading"},
                                       {"step", "scene"},
                                       {"share", 0.4},
                                       {"eta_ms", 120.0},
                                       {"reason", "loading x.glb: decoding images: 1 of 3"}}),
              "");
    EXPECT_NE(gis::checkServerMessage({{"type", "progress"}, {"state", "rendering"}}), "");
    EXPECT_NE(gis::checkServerMessage({{"type", "camera"}}).find("not a server message"), std::string::npos);
}

TEST(Protocol, TheSessionHandlesExactlyTheSessionRows) {
    std::vector<std::string> rows;
    for (const auto& m : gis::clientMessages())
        if (!m.connection) rows.push_back(m.type);
    std::sort(rows.begin(), rows.end());
    auto handled = gis::Session::messageTypes();
    std::sort(handled.begin(), handled.end());
    EXPECT_EQ(handled, rows) << "protocol/messages.json's session rows and Session's handlers";
}

#include <gtest/gtest.h>

#include "core/JsonSchema.h"

using nlohmann::json;

namespace {
const json kSchema = json::parse(R"({
  "type": "object", "required": ["type", "size"], "additionalProperties": false,
  "properties": {
    "type": {"const": "resize"},
    "size": {"type": "array", "items": {"type": "integer", "minimum": 16, "maximum": 4096},
             "minItems": 2, "maxItems": 2},
    "note": {"type": "string", "maxLength": 4}
  }
})");
}

TEST(JsonSchema, AcceptsConformingInstances) {
    EXPECT_FALSE(gis::validateJson(json::parse(R"({"type":"resize","size":[64,32]})"), kSchema));
}

TEST(JsonSchema, ReportsPointerAndReason) {
    auto v = gis::validateJson(json::parse(R"({"type":"resize","size":[64,"a"]})"), kSchema);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->pointer, "/size/1");
    EXPECT_NE(v->message.find("integer"), std::string::npos);

    v = gis::validateJson(json::parse(R"({"type":"resize"})"), kSchema);
    ASSERT_TRUE(v);
    EXPECT_NE(v->message.find("'size'"), std::string::npos);

    v = gis::validateJson(json::parse(R"({"type":"resize","size":[64,8]})"), kSchema);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->pointer, "/size/1");

    v = gis::validateJson(json::parse(R"({"type":"resize","size":[64,64],"extra":1})"), kSchema);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->pointer, "/extra");

    v = gis::validateJson(json::parse(R"({"type":"resize","size":[64,64,64]})"), kSchema);
    ASSERT_TRUE(v);
    v = gis::validateJson(json::parse(R"({"type":"resize","size":[64,64],"note":"toolong"})"), kSchema);
    ASSERT_TRUE(v);
    v = gis::validateJson(json::parse(R"([1,2])"), kSchema);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->pointer, "");
}

// Hostile input (issue #17): nesting is refused before any recursive code sees it, and error
// excerpts stay short whatever the value.
TEST(JsonLimits, FindsTheFirstBracketPastTheDepthLimit) {
    EXPECT_FALSE(gis::findExcessNesting(R"({"a":[1,{"b":[]}]})", 4));
    EXPECT_EQ(gis::findExcessNesting(R"({"a":[1,{"b":[]}]})", 3), 13u);
    EXPECT_FALSE(gis::findExcessNesting("", 1));
    EXPECT_FALSE(gis::findExcessNesting("[]", 1));
    EXPECT_EQ(gis::findExcessNesting("[[]]", 1), 1u);
}

TEST(JsonLimits, BracketsInsideStringsDoNotCount) {
    EXPECT_FALSE(gis::findExcessNesting(R"({"a":"[[[[{{{{"})", 1));
    EXPECT_FALSE(gis::findExcessNesting(R"({"a":"\"[[[["})", 1)); // escaped quote keeps the string open
    EXPECT_EQ(gis::findExcessNesting(R"({"a":"\\",  "b":[[]]})", 2), 17u); // "\\" closes the string
}

TEST(JsonLimits, DeepDocumentsAreRefusedWithTheOffset) {
    const std::string deep = "{\"scene\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
    std::string error;
    const json parsed = gis::parseJsonExplained(deep, error);
    EXPECT_TRUE(parsed.is_discarded());
    EXPECT_NE(error.find("nested deeper than 64 levels at byte 73"), std::string::npos) << error;
    // At the limit it parses.
    const std::string ok = std::string(64, '[') + std::string(64, ']');
    EXPECT_FALSE(gis::parseJsonExplained(ok, error).is_discarded()) << error;
    EXPECT_TRUE(gis::parseJsonExplained("[" + ok + "]", error).is_discarded());
}

TEST(JsonLimits, ExcerptsAreBoundedAndValidUtf8) {
    json big = json::array();
    for (int i = 0; i < 10000; ++i) big.push_back({{"key" + std::to_string(i), std::string(1000, 'x')}});
    const std::string e = gis::jsonExcerpt(big, 60);
    EXPECT_LE(e.size(), 60u);
    EXPECT_EQ(e.substr(e.size() - 3), "...");
    json deep = 1;
    for (int i = 0; i < 60; ++i) deep = json::array({deep});
    EXPECT_EQ(gis::jsonExcerpt(deep, 200), "[[[[...]]]]");
    const std::string accents = gis::jsonExcerpt(json(std::string(100, '\xC3') + "\xA9"), 21);
    EXPECT_EQ(gis::validUtf8(accents), accents);
    EXPECT_EQ(gis::jsonExcerpt(json{{"a", 1}}), R"({"a":1})");
}

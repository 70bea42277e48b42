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

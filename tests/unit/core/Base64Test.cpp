#include <gtest/gtest.h>

#include "core/Base64.h"

namespace gis {
namespace {

TEST(Base64, RoundTripsEveryLengthAndByte) {
    std::string bytes;
    for (int i = 0; i < 300; ++i) {
        const std::string encoded = base64Encode(bytes);
        EXPECT_EQ(encoded.size() % 4, 0u);
        const auto decoded = base64Decode(encoded);
        ASSERT_TRUE(decoded.has_value()) << i;
        EXPECT_EQ(*decoded, bytes);
        bytes += static_cast<char>(i * 7);
    }
    EXPECT_EQ(base64Encode("glTF"), "Z2xURg==");
    EXPECT_EQ(base64Decode("Z2xURg==").value(), "glTF");
}

TEST(Base64, RefusesWhatIsNotBase64) {
    EXPECT_FALSE(base64Decode("abc"));      // not a multiple of 4
    EXPECT_FALSE(base64Decode("ab$d"));     // outside the alphabet
    EXPECT_FALSE(base64Decode("a=bc"));     // padding before data
    EXPECT_FALSE(base64Decode("ab=c"));     // data after padding
    EXPECT_FALSE(base64Decode("ab==abcd")); // padding not at the end
    EXPECT_FALSE(base64Decode("ab c"));     // whitespace
    EXPECT_TRUE(base64Decode("").has_value());
}

} // namespace
} // namespace gis

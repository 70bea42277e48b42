// The command-line helpers the three executables share: numbers with their range in the message, an
// option table whose help and parse come from one declaration, and main()'s exit codes.
#include <stdexcept>

#include <gtest/gtest.h>

#include "core/CommandLine.h"

namespace gis::cli {
namespace {

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(CommandLine, NumbersAreCheckedWholeAndInRange) {
    EXPECT_EQ(parseInteger("--n", "42", 1, 100), 42);
    EXPECT_EQ(errorOf([] { parseInteger("--n", "42x", 1, 100); }),
              "--n: must be an integer in [1, 100], got '42x'");
    EXPECT_EQ(errorOf([] { parseInteger("--n", "0", 1, 100); }),
              "--n: must be an integer in [1, 100], got '0'");
    EXPECT_EQ(errorOf([] { parseInteger("--n", "99999999999999999999", 1, 100); }),
              "--n: must be an integer in [1, 100], got '99999999999999999999'");
    EXPECT_DOUBLE_EQ(parseNumber("--f", "0.25", 0.1, 1), 0.25);
    EXPECT_EQ(errorOf([] { parseNumber("--f", "nan", 0, 1); }), "--f: must be a number in [0, 1], got 'nan'");
    EXPECT_EQ(errorOf([] { parseNumber("--f", "2", 0.1, 1); }), "--f: must be a number in [0.1, 1], got '2'");
    int w = 0, h = 0;
    parseSize("--size", "640x480", 4096, w, h);
    EXPECT_EQ(w, 640);
    EXPECT_EQ(h, 480);
    EXPECT_EQ(errorOf([&] { parseSize("--size", "640", 4096, w, h); }),
              "--size: must look like 512x512, got '640'");
    EXPECT_EQ(errorOf([&] { parseSize("--size", "640x8000", 4096, w, h); }),
              "--size height: must be an integer in [16, 4096], got '8000'");
}

TEST(CommandLine, ListsSplitAndJoin) {
    EXPECT_EQ(splitList("a,,b,"), (std::vector<std::string>{"a", "b"}));
    EXPECT_EQ(joinList({"a", "b"}), "a, b");
    EXPECT_EQ(joinList({"a", "b"}, ","), "a,b");
    EXPECT_EQ(numberText(0.5), "0.5");
    EXPECT_EQ(numberText(8192), "8192");
    EXPECT_EQ(numberText(1e7), "10000000") << "whole numbers in full";
    EXPECT_EQ(numberText(-3), "-3");
}

TEST(CommandLine, OptionTableHelpAndParseComeFromOneDeclaration) {
    int frames = 3;
    double scale = 0.5;
    bool quiet = false;
    std::string scene;
    OptionTable t;
    t.value("--scene", "NAME", "the scene", [&](const std::string& v) { scene = v; })
        .integer("--frames", "N", "frames to time", 1, 100, frames)
        .number("--scale", "F", "size factor", 0.1, 1, scale)
        .section("Quiet:")
        .flag("--quiet", "only errors", [&] { quiet = true; });
    const std::string usage = t.usage(60);
    EXPECT_NE(usage.find("  --frames N            frames to time, 1..100 (default 3)\n"), std::string::npos)
        << usage;
    EXPECT_NE(usage.find("size factor, 0.1..1 (default 0.5)"), std::string::npos) << usage;
    EXPECT_NE(usage.find("\nQuiet:\n  --quiet"), std::string::npos) << usage;
    EXPECT_TRUE(OptionTable::asksForHelp({"--frames", "0", "-h"})) << "help wins over a bad value";
    EXPECT_FALSE(OptionTable::asksForHelp({"--scene", "help"}));
    EXPECT_TRUE(t.has("--quiet"));
    EXPECT_FALSE(t.has("Quiet:"));

    t.parse({"--scene", "builtin:cornell", "--frames", "7", "--quiet", "--scale", "1"});
    EXPECT_EQ(scene, "builtin:cornell");
    EXPECT_EQ(frames, 7);
    EXPECT_DOUBLE_EQ(scale, 1.0);
    EXPECT_TRUE(quiet);
    EXPECT_EQ(errorOf([&] {
                  t.parse({"--frames", "0"});
              }),
              "--frames: must be an integer in [1, 100], got '0'");
    EXPECT_EQ(errorOf([&] { t.parse({"--frobnicate"}); }), "unknown option '--frobnicate' (see --help)");
    EXPECT_EQ(errorOf([&] { t.parse({"--scene"}); }), "--scene needs a value (NAME)");
}

TEST(CommandLine, LongHelpWrapsUnderItsColumn) {
    OptionTable t;
    t.flag("--a-very-long-option-name", "one two three four five six seven eight nine ten", [] {});
    const std::string usage = t.usage(40);
    // 16 columns of text beside the 24-column option column.
    EXPECT_EQ(usage, "  --a-very-long-option-name\n"
                     "                        one two three\n"
                     "                        four five six\n"
                     "                        seven eight nine\n"
                     "                        ten\n");
}

TEST(CommandLine, MainTurnsErrorsIntoExitCodes) {
    EXPECT_EQ(runMain("t", [] { return 0; }), 0);
    EXPECT_EQ(runMain("t", []() -> int { throw UsageError("bad"); }), 2);
    EXPECT_EQ(runMain("t", []() -> int { throw InputError("--x", "bad"); }), 2);
    EXPECT_EQ(runMain("t", []() -> int { throw std::runtime_error("broken"); }), 1);
}

} // namespace
} // namespace gis::cli

// The drain setting and the generated configuration reference (docs/operations.md embeds it).
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>

#include "core/Error.h"
#include "net/ServerOptions.h"

namespace {
std::map<std::string, std::string> gDrainEnv;
const char* drainEnv(const char* name) {
    auto it = gDrainEnv.find(name);
    return it == gDrainEnv.end() ? nullptr : it->second.c_str();
}
} // namespace

TEST(ServerDrain, DefaultFlagEnvironmentAndRange) {
    gDrainEnv.clear();
    EXPECT_EQ(gis::parseServerArgs({}, drainEnv).config.drainSeconds, 20);
    EXPECT_EQ(gis::parseServerArgs({"--drain-seconds", "0"}, drainEnv).config.drainSeconds, 0);
    gDrainEnv = {{"GI_DRAIN_SECONDS", "45"}};
    auto parsed = gis::parseServerArgs({}, drainEnv);
    EXPECT_EQ(parsed.config.drainSeconds, 45);
    EXPECT_EQ(parsed.sources["--drain-seconds"], "env GI_DRAIN_SECONDS");
    gDrainEnv.clear();
    try {
        gis::parseServerArgs({"--drain-seconds", "3601"}, drainEnv);
        FAIL() << "3601 must be refused";
    } catch (const gis::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("[0, 3600]"), std::string::npos) << e.what();
    }
}

TEST(ServerDrain, ConfigReferenceFlagStopsParsing) {
    gDrainEnv = {{"GI_PORT", "not a number"}}; // not looked at: the reference needs no valid settings
    const auto parsed = gis::parseServerArgs({"--config-reference"}, drainEnv);
    EXPECT_TRUE(parsed.configReference);
    gDrainEnv.clear();
}

TEST(ServerDrain, ConfigReferenceHasOneWellFormedRowPerOption) {
    const std::string reference = gis::serverConfigReference();
    std::istringstream lines(reference);
    std::string line;
    int rows = 0;
    while (std::getline(lines, line)) {
        // Four cells: five bars that are not escaped.
        int bars = 0;
        for (std::size_t i = 0; i < line.size(); ++i)
            if (line[i] == '|' && (i == 0 || line[i - 1] != '\\')) ++bars;
        EXPECT_EQ(bars, 5) << line;
        ++rows;
    }
    EXPECT_EQ(rows, static_cast<int>(gis::serverOptions().size()) + 3); // header, rule, --config
    for (const auto& o : gis::serverOptions()) {
        EXPECT_NE(reference.find("| `" + o.flag), std::string::npos) << o.flag;
        EXPECT_NE(reference.find("`" + o.env + "`"), std::string::npos) << o.env;
    }
    EXPECT_NE(reference.find("`--gl egl\\|osmesa`"), std::string::npos) << "bars in cells are escaped";
    // Not the core count of the machine that generated docs/operations.md.
    EXPECT_NE(reference.find("(default: the number of cores)"), std::string::npos);
}

// gi-server settings: one table gives flags, environment, config file, help and the summary.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "core/Error.h"
#include "net/ServerOptions.h"

namespace {
std::map<std::string, std::string> gEnv;
const char* fakeEnv(const char* name) {
    auto it = gEnv.find(name);
    return it == gEnv.end() ? nullptr : it->second.c_str();
}
std::string errorOf(const std::vector<std::string>& args) {
    try {
        gis::parseServerArgs(args, fakeEnv);
    } catch (const gis::InputError& e) {
        return e.what();
    }
    return {};
}
} // namespace

TEST(ServerOptions, EveryOptionHasFlagEnvHelpAndAppearsInUsage) {
    const std::string usage = gis::serverUsage();
    for (const auto& o : gis::serverOptions()) {
        EXPECT_EQ(o.flag.rfind("--", 0), 0u) << o.flag;
        EXPECT_EQ(o.env.rfind("GI_", 0), 0u) << o.flag;
        EXPECT_FALSE(o.help.empty()) << o.flag;
        EXPECT_NE(usage.find(o.flag), std::string::npos) << o.flag;
        EXPECT_NE(usage.find("$" + o.env), std::string::npos) << o.flag;
    }
}

TEST(ServerOptions, PrecedenceIsDefaultsFileEnvironmentFlags) {
    const auto file =
        std::filesystem::temp_directory_path() / ("gis_server_config_" + std::to_string(::getpid()));
    std::ofstream(file)
        << R"({"max-sessions": 3, "port": 9000, "rate-limit": 10, "allow-origin": ["https://a.example"]})";
    gEnv = {{"GI_CONFIG", file.string()}, {"GI_PORT", "9001"}, {"GI_TOKEN", "s3cret"}};
    auto parsed = gis::parseServerArgs({"--rate-limit", "20", "--size", "320x240"}, fakeEnv);
    EXPECT_EQ(parsed.config.maxSessions, 3);        // file
    EXPECT_EQ(parsed.config.port, 9001);            // env beats file
    EXPECT_EQ(parsed.config.messagesPerSecond, 20); // flag beats file
    EXPECT_EQ(parsed.config.session.width, 320);
    EXPECT_EQ(parsed.config.allowOrigins, std::vector<std::string>{"https://a.example"});
    EXPECT_EQ(parsed.sources["--port"], "env GI_PORT");
    const std::string summary = gis::describeServerConfig(parsed.config, parsed.sources);
    EXPECT_EQ(summary.find("s3cret"), std::string::npos) << "the token must be masked";
    EXPECT_NE(summary.find("--token (set)"), std::string::npos);
    gEnv.clear();
    std::filesystem::remove(file);
}

TEST(ServerOptions, ErrorsNameTheSourceAndTheRange) {
    gEnv.clear();
    EXPECT_NE(errorOf({"--port", "0"}).find("--port: must be an integer in [1, 65535], got '0'"),
              std::string::npos);
    EXPECT_NE(errorOf({"--frobnicate", "1"}).find("unknown option"), std::string::npos);
    EXPECT_NE(errorOf({"--max-size", "big"}).find("must look like 512x512"), std::string::npos);
    EXPECT_NE(errorOf({"--technique", "nope"}).find("nope"), std::string::npos);
    EXPECT_NE(errorOf({"--port"}).find("needs a value"), std::string::npos);
    gEnv = {{"GI_MAX_SESSIONS", "0"}};
    EXPECT_NE(errorOf({}).find("$GI_MAX_SESSIONS"), std::string::npos);
    const auto file =
        std::filesystem::temp_directory_path() / ("gis_server_badcfg_" + std::to_string(::getpid()));
    std::ofstream(file) << R"({"max-sesions": 3})";
    gEnv = {{"GI_CONFIG", file.string()}};
    EXPECT_NE(errorOf({}).find("max-sesions: unknown setting"), std::string::npos);
    gEnv.clear();
    std::filesystem::remove(file);
}

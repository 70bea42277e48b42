#include "core/Log.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>

namespace gis {
namespace {
std::atomic<int> gLevel{static_cast<int>(LogLevel::Info)};
std::mutex gMutex;
const char* levelName(LogLevel l) {
    switch (l) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warn: return "warn";
    case LogLevel::Error: return "error";
    }
    return "?";
}
} // namespace

void setLogLevel(LogLevel level) { gLevel = static_cast<int>(level); }
LogLevel logLevel() { return static_cast<LogLevel>(gLevel.load()); }

void log(LogLevel level, const std::string& message) {
    if (static_cast<int>(level) < gLevel.load()) return;
    std::lock_guard lock(gMutex);
    std::fprintf(stderr, "[%s] %s\n", levelName(level), message.c_str());
    std::fflush(stderr);
}

} // namespace gis

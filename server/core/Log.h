// Minimal thread-safe logging to stderr. Messages start with the component: "gl: ...".
#pragma once

#include <string>

namespace gis {

enum class LogLevel { Debug = 0, Info = 1, Warn = 2, Error = 3 };

void setLogLevel(LogLevel level);
LogLevel logLevel();
void log(LogLevel level, const std::string& message);

inline void logDebug(const std::string& m) { log(LogLevel::Debug, m); }
inline void logInfo(const std::string& m) { log(LogLevel::Info, m); }
inline void logWarn(const std::string& m) { log(LogLevel::Warn, m); }
inline void logError(const std::string& m) { log(LogLevel::Error, m); }

} // namespace gis

// Error policy (docs/architecture.md, "Errors"):
//  - GIS_ASSERT: programmer mistakes; prints the condition and location, then aborts.
//  - gis::Error: bad input at load, compile and request boundaries; caught there and turned into a
//    protocol error or a CLI message. The per-frame path never throws.
#pragma once

#include <stdexcept>
#include <string>

namespace gis {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// An error in a request or input whose location is known (a JSON pointer, a flag, a file).
class InputError : public Error {
public:
    InputError(std::string where, const std::string& message)
        : Error(where.empty() ? message : where + ": " + message), mWhere(std::move(where)), mReason(message) {}
    const std::string& where() const { return mWhere; }
    const std::string& reason() const { return mReason; }

private:
    std::string mWhere;
    std::string mReason;
};

[[noreturn]] void assertFailed(const char* condition, const char* file, int line, const std::string& detail);

} // namespace gis

#define GIS_ASSERT(cond)                                                                                     \
    do {                                                                                                     \
        if (!(cond)) ::gis::assertFailed(#cond, __FILE__, __LINE__, {});                                     \
    } while (0)

#define GIS_ASSERT_MSG(cond, msg)                                                                            \
    do {                                                                                                     \
        if (!(cond)) ::gis::assertFailed(#cond, __FILE__, __LINE__, (msg));                                  \
    } while (0)

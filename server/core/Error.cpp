#include "core/Error.h"

#include <cstdio>
#include <cstdlib>

namespace gis {

void assertFailed(const char* condition, const char* file, int line, const std::string& detail) {
    std::fprintf(stderr, "assertion failed: %s at %s:%d%s%s\n", condition, file, line, detail.empty() ? "" : ": ",
                 detail.c_str());
    std::abort();
}

} // namespace gis

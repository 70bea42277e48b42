#include "core/Memory.h"

#include <fstream>

#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace gis {

std::optional<std::size_t> residentBytes() {
    std::ifstream statm("/proc/self/statm");
    std::size_t totalPages = 0, residentPages = 0;
    if (!(statm >> totalPages >> residentPages)) return std::nullopt;
    const long pageBytes = sysconf(_SC_PAGESIZE);
    if (pageBytes <= 0) return std::nullopt;
    return residentPages * static_cast<std::size_t>(pageBytes);
}

void releaseFreedMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

} // namespace gis

#include "net/SessionDirectory.h"

#include <cstdint>
#include <mutex>
#include <random>

namespace gis {

std::string randomToken(const char* prefix) {
    static std::mutex mutex;
    static std::random_device device;
    std::lock_guard lock(mutex);
    static const char* hex = "0123456789abcdef";
    std::string out = prefix;
    for (int i = 0; i < 4; ++i) {
        const std::uint32_t v = device();
        for (int b = 0; b < 8; ++b) out += hex[(v >> (4 * b)) & 0xf];
    }
    return out;
}

bool sameSecret(const std::string& presented, const std::string& expected) {
    // Constant time in the length of the expected secret: no early exit on the first difference.
    unsigned diff = presented.size() == expected.size() ? 0u : 1u;
    for (std::size_t i = 0; i < expected.size(); ++i)
        diff |= static_cast<unsigned>(expected[i] ^ (i < presented.size() ? presented[i] : 0));
    return diff == 0;
}

} // namespace gis

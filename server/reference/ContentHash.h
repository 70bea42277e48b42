// Content hashing for reference cache keys: a 128-bit non-cryptographic digest (two independent 64-bit
// lanes, each word scrambled with the SplitMix64 finaliser). Collisions between honest requests are
// negligible at 128 bits; the cache is not meant to resist crafted inputs.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>

#include "reference/ReferenceRenderer.h"
#include "reference/Sampling.h"

namespace gis::reference {

class Hasher {
public:
    void bytes(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        mLength += n;
        while (n >= 8) {
            std::uint64_t w;
            std::memcpy(&w, p, 8);
            word(w);
            p += 8;
            n -= 8;
        }
        if (n > 0) {
            std::uint64_t w = 0;
            std::memcpy(&w, p, n);
            word(w ^ (static_cast<std::uint64_t>(n) << 56));
        }
    }
    template <class T> void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof v);
    }
    void text(const std::string& s) {
        value(s.size());
        bytes(s.data(), s.size());
    }
    std::string hex() const {
        const std::uint64_t a = mix64(mA ^ mLength), b = mix64(mB ^ mix64(mA + mLength));
        static const char* kDigits = "0123456789abcdef";
        std::string out(32, '0');
        for (int i = 0; i < 16; ++i) {
            out[static_cast<size_t>(i)] = kDigits[(a >> (60 - 4 * i)) & 15u];
            out[static_cast<size_t>(16 + i)] = kDigits[(b >> (60 - 4 * i)) & 15u];
        }
        return out;
    }

private:
    void word(std::uint64_t w) {
        mA = mix64(mA ^ w);
        mB = ((mB ^ w) << 29 | (mB ^ w) >> 35) * 0x9fb21c651e98df25ull + 0x2545f4914f6cdd1dull;
    }
    std::uint64_t mA = 0x243f6a8885a308d3ull;
    std::uint64_t mB = 0x13198a2e03707344ull;
    std::uint64_t mLength = 0;
};

/// Digest of everything in the scene the reference image depends on (geometry, materials, textures,
/// bounds); lights and cameras come from the FrameState instead.
std::string sceneDigest(const Scene& scene);
/// Key of one request given its scene digest.
std::string requestKey(const std::string& sceneDigest, const FrameState& state,
                       const ReferenceOptions& options);

} // namespace gis::reference

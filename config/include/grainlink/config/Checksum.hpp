#pragma once
// The checksum of grainlink's own files (a DEM checkpoint's trailer, a coupled checkpoint's
// manifest): FNV-1a, 64 bit. A flipped bit anywhere changes it; it is no defence against a forger.
#include <cstddef>
#include <cstdint>

namespace grainlink::config {

struct Checksum {
    std::uint64_t value = 14695981039346656037ull;
    void add(const char *bytes, std::size_t n) {
        for (std::size_t k = 0; k < n; ++k)
            value = (value ^ std::uint8_t(bytes[k])) * 1099511628211ull;
    }
};

} // namespace grainlink::config

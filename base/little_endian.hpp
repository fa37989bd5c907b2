#pragma once
// Little-endian integers of one to eight bytes, written and read byte by byte so that a wire format does not
// depend on the host's byte order.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace airseg {

/// Appends the low `bytes` bytes of `v` to `out`, least significant first.
inline void append_le(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i) {
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
}

/// The `bytes`-byte unsigned integer stored least significant byte first at `in`.
inline std::uint64_t load_le(const std::uint8_t* in, std::size_t bytes) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
        v |= static_cast<std::uint64_t>(in[i]) << (8 * i);
    }
    return v;
}

}  // namespace airseg

#pragma once
// FNV-1a, 64 bit: a checksum against truncation and stray bytes, and a fingerprint to tell two texts apart
// (not against an adversary). The same value on every architecture, unlike std::hash (32 bit on armhf).
#include <cstdint>
#include <string_view>

namespace airseg {

inline std::uint64_t fnv1a64(std::string_view data) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (const char c : data) {
        h ^= static_cast<unsigned char>(c);
        h *= 0x100000001b3ull;
    }
    return h;
}

}  // namespace airseg

#include "services/groundlink/transport/crc32.hpp"

#include <array>

namespace airseg::groundlink {
namespace {

// Slicing by 8 (tables[k][b]: the CRC of byte b followed by k zero bytes): eight bytes per step, a table
// look-up each, instead of one dependent look-up per byte.
using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

constexpr Tables make_crc32_tables() {
    Tables t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) {
            c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
        }
        t[0][i] = c;
    }
    for (std::size_t k = 1; k < t.size(); ++k) {
        for (std::size_t i = 0; i < 256; ++i) {
            t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFU];
        }
    }
    return t;
}

constexpr Tables kTables = make_crc32_tables();

std::uint32_t load_le32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
           (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

}  // namespace

void Crc32::update(std::span<const std::uint8_t> data) {
    std::uint32_t c = state_;
    const std::uint8_t* p = data.data();
    std::size_t n = data.size();
    for (; n >= 8; n -= 8, p += 8) {
        const std::uint32_t lo = c ^ load_le32(p);
        const std::uint32_t hi = load_le32(p + 4);
        c = kTables[7][lo & 0xFFU] ^ kTables[6][(lo >> 8) & 0xFFU] ^ kTables[5][(lo >> 16) & 0xFFU] ^
            kTables[4][lo >> 24] ^ kTables[3][hi & 0xFFU] ^ kTables[2][(hi >> 8) & 0xFFU] ^
            kTables[1][(hi >> 16) & 0xFFU] ^ kTables[0][hi >> 24];
    }
    for (; n > 0; --n, ++p) {
        c = kTables[0][(c ^ *p) & 0xFFU] ^ (c >> 8);
    }
    state_ = c;
}

std::uint32_t crc32(std::span<const std::uint8_t> data) {
    Crc32 c;
    c.update(data);
    return c.value();
}

}  // namespace airseg::groundlink

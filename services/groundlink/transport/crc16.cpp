#include "services/groundlink/transport/crc16.hpp"

#include <array>

namespace airseg::groundlink {
namespace {

constexpr std::array<std::uint16_t, 256> make_crc16_table() {
    std::array<std::uint16_t, 256> table{};
    for (unsigned i = 0; i < 256; ++i) {
        auto c = static_cast<std::uint16_t>(i << 8);
        for (int k = 0; k < 8; ++k) {
            c = static_cast<std::uint16_t>((c & 0x8000U) != 0 ? (c << 1) ^ 0x1021U : c << 1);
        }
        table[i] = c;
    }
    return table;
}

constexpr std::array<std::uint16_t, 256> kCrc16Table = make_crc16_table();

}  // namespace

std::uint16_t crc16_ccitt(std::span<const std::uint8_t> data) {
    std::uint16_t crc = 0xFFFF;
    for (std::uint8_t b : data) {
        crc = static_cast<std::uint16_t>((crc << 8) ^ kCrc16Table[((crc >> 8) ^ b) & 0xFFU]);
    }
    return crc;
}

}  // namespace airseg::groundlink

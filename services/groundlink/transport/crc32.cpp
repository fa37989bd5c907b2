#include "services/groundlink/transport/crc32.hpp"

#include <array>

namespace airseg::groundlink {
namespace {

constexpr std::array<std::uint32_t, 256> make_crc32_table() {
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) {
            c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
        }
        table[i] = c;
    }
    return table;
}

constexpr std::array<std::uint32_t, 256> kCrc32Table = make_crc32_table();

}  // namespace

void Crc32::update(std::span<const std::uint8_t> data) {
    for (std::uint8_t b : data) {
        state_ = kCrc32Table[(state_ ^ b) & 0xFFU] ^ (state_ >> 8);
    }
}

std::uint32_t crc32(std::span<const std::uint8_t> data) {
    Crc32 c;
    c.update(data);
    return c.value();
}

}  // namespace airseg::groundlink

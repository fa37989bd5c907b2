#pragma once
// CRC-16/MCRF4XX, the checksum MAVLink calls "X.25": polynomial 0x1021 reflected, initial value 0xFFFF,
// no final XOR. constexpr so that CRC_EXTRA can be derived from the message declarations at compile time.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace airseg::mavlink {

class Crc16 {
  public:
    static constexpr std::uint16_t kInitial = 0xFFFF;

    constexpr void add(std::uint8_t byte) {
        std::uint8_t tmp = byte ^ static_cast<std::uint8_t>(value_ & 0xFF);
        tmp = static_cast<std::uint8_t>(tmp ^ (tmp << 4));
        value_ = static_cast<std::uint16_t>((value_ >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
    }
    constexpr void add(std::span<const std::uint8_t> bytes) {
        for (std::uint8_t b : bytes) {
            add(b);
        }
    }
    constexpr void add(std::string_view text) {
        for (char c : text) {
            add(static_cast<std::uint8_t>(c));
        }
    }
    constexpr std::uint16_t value() const { return value_; }

  private:
    std::uint16_t value_ = kInitial;
};

}  // namespace airseg::mavlink

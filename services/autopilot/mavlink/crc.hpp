#pragma once
// CRC-16/MCRF4XX, the checksum MAVLink calls "X.25": polynomial 0x1021 reflected, initial value 0xFFFF,
// no final XOR. constexpr so that CRC_EXTRA can be derived from the message declarations at compile time.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace airseg::mavlink {

namespace detail {
/// One step of the checksum on a register holding `low` (high byte zero) and a zero data byte: the change a
/// byte makes, so that add(byte) is (crc >> 8) ^ kCrcTable[(crc ^ byte) & 0xFF].
constexpr std::uint16_t crc_step(std::uint8_t low) {
    const auto tmp = static_cast<std::uint8_t>(low ^ (low << 4));
    return static_cast<std::uint16_t>((tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
}
inline constexpr auto kCrcTable = [] {
    std::array<std::uint16_t, 256> table{};
    for (std::size_t i = 0; i < table.size(); ++i) {
        table[i] = crc_step(static_cast<std::uint8_t>(i));
    }
    return table;
}();
}  // namespace detail

class Crc16 {
  public:
    static constexpr std::uint16_t kInitial = 0xFFFF;

    constexpr void add(std::uint8_t byte) {
        std::uint8_t tmp = byte ^ static_cast<std::uint8_t>(value_ & 0xFF);
        tmp = static_cast<std::uint8_t>(tmp ^ (tmp << 4));
        value_ = static_cast<std::uint16_t>((value_ >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
    }
    // A table lookup per byte: about half the instructions of add(byte), which matters on a link where
    // every received byte is checksummed once.
    constexpr void add(std::span<const std::uint8_t> bytes) {
        std::uint16_t v = value_;
        for (std::uint8_t b : bytes) {
            v = static_cast<std::uint16_t>((v >> 8) ^ detail::kCrcTable[(v ^ b) & 0xFF]);
        }
        value_ = v;
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

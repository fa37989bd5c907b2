#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF): check value of
// "123456789" is 0xCBF43926.
#include <cstdint>
#include <span>

namespace airseg::groundlink {

class Crc32 {
  public:
    void update(std::span<const std::uint8_t> data);
    [[nodiscard]] std::uint32_t value() const { return ~state_; }

  private:
    std::uint32_t state_ = 0xFFFFFFFFU;
};

std::uint32_t crc32(std::span<const std::uint8_t> data);

}  // namespace airseg::groundlink

#pragma once
// CRC-16/CCITT-FALSE (polynomial 0x1021, init 0xFFFF, not reflected): check value of "123456789" is 0x29B1.
// Guards each forward-error-correction shard, where four bytes of CRC-32 would cost too much.
#include <cstdint>
#include <span>

namespace airseg::groundlink {

std::uint16_t crc16_ccitt(std::span<const std::uint8_t> data);

}  // namespace airseg::groundlink

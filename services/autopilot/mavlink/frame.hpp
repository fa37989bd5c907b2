#pragma once
// A MAVLink frame as the parser delivers it, and the constants of the two framings.
//   v1: 0xFE len seq sysid compid msgid                       payload crc16
//   v2: 0xFD len incompat compat seq sysid compid msgid[3 LE] payload crc16 [signature, 13 bytes]
// The CRC covers every byte after the magic up to the end of the payload, then the message's CRC_EXTRA.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace airseg::mavlink {

enum class Version : std::uint8_t { V1 = 1, V2 = 2 };

inline constexpr std::uint8_t kMagicV1 = 0xFE;
inline constexpr std::uint8_t kMagicV2 = 0xFD;
inline constexpr std::uint8_t kIncompatSigned = 0x01;  // the only incompatibility flag defined so far
inline constexpr std::size_t kHeaderLengthV1 = 6;
inline constexpr std::size_t kHeaderLengthV2 = 10;
inline constexpr std::size_t kChecksumLength = 2;
inline constexpr std::size_t kSignatureLength = 13;
inline constexpr std::size_t kMaxPayload = 255;
inline constexpr std::size_t kMaxFrameLength =
    kHeaderLengthV2 + kMaxPayload + kChecksumLength + kSignatureLength;

struct Frame {
    Version version = Version::V2;
    std::uint8_t incompat_flags = 0;
    std::uint8_t compat_flags = 0;
    std::uint8_t seq = 0;
    std::uint8_t sysid = 0;
    std::uint8_t compid = 0;
    std::uint32_t msgid = 0;
    std::uint8_t wire_length = 0;     // payload bytes as received
    std::uint8_t payload_length = 0;  // bytes of payload_view(): the message's full length when it is known
    bool is_signed = false;           // carried a signature (skipped, not verified)
    bool checksum_verified = false;   // false only for message ids outside the dialect (no CRC_EXTRA known)
    bool typed = false;               // a message of messages.def: the only ones the daemon acts on
    std::array<std::uint8_t, kMaxPayload> payload{};  // zero beyond wire_length: MAVLink 2 zero-extension

    std::span<const std::uint8_t> payload_view() const { return std::span(payload).first(payload_length); }
};

}  // namespace airseg::mavlink

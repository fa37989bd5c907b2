#pragma once
// Frame and chunk layouts (docs/ground-link.md, "Byte layouts"). A frame is a header, then chunks (data
// frames) or a handshake body (HELLO), then the MAC tag (keyed links only), then CRC-32, all COBS-encoded and
// delimited.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "services/groundlink/transport/frame_mac.hpp"

namespace airseg::groundlink::frame {

enum class Kind : std::uint8_t { Data = 0, Hello = 1 };

inline constexpr std::uint8_t kProtocolVersion = 2;
inline constexpr std::size_t kCrcBytes = 4;
inline constexpr std::size_t kDataHeaderBytes = 4;  // header byte + 24-bit frame number
inline constexpr std::size_t kHelloBodyBytes = 18;  // version, sender nonce, echo nonce, flags
inline constexpr std::size_t kMaxBitmapBytes = 16;  // selective-ack bitmap covers 128 segments
inline constexpr std::uint32_t kFrameNumberMask = 0xFFFFFFU;

/// Frame bytes besides the chunks: header, frame number, tag, CRC, COBS code byte and delimiter (COBS adds
/// one more byte per 254 of payload).
constexpr std::size_t frame_overhead(bool keyed) {
    return kDataHeaderBytes + (keyed ? kMacTagBytes : 0) + kCrcBytes + 2;
}

struct SafeChunk {
    std::uint8_t channel = 0;
    bool end = false;  ///< last fragment of its message
    std::uint16_t seq = 0;
    std::span<const std::uint8_t> data;
};
struct FastChunk {
    std::uint8_t priority = 0;
    std::uint16_t topic = 0;
    bool fragmented = false;
    std::uint8_t msg_id = 0;
    std::uint8_t index = 0;
    std::uint8_t count = 1;
    std::span<const std::uint8_t> data;
};
struct AckChunk {
    std::uint8_t channel = 0;
    std::uint16_t next_expected = 0;
    /// Bit i (byte i/8, bit i%8) set: segment next_expected + 1 + i was received.
    std::vector<std::uint8_t> bitmap;
};
inline constexpr std::uint16_t kReportBursty = 0x8000;
inline constexpr double kReportRateUnit = 2e-6;

struct ReportChunk {
    /// The byte error rate the receiver measures on frames from this end: bits 0-14 in units of two
    /// millionths (saturating), bit 15 set when the errors come in bursts (kReportBursty).
    std::uint16_t byte_error_ppm = 0;
};
using Chunk = std::variant<SafeChunk, FastChunk, AckChunk, ReportChunk>;

constexpr std::size_t safe_chunk_overhead() {
    return 5;
}  // type, seq, length
constexpr std::size_t fast_chunk_overhead(bool fragmented) {
    return fragmented ? 8 : 5;
}
std::size_t encoded_size(const Chunk& c);

/// Header flags of a data frame: bits 0-1 the paths the sender hears, bit 2 the sender has urgent traffic
/// (the peer should not borrow its transmit path).
inline constexpr std::uint8_t kUrgentFlag = 0x04;

/// Serializes a data frame (header, frame number, chunks) without tag and CRC. The last chunk omits its
/// length.
std::vector<std::uint8_t> encode_data(std::uint8_t header_flags, std::uint32_t frame_number24,
                                      std::span<const Chunk> chunks);

struct Hello {
    std::uint8_t heard_mask = 0;
    std::uint64_t sender_nonce = 0;
    std::uint64_t echo_nonce = 0;  ///< latest nonce heard from the peer, 0 when none
    bool established = false;      ///< the sender holds a session (sender_nonce, echo_nonce)
};
std::vector<std::uint8_t> encode_hello(const Hello& h);

/// Appends tag (keyed) and CRC (see seal); the frame as it goes into COBS or forward error correction.
std::vector<std::uint8_t> seal_plain(std::vector<std::uint8_t> frame, const FrameMac* mac,
                                     const MacContext& ctx);

/// Appends tag (keyed) and CRC, then COBS-encodes with delimiter. Unkeyed links fold the two session nonces
/// into the CRC instead, so frames of a stale session fail it.
std::vector<std::uint8_t> seal(std::vector<std::uint8_t> frame, const FrameMac* mac, const MacContext& ctx);

/// Checks the CRC of a decoded frame; on success returns the frame without CRC (tag still attached when
/// keyed).
std::optional<std::span<const std::uint8_t>> check_crc(std::span<const std::uint8_t> plain, bool keyed,
                                                       const MacContext& ctx);

[[nodiscard]] std::optional<Kind> kind_of(std::span<const std::uint8_t> frame);
[[nodiscard]] std::uint8_t heard_mask_of(std::span<const std::uint8_t> frame);
[[nodiscard]] bool urgent_of(std::span<const std::uint8_t> frame);
std::optional<Hello> decode_hello(std::span<const std::uint8_t> frame);
/// Frame number (24 bits) of a data frame; nullopt when too short.
std::optional<std::uint32_t> frame_number_of(std::span<const std::uint8_t> frame);
/// Parses the chunks of an authenticated data frame (tag and CRC removed); nullopt when malformed. Spans
/// point into `frame`.
std::optional<std::vector<Chunk>> decode_chunks(std::span<const std::uint8_t> frame);

}  // namespace airseg::groundlink::frame

#pragma once
// Building MAVLink frames. encode_frame() writes one frame from an explicit header and a payload;
// Encoder is one sender's identity (sysid, compid, version) with its own sequence counter, for typed
// messages.
//
//   mavlink::Encoder to_autopilot{255, 190};            // a GCS-like identity, MAVLink 2
//   mavlink::CommandLong cmd;  cmd.target_system = 1;  cmd.command = 400;  cmd.param1 = 1;
//   std::vector<std::uint8_t> bytes = to_autopilot.encode(cmd);
//
// Payload length on the wire: MAVLink 1 sends the base fields only (extensions cannot be carried);
// MAVLink 2 sends all fields with trailing zero bytes removed (at least one byte stays), as the
// specification's payload truncation rule says.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink {

struct FrameHeader {
    Version version = Version::V2;
    std::uint8_t seq = 0;
    std::uint8_t sysid = 0;
    std::uint8_t compid = 0;
    std::uint32_t msgid = 0;
    std::uint8_t compat_flags = 0;  // MAVLink 2 only; written as given
};

/// Bytes of `payload` a frame of this version carries: v1 cuts to base_length, v2 drops trailing zeros.
std::size_t wire_payload_length(Version version, std::span<const std::uint8_t> payload,
                                std::size_t base_length);

/// Writes one unsigned frame carrying `payload` exactly as given (the caller has already applied
/// wire_payload_length) and returns its size, or 0 when it cannot be framed: a MAVLink 1 message id above
/// 255, a MAVLink 2 id above 2^24 - 1, or a payload over 255 bytes.
std::size_t encode_frame(const FrameHeader& header, std::uint8_t crc_extra,
                         std::span<const std::uint8_t> payload, std::span<std::uint8_t, kMaxFrameLength> out);

/// Frames a full-length payload of a known message (as laid out by MessageInfo), applying the version's
/// payload length rule. Returns the frame size, or 0 as encode_frame does.
std::size_t encode_message(const FrameHeader& header, const MessageInfo& info,
                           std::span<const std::uint8_t> payload,
                           std::span<std::uint8_t, kMaxFrameLength> out);

/// The bytes of a frame as the parser delivered it (same header, the payload as received, unsigned: a
/// signature is not kept), for passing a verified frame on; empty when its message id is unknown.
std::vector<std::uint8_t> reencode(const Frame& frame);

class Encoder {
  public:
    Encoder(std::uint8_t sysid, std::uint8_t compid, Version version = Version::V2)
        : sysid_(sysid), compid_(compid), version_(version) {}

    /// Writes the frame of `m` into `out` and returns its size; the sequence number advances by one.
    template <Message M>
    std::size_t encode(const M& m, std::span<std::uint8_t, kMaxFrameLength> out) {
        std::array<std::uint8_t, kMaxPayload> payload{};
        const std::size_t length = encode_payload(m, payload);
        constexpr auto& layout = MessageTraits<M>::layout;
        const std::size_t on_wire =
            wire_payload_length(version_, std::span(payload).first(length), layout.base_length);
        return encode_frame(next_header(M::kId), layout.crc_extra, std::span(payload).first(on_wire), out);
    }
    template <Message M>
    std::vector<std::uint8_t> encode(const M& m) {
        std::array<std::uint8_t, kMaxFrameLength> frame{};
        return std::vector<std::uint8_t>(frame.begin(),
                                         frame.begin() + static_cast<std::ptrdiff_t>(encode(m, frame)));
    }

    std::uint8_t sysid() const { return sysid_; }
    std::uint8_t compid() const { return compid_; }
    Version version() const { return version_; }
    void set_version(Version v) { version_ = v; }
    /// Sequence number the next frame will carry.
    std::uint8_t next_seq() const { return seq_; }

  private:
    FrameHeader next_header(std::uint32_t msgid) {
        return FrameHeader{version_, seq_++, sysid_, compid_, msgid, 0};
    }

    std::uint8_t sysid_;
    std::uint8_t compid_;
    Version version_;
    std::uint8_t seq_ = 0;
};

}  // namespace airseg::mavlink

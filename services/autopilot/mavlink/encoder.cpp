#include "services/autopilot/mavlink/encoder.hpp"

#include <algorithm>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/wire.hpp"

namespace airseg::mavlink {

std::size_t wire_payload_length(Version version, std::span<const std::uint8_t> payload,
                                std::size_t base_length) {
    if (version == Version::V1) {
        return std::min(payload.size(), base_length);
    }
    std::size_t length = payload.size();
    while (length > 1 && payload[length - 1] == 0) {
        --length;
    }
    return length;
}

std::size_t encode_frame(const FrameHeader& header, std::uint8_t crc_extra,
                         std::span<const std::uint8_t> payload,
                         std::span<std::uint8_t, kMaxFrameLength> out) {
    if (payload.size() > kMaxPayload) {
        return 0;
    }
    std::size_t n = 0;
    if (header.version == Version::V1) {
        if (header.msgid > 0xFF) {
            return 0;
        }
        out[n++] = kMagicV1;
        out[n++] = static_cast<std::uint8_t>(payload.size());
        out[n++] = header.seq;
        out[n++] = header.sysid;
        out[n++] = header.compid;
        out[n++] = static_cast<std::uint8_t>(header.msgid);
    } else {
        if (header.msgid > 0xFFFFFF) {
            return 0;
        }
        out[n++] = kMagicV2;
        out[n++] = static_cast<std::uint8_t>(payload.size());
        out[n++] = 0;  // incompatibility flags: this encoder does not sign
        out[n++] = header.compat_flags;
        out[n++] = header.seq;
        out[n++] = header.sysid;
        out[n++] = header.compid;
        out[n++] = static_cast<std::uint8_t>(header.msgid);
        out[n++] = static_cast<std::uint8_t>(header.msgid >> 8);
        out[n++] = static_cast<std::uint8_t>(header.msgid >> 16);
    }
    std::copy(payload.begin(), payload.end(), out.begin() + static_cast<std::ptrdiff_t>(n));
    n += payload.size();
    Crc16 crc;
    crc.add(std::span<const std::uint8_t>(out.data() + 1, n - 1));
    crc.add(crc_extra);
    wire::put(out.data() + n, crc.value());
    return n + kChecksumLength;
}

std::size_t encode_message(const FrameHeader& header, const MessageInfo& info,
                           std::span<const std::uint8_t> payload,
                           std::span<std::uint8_t, kMaxFrameLength> out) {
    const auto full = payload.first(std::min<std::size_t>(payload.size(), info.length));
    return encode_frame(header, info.crc_extra,
                        full.first(wire_payload_length(header.version, full, info.base_length)), out);
}

std::vector<std::uint8_t> reencode(const Frame& frame) {
    const MessageInfo* info = find_dialect_message(frame.msgid);
    if (!info) {
        return {};
    }
    std::array<std::uint8_t, kMaxFrameLength> buf{};
    const FrameHeader h{frame.version, frame.seq, frame.sysid, frame.compid, frame.msgid, frame.compat_flags};
    const std::size_t n =
        encode_frame(h, info->crc_extra, std::span(frame.payload).first(frame.wire_length), buf);
    return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace airseg::mavlink

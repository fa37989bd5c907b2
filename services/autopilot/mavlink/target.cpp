#include "services/autopilot/mavlink/target.hpp"

#include <algorithm>

#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::mavlink {

TargetOffsets target_offsets(std::uint32_t msgid) {
    TargetOffsets out;
    const auto* info = find_dialect_message(msgid);
    if (info == nullptr) {
        return out;
    }
    // Only a single uint8_t is an addressee: a few messages have arrays or other fields of similar names.
    const auto offset_of = [&](std::string_view name) -> std::optional<std::uint8_t> {
        const auto* field = info->find_field(name);
        if (field == nullptr || field->type != FieldType::Uint8 || field->array_length != 0) {
            return std::nullopt;
        }
        return field->offset;
    };
    out.system = offset_of("target_system");
    out.component = offset_of("target_component");
    return out;
}

namespace {

/// The addressee of message `msgid` whose payload is `payload`, zero beyond its end.
std::optional<FrameTarget> target_in(std::uint32_t msgid, std::span<const std::uint8_t> payload) {
    const auto offsets = target_offsets(msgid);
    if (!offsets.system) {
        return std::nullopt;
    }
    const auto at = [&](std::uint8_t offset) -> std::uint8_t {
        return offset < payload.size() ? payload[offset] : 0;  // MAVLink 2 truncation: a missing byte is 0
    };
    FrameTarget target;
    target.system = at(*offsets.system);
    if (offsets.component) {
        target.component = at(*offsets.component);
    }
    return target;
}

}  // namespace

std::optional<FrameTarget> frame_target(const Frame& frame) {
    return target_in(frame.msgid, frame.payload);
}

std::optional<FrameTarget> frame_target(std::span<const std::uint8_t> frame) {
    std::uint32_t msgid = 0;
    std::size_t header = 0;
    if (frame.size() >= kHeaderLengthV2 && frame[0] == kMagicV2) {
        msgid = std::uint32_t{frame[7]} | std::uint32_t{frame[8]} << 8 | std::uint32_t{frame[9]} << 16;
        header = kHeaderLengthV2;
    } else if (frame.size() >= kHeaderLengthV1 && frame[0] == kMagicV1) {
        msgid = frame[5];
        header = kHeaderLengthV1;
    } else {
        return std::nullopt;
    }
    const std::size_t length = std::min<std::size_t>(frame[1], frame.size() - header);
    return target_in(msgid, frame.subspan(header, length));
}

}  // namespace airseg::mavlink

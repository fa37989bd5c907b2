#include "ground/mavlink_target.hpp"

#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::ground {

namespace mav = airseg::mavlink;

TargetOffsets target_offsets(std::uint32_t msgid) {
    TargetOffsets out;
    const auto* info = mav::find_dialect_message(msgid);
    if (info == nullptr) {
        return out;
    }
    // Only a single uint8_t is an addressee: a few messages have arrays or other fields of similar names.
    const auto offset_of = [&](std::string_view name) -> std::optional<std::uint8_t> {
        const auto* field = info->find_field(name);
        if (field == nullptr || field->type != mav::FieldType::Uint8 || field->array_length != 0) {
            return std::nullopt;
        }
        return field->offset;
    };
    out.system = offset_of("target_system");
    out.component = offset_of("target_component");
    return out;
}

std::optional<FrameTarget> frame_target(const mav::Frame& frame) {
    const auto offsets = target_offsets(frame.msgid);
    if (!offsets.system) {
        return std::nullopt;
    }
    FrameTarget target;
    // frame.payload is zero beyond what was received (MAVLink 2 truncation): a missing byte is 0.
    target.system = frame.payload[*offsets.system];
    if (offsets.component) {
        target.component = frame.payload[*offsets.component];
    }
    return target;
}

}  // namespace airseg::ground

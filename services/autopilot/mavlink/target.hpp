#pragma once
// Whom a MAVLink frame is addressed to: its target_system and target_component fields, read from the
// payload at the offsets the message table declares. A message without such a field has no addressee
// (broadcast). MAVLink 2 drops trailing zero bytes of a payload; the parser zero-extends it again, so a
// truncated target byte reads as 0, as the specification means it.
//
// The offsets come from the table of ArduPilot's whole dialect (dialect.def); a frame of a message outside it
// counts as broadcast.
#include <cstdint>
#include <optional>
#include <span>

#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::mavlink {

struct TargetOffsets {
    std::optional<std::uint8_t> system;     // payload offset of target_system, if the message has one
    std::optional<std::uint8_t> component;  // payload offset of target_component, if the message has one
};

/// The offsets of message `msgid`'s target fields; both empty for an unknown message or one without them.
TargetOffsets target_offsets(std::uint32_t msgid);

struct FrameTarget {
    std::uint8_t system = 0;     // 0: every system
    std::uint8_t component = 0;  // 0: every component of the system
};

/// The addressee of `frame` (as the parser delivers it: payload zero-extended), or nothing when its message
/// has no target_system (a broadcast).
std::optional<FrameTarget> frame_target(const Frame& frame);

/// The same from a whole frame's bytes as they came (MAVLink 1 or 2, unparsed; a payload cut short reads as
/// zero-extended); nothing for a frame too short to have a header.
std::optional<FrameTarget> frame_target(std::span<const std::uint8_t> frame);

}  // namespace airseg::mavlink

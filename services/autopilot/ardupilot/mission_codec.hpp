#pragma once
// Neutral mission items as ArduPilot mission commands, and back.
//   Waypoint -> MAV_CMD_NAV_WAYPOINT (param1 hold seconds, param2 acceptance radius)
//   Stop     -> MAV_CMD_NAV_LOITER_UNLIM (a board without it: DO_JUMP past the mission's end)
//   JumpTo   -> MAV_CMD_DO_JUMP (param1 slot, param2 -1: forever)
// Positions use MAV_FRAME_GLOBAL_RELATIVE_ALT_INT. A per-leg speed has no place in the same slot of a Rover
// mission (it would need a DO_CHANGE_SPEED slot of its own) and is not encoded.
#include <cstdint>
#include <vector>

#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::autopilot::ardupilot {

/// The DO_JUMP target that is past the end of any mission such a board can hold.
inline constexpr std::uint16_t kJumpPastTheEnd = 255;
/// `stop_as_jump`: a board without NAV_LOITER_UNLIM (APM:Rover 2.42-2.45 answers MAV_MISSION_UNSUPPORTED)
/// gets a Stop as a DO_JUMP past the end. Its command processor runs the do-commands after a waypoint once
/// that waypoint is reached; the jump leaves no command to run ("No commands - setting HOLD"), so the board
/// holds at the waypoint before the Stop by itself, as NAV_LOITER_UNLIM at that point would keep it there,
/// whether or not this daemon is running.
mavlink::MissionItemInt encode_item(const MissionItem& item, bool stop_as_jump = false);
/// Commands other than the three above read as a Waypoint at the item's position.
MissionItem decode_item(const mavlink::MissionItemInt& item);
/// The home slot as an item (ArduPilot keeps home in slot 0, in absolute altitude).
mavlink::MissionItemInt home_item(const Position& home);

}  // namespace airseg::autopilot::ardupilot

#pragma once
// Neutral mission items as ArduPilot mission commands, and back.
//   Waypoint -> MAV_CMD_NAV_WAYPOINT (param1 hold seconds, param2 acceptance radius)
//   Stop     -> MAV_CMD_NAV_LOITER_UNLIM
//   JumpTo   -> MAV_CMD_DO_JUMP (param1 slot, param2 -1: forever)
// Positions use MAV_FRAME_GLOBAL_RELATIVE_ALT_INT. A per-leg speed has no place in the same slot of a Rover
// mission (it would need a DO_CHANGE_SPEED slot of its own) and is not encoded.
#include <vector>

#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::autopilot::ardupilot {

/// `stop_as_waypoint`: a board without NAV_LOITER_UNLIM (APM:Rover 2.x answers MAV_MISSION_UNSUPPORTED)
/// gets a Stop as a NAV_WAYPOINT at its position; the driver holds the vehicle when it gets there.
mavlink::MissionItemInt encode_item(const MissionItem& item, bool stop_as_waypoint = false);
/// Commands other than the three above read as a Waypoint at the item's position.
MissionItem decode_item(const mavlink::MissionItemInt& item);
/// The home slot as an item (ArduPilot keeps home in slot 0, in absolute altitude).
mavlink::MissionItemInt home_item(const Position& home);

}  // namespace airseg::autopilot::ardupilot

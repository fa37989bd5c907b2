#pragma once
// The vehicle telemetry sample pushed to the ground, made from the autopilot's neutral telemetry.
#include "services/autopilot/autopilot.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::groundlink {

/// Flight plan progress as the sample carries it (plan_state 0 none, 1 running, 2 paused, 3 done), taken from
/// the flight plan service's flightplan::PlanProgress bus variable.
struct PlanProgressSample {
    std::uint8_t plan_state = 0;
    std::uint16_t element = 0;
    std::uint32_t next_waypoint = 0;
};

/// Angles in radians become whole degrees; the mode travels as the autopilot's number (protocol::kModeUnknown
/// when absent or too large for the byte); a missing position (none yet, no fix, or refused by the driver's
/// checks) leaves latitude and longitude 0 and sets no_position.
protocol::Telemetry make_sample(const autopilot::Telemetry& t, const PlanProgressSample& plan = {});

}  // namespace airseg::groundlink

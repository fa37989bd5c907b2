#pragma once
// A mission a standard ground station uploaded (autopilot::GroundStationMission) as a flight plan: the plan
// text the loader takes, and whether one may replace the running plan at all.
//
// A running or paused plan is never replaced from a ground station: a mission upload is easy to do by
// mistake from a ground station's planning view, and pausing keeps the plan to be resumed.
#include <optional>
#include <string>
#include <vector>

#include "services/autopilot/autopilot.hpp"
#include "services/flightplan/feeder_types.hpp"

namespace airseg::flightplan {

inline constexpr const char* kGroundMissionName = "ground station mission";
inline constexpr const char* kGroundMissionSource = "ground station";

/// The plan YAML for the mission's items: a waypoint each, a hold of hold_s seconds there for a timed hold,
/// a hold until released there for a Stop.
std::string ground_mission_plan(const std::vector<autopilot::MissionItem>& items);

/// Why a ground station's mission may not become the plan now, or nothing.
std::optional<std::string> ground_mission_refusal(const FeederProgress& progress);

}  // namespace airseg::flightplan

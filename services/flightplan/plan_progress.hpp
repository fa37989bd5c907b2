#pragma once
// Plan progress as a bus variable (publish_latest), for services that report it compactly: the ground link's
// telemetry samples carry it to the ground.
#include <cstdint>
#include <string>

#include "services/flightplan/feeder_types.hpp"

namespace airseg::flightplan {

struct PlanProgress {
    PlanState state = PlanState::None;
    std::uint32_t element = 0;  // index of the top-level plan element being flown
    std::uint64_t next_waypoint = 0;
    std::uint64_t waypoints_reached = 0;
    std::uint32_t generation =
        0;  // which plan: each plan loaded or resumed counts on (so does a cleared one)
    std::string name{};
    std::uint32_t extensions = 0;  // plans appended to this one (plan.append): its count has grown
    bool operator==(const PlanProgress&) const = default;
};

}  // namespace airseg::flightplan

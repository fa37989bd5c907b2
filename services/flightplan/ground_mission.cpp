#include "services/flightplan/ground_mission.hpp"

#include <iomanip>
#include <sstream>

namespace airseg::flightplan {

std::string ground_mission_plan(const std::vector<autopilot::MissionItem>& items) {
    std::ostringstream yaml;
    yaml << std::fixed << std::setprecision(7);
    yaml << "plan:\n  name: " << kGroundMissionName << "\n  elements:\n";
    for (const auto& item : items) {
        const bool stop = item.kind == autopilot::MissionItem::Kind::Stop;
        const bool timed = !stop && item.hold_s && *item.hold_s > 0;
        yaml << "    - " << (stop || timed ? "hold" : "waypoint") << ": {lat: " << item.lat
             << ", lon: " << item.lon;
        if (stop) {
            yaml << ", until_released: true";
        } else if (timed) {
            yaml << std::setprecision(3) << ", seconds: " << *item.hold_s << std::setprecision(7);
        }
        yaml << "}\n";
    }
    return yaml.str();
}

std::optional<std::string> ground_mission_refusal(const FeederProgress& progress) {
    if (progress.state != PlanState::Running && progress.state != PlanState::Paused) {
        return std::nullopt;
    }
    return "airseg: a flight plan is running (" + progress.plan_name +
           "); pause is not enough: let it end, or load the mission as a plan with airsegctl plan load";
}

}  // namespace airseg::flightplan

#pragma once
// Puts the autopilot's status variable into the status document: every AutopilotStatus published on the bus
// becomes the document's `autopilot` section (see docs/status.md for its keys).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "services/autopilot/autopilot.hpp"
#include "services/common/bus.hpp"

namespace airseg::daemon {

nlohmann::json autopilot_status_json(const autopilot::AutopilotStatus& s);

/// Vehicle states as operators write them: "PARKING", "WAYPOINT_NAVIGATION".
std::string state_name(autopilot::VehicleState s);
/// Either case is accepted: "PARKING" or "parking".
std::optional<autopilot::VehicleState> parse_state_name(std::string_view text);

class AutopilotStatusSection {
  public:
    AutopilotStatusSection(Bus& bus, Strand strand);

  private:
    Bus& bus_;
    std::optional<autopilot::AutopilotStatus>
        last_;  // only changes are published: the status service keeps the newest
    Subscription subscription_;
};

}  // namespace airseg::daemon

#include "services/flightplan/plan.hpp"

#include <cmath>

namespace airseg::flightplan {

const char* to_string(NodeKind kind) {
    switch (kind) {
        case NodeKind::ElementList:
            return "elements";
        case NodeKind::Waypoint:
            return "waypoint";
        case NodeKind::Hold:
            return "hold";
        case NodeKind::Scan:
            return "scan";
        case NodeKind::Orbit:
            return "orbit";
        case NodeKind::Speed:
            return "speed";
        case NodeKind::Repeat:
            return "repeat";
        case NodeKind::Block:
            return "block";
        case NodeKind::Goto:
            return "goto";
    }
    return "?";
}

const char* to_string(ReactionAction action) {
    switch (action) {
        case ReactionAction::Hold:
            return "hold";
        case ReactionAction::ReturnHome:
            return "return_home";
        case ReactionAction::Continue:
            return "continue";
        case ReactionAction::GotoBlock:
            return "goto";
    }
    return "?";
}

std::uint64_t OrbitPattern::count() const {
    return static_cast<std::uint64_t>(std::llround(turns * static_cast<double>(points_per_turn))) + 1;
}

Enu OrbitPattern::point(std::uint64_t k) const {
    // Starts due north of the centre; bearings grow clockwise.
    const double step = 2.0 * kPi / static_cast<double>(points_per_turn);
    const double bearing = (clockwise ? 1.0 : -1.0) * step * static_cast<double>(k % points_per_turn);
    return {centre.e + radius * std::sin(bearing), centre.n + radius * std::cos(bearing)};
}

std::optional<VehicleProfile> VehicleProfile::defaults_for(std::string_view type) {
    if (type == "rover")
        return VehicleProfile{"rover", 4.0, 2.0, 2.0};
    if (type == "boat")
        return VehicleProfile{"boat", 5.0, 3.0, 2.0};
    if (type == "plane")
        return VehicleProfile{"plane", 100.0, 30.0, 18.0};
    if (type == "copter")
        return VehicleProfile{"copter", 2.0, 1.0, 5.0};
    return std::nullopt;
}

std::uint32_t Plan::find(std::string_view wanted) const {
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
        if (!nodes[i].name.empty() && nodes[i].name == wanted)
            return i;
    }
    return kNoNode;
}

const std::string& Plan::element_path(std::uint32_t id) const {
    static const std::string kNone;
    return id < nodes.size() ? nodes[id].path : kNone;
}

}  // namespace airseg::flightplan

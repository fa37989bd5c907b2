#include "services/flightplan/feeder_types.hpp"

namespace airseg::flightplan {

const char* to_string(PlanState state) {
    switch (state) {
        case PlanState::None:
            return "none";
        case PlanState::Running:
            return "running";
        case PlanState::Paused:
            return "paused";
        case PlanState::Done:
            return "done";
        case PlanState::Interrupted:
            return "interrupted";
        case PlanState::Failed:
            return "failed";
    }
    return "?";
}

const char* to_string(FeederEvent::Kind kind) {
    switch (kind) {
        case FeederEvent::Kind::ElementStarted:
            return "element-started";
        case FeederEvent::Kind::ElementFinished:
            return "element-finished";
        case FeederEvent::Kind::WaypointReached:
            return "waypoint-reached";
        case FeederEvent::Kind::HoldStarted:
            return "hold-started";
        case FeederEvent::Kind::HoldEnded:
            return "hold-ended";
        case FeederEvent::Kind::PlanDone:
            return "plan-done";
        case FeederEvent::Kind::PlanBlocked:
            return "plan-blocked";
        case FeederEvent::Kind::RequestFailed:
            return "request-failed";
        case FeederEvent::Kind::WindowStarved:
            return "window-starved";
        case FeederEvent::Kind::HeldAtFrontier:
            return "held-at-frontier";
        case FeederEvent::Kind::Interrupted:
            return "interrupted";
        case FeederEvent::Kind::Continued:
            return "continued";
        case FeederEvent::Kind::PlanFailed:
            return "plan-failed";
    }
    return "?";
}

std::ostream& operator<<(std::ostream& os, const FeederRequest& r) {
    os << "#" << r.id << " ";
    if (const auto* up = std::get_if<autopilot::UploadMission>(&r.op)) {
        return os << "upload(" << up->items.size() << " items)";
    }
    if (const auto* w = std::get_if<autopilot::WriteMissionItems>(&r.op)) {
        return os << "write(slot " << w->first_slot << " x" << w->items.size() << ")";
    }
    if (const auto* s = std::get_if<autopilot::SetMissionCurrent>(&r.op)) {
        return os << "set-current(" << s->slot << ")";
    }
    const auto& change = std::get<autopilot::RequestStateChange>(r.op);
    return os << (change.state == autopilot::VehicleState::Parking ? "hold" : "resume");
}

}  // namespace airseg::flightplan

#include "services/autopilot/autopilot.hpp"

#include <array>
#include <utility>

namespace airseg::autopilot {

namespace {
constexpr std::array<std::pair<VehicleState, const char*>, 7> kStateNames = {{
    {VehicleState::Unknown, "unknown"},
    {VehicleState::ConfigureCheck, "configure_check"},
    {VehicleState::Parking, "parking"},
    {VehicleState::Directed, "directed"},
    {VehicleState::ManualNavigation, "manual_navigation"},
    {VehicleState::WaypointNavigation, "waypoint_navigation"},
    {VehicleState::Manual, "manual"},
}};
}  // namespace

const char* to_string(VehicleState s) {
    for (const auto& [state, name] : kStateNames) {
        if (state == s) {
            return name;
        }
    }
    return "?";
}

std::optional<VehicleState> vehicle_state_from_string(std::string_view text) {
    for (const auto& [state, name] : kStateNames) {
        if (text == name) {
            return state;
        }
    }
    return std::nullopt;
}

std::ostream& operator<<(std::ostream& os, VehicleState s) {
    return os << to_string(s);
}

const char* to_string(RequestResult r) {
    switch (r) {
        case RequestResult::Ok:
            return "ok";
        case RequestResult::Refused:
            return "refused";
        case RequestResult::Timeout:
            return "timeout";
        case RequestResult::Busy:
            return "busy";
        case RequestResult::NotReady:
            return "not ready";
        case RequestResult::Invalid:
            return "invalid";
        case RequestResult::Cancelled:
            return "cancelled";
    }
    return "?";
}

std::ostream& operator<<(std::ostream& os, RequestResult r) {
    return os << to_string(r);
}

const char* to_string(RequestKind k) {
    switch (k) {
        case RequestKind::SetState:
            return "set_state";
        case RequestKind::UploadMission:
            return "upload_mission";
        case RequestKind::WriteItems:
            return "write_items";
        case RequestKind::DownloadMission:
            return "download_mission";
        case RequestKind::SetCurrent:
            return "set_current";
        case RequestKind::ClearMission:
            return "clear_mission";
        case RequestKind::GetParam:
            return "get_param";
        case RequestKind::SetParam:
            return "set_param";
        case RequestKind::ListParams:
            return "list_params";
    }
    return "?";
}

RequestDone not_answered() {
    RequestDone done;
    done.result = RequestResult::Cancelled;
    done.detail = "not answered: the autopilot service is not running";
    return done;
}

}  // namespace airseg::autopilot

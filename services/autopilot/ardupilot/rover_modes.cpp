#include "services/autopilot/ardupilot/rover_modes.hpp"

namespace airseg::autopilot::ardupilot {

const char* rover_mode_known_name(std::uint32_t m) {
    switch (static_cast<RoverMode>(m)) {
        case RoverMode::Manual:
            return "MANUAL";
        case RoverMode::Acro:
            return "ACRO";
        case RoverMode::Steering:
            return "STEERING";
        case RoverMode::Hold:
            return "HOLD";
        case RoverMode::Loiter:
            return "LOITER";
        case RoverMode::Follow:
            return "FOLLOW";
        case RoverMode::Simple:
            return "SIMPLE";
        case RoverMode::Auto:
            return "AUTO";
        case RoverMode::Rtl:
            return "RTL";
        case RoverMode::SmartRtl:
            return "SMART_RTL";
        case RoverMode::Guided:
            return "GUIDED";
        case RoverMode::Initialising:
            return "INITIALISING";
    }
    return nullptr;
}

std::string rover_mode_name(std::uint32_t m) {
    const char* name = rover_mode_known_name(m);
    return name != nullptr ? std::string(name) : "MODE(" + std::to_string(m) + ")";
}

VehicleState state_for(std::uint32_t custom_mode, bool booting, bool override_active, bool failsafe_latched) {
    if (booting || custom_mode == static_cast<std::uint32_t>(RoverMode::Initialising)) {
        return VehicleState::ConfigureCheck;
    }
    if (failsafe_latched) {
        return VehicleState::Manual;
    }
    switch (static_cast<RoverMode>(custom_mode)) {
        case RoverMode::Hold:
        case RoverMode::Loiter:
            return VehicleState::Parking;
        case RoverMode::Manual:
            return override_active ? VehicleState::ManualNavigation : VehicleState::Directed;
        case RoverMode::Acro:
        case RoverMode::Steering:
        case RoverMode::Simple:
            return VehicleState::Directed;  // the RC pilot drives, with the autopilot's help
        case RoverMode::Auto:
            return VehicleState::WaypointNavigation;
        default:
            return VehicleState::Unknown;
    }
}

std::optional<RoverMode> mode_for(VehicleState s) {
    switch (s) {
        case VehicleState::Parking:
            return RoverMode::Hold;
        case VehicleState::Directed:
        case VehicleState::ManualNavigation:
        case VehicleState::Manual:
            return RoverMode::Manual;
        case VehicleState::WaypointNavigation:
            return RoverMode::Auto;
        case VehicleState::Unknown:
        case VehicleState::ConfigureCheck:
            return std::nullopt;
    }
    return std::nullopt;
}

std::optional<std::string> transition_refusal(VehicleState from, VehicleState to) {
    if (!mode_for(to)) {
        return std::string(to_string(to)) + " cannot be requested; the autopilot enters it by itself";
    }
    if (to == VehicleState::Manual) {
        return std::nullopt;  // the failsafe is always reachable
    }
    switch (from) {
        case VehicleState::Manual:
            return std::string("failsafe manual holds until an operator reset");
        case VehicleState::ConfigureCheck:
            return std::string("the autopilot is still booting or being configured");
        default:
            return std::nullopt;
    }
}

}  // namespace airseg::autopilot::ardupilot

#pragma once
// ArduPilot Rover's flight modes and how they map onto the neutral vehicle states, with the table of state
// transitions a requester may ask for.
#include <cstdint>
#include <optional>
#include <string>

#include "services/autopilot/autopilot.hpp"

namespace airseg::autopilot::ardupilot {

// Rover custom_mode numbers (ArduPilot Rover's mode enumeration).
enum class RoverMode : std::uint32_t {
    Manual = 0,
    Acro = 1,
    Steering = 3,
    Hold = 4,
    Loiter = 5,
    Follow = 6,
    Simple = 7,
    Auto = 10,
    Rtl = 11,
    SmartRtl = 12,
    Guided = 15,
    Initialising = 16,
};

/// "MANUAL", "HOLD", ...; "MODE(n)" for a number Rover does not define.
std::string rover_mode_name(std::uint32_t custom_mode);

/// "MANUAL", "HOLD", ...; nullptr for a number Rover does not define (the caller chooses how to show it).
const char* rover_mode_known_name(std::uint32_t custom_mode);

/// What a heartbeat says about the neutral state. `booting`: the autopilot reports BOOT/CALIBRATING or
/// is not yet READY in this system's eyes; `override_active`: the ground joystick drives (MANUAL +
/// RC override); `failsafe_latched`: the operator's failsafe MANUAL holds until an explicit reset.
/// Modes the neutral states do not name (RTL, SMART_RTL, GUIDED, FOLLOW) map to Unknown; the mode name
/// still says what the autopilot does.
VehicleState state_for(std::uint32_t custom_mode, bool booting, bool override_active, bool failsafe_latched);

/// The Rover mode a requested state needs, or nothing for states that cannot be requested
/// (Unknown, ConfigureCheck).
std::optional<RoverMode> mode_for(VehicleState requested);

/// Whether `to` may be requested while in `from`: empty when allowed, else why not.
std::optional<std::string> transition_refusal(VehicleState from, VehicleState to);

}  // namespace airseg::autopilot::ardupilot

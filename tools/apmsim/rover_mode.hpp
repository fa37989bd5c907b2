#pragma once
// ArduPilot Rover flight modes as they appear in HEARTBEAT.custom_mode.
#include <cstdint>
#include <optional>
#include <string_view>

namespace airseg::apmsim {

enum class RoverMode : std::uint32_t {
    Manual = 0,
    Acro = 1,
    Learning = 2,  // Rover 2.x only; later firmware dropped it
    Steering = 3,
    Hold = 4,
    Loiter = 5,
    Auto = 10,
    Rtl = 11,
    SmartRtl = 12,
    Guided = 15,
    Initialising = 16,
};

/// Upper-case name as ground stations show it ("AUTO"); "MODE<n>" style text is never needed because
/// only known modes are ever stored.
std::string_view mode_name(RoverMode mode);
/// Mode from its name (any case) or number; nothing if unknown.
std::optional<RoverMode> parse_mode(std::string_view text);
/// Mode from a custom_mode number; nothing if the rover has no such mode.
std::optional<RoverMode> mode_from_number(std::uint32_t number);
/// Modes the vehicle drives itself in (navigation to a target location).
bool is_navigating(RoverMode mode);

}  // namespace airseg::apmsim

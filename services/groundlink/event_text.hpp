#pragma once
// The words of the events pushed to the ground (airsegctl watch and log): what an operator needs to read,
// at the severity an operator should give it. Header-only: a few pure functions over bus messages.
#include <fmt/format.h>

#include <string>
#include <string_view>

#include "services/autopilot/autopilot.hpp"
#include "services/common/text.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::groundlink {

/// A vehicle state as the operator names it (the words of `airsegctl state`).
inline std::string state_words(autopilot::VehicleState s) {
    if (s == autopilot::VehicleState::ConfigureCheck) {
        return "STARTING";  // the connection sequence: parameters and streams set, not yet ready
    }
    return to_upper(autopilot::to_string(s));
}

/// "autopilot mode MANUAL -> HOLD" while the vehicle's state stays, "vehicle PARKING -> DIRECTED (autopilot
/// mode HOLD -> GUIDED)" when it changes; a change airsegd did not ask for says so.
inline std::string mode_change_text(const autopilot::ModeChanged& m) {
    const std::string modes = fmt::format("autopilot mode {} -> {}", m.from_mode, m.to_mode);
    const char* external =
        m.cause == autopilot::ModeChangeCause::External ? ", not asked for by airsegd (RC, failsafe)" : "";
    if (m.from == m.to) {
        return modes + external;
    }
    return fmt::format("vehicle {} -> {} ({}{})", state_words(m.from), state_words(m.to), modes, external);
}

/// The severity of an autopilot status text. MAV_SEVERITY 0..3 (emergency..error) is an error, except the
/// boot notices ArduPilot sends at CRITICAL or ALERT on every power-up (the sensor calibration, "Initialising
/// APM..."): routine, so info; a calibration that failed stays an error.
inline protocol::Event::Severity status_text_severity(int mav_severity, std::string_view text) {
    const std::string lower = to_lower(std::string(text));
    const auto has = [&lower](std::string_view word) { return lower.find(word) != std::string::npos; };
    const bool routine_boot =
        (has("beginning ins calibration") || has("calibrating") || has("calibration complete") ||
         has("initialising apm") || has("ground start") || has("warming up") || has("demo servos")) &&
        !has("fail") && !has("error") && !has("bad") && !has("prearm");
    if (mav_severity <= 3 && !routine_boot) {
        return protocol::Event::Severity::Error;
    }
    return mav_severity == 4 && !routine_boot ? protocol::Event::Severity::Warning
                                              : protocol::Event::Severity::Info;
}

}  // namespace airseg::groundlink

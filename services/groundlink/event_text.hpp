#pragma once
// The words of the events pushed to the ground (airsegctl watch and log): what an operator needs to read,
// at the severity an operator should give it. Header-only: a few pure functions over bus messages.
#include <fmt/format.h>

#include <optional>
#include <string>
#include <string_view>

#include "services/autopilot/autopilot.hpp"
#include "services/common/text.hpp"
#include "services/flightplan/plan_progress.hpp"
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

/// Nothing, for a change the operator cannot see: the same state and the same mode name (a reconnect's
/// configure check passing through), whatever moved it.
inline std::optional<std::string> mode_change_event(const autopilot::ModeChanged& m) {
    if (m.from == m.to && m.from_mode == m.to_mode) {
        return std::nullopt;
    }
    return mode_change_text(m);
}

/// Whether a text or a slot event has nothing to say while a flight plan drives the mission (running, or
/// paused with its window on the board): the autopilot's mission is then the plan's rolling window, so its
/// slots cycle and every rewrite of the window is "Flight plan received". The plan's own events say it once.
inline bool plan_drives_mission(flightplan::PlanState s) {
    return s == flightplan::PlanState::Running || s == flightplan::PlanState::Paused;
}

/// ArduPilot's texts about its mission that the rolling window causes on every waypoint: "Reached waypoint
/// #N dist Mm" (N a slot of the window), "Flight plan received" (each rewrite), "Mission: N ..." (each item
/// started). While a plan drives, the plan's own event replaces them (they are counted in status,
/// groundlink.events_folded).
inline bool is_window_text(std::string_view text) {
    const std::string lower = to_lower(std::string(text));  // older boards say "flight plan received"
    return lower.starts_with("reached waypoint #") || lower.starts_with("flight plan received") ||
           lower.starts_with("mission: ");
}

/// "plan waypoint 7 reached" when the plan's reached count grows by one (its number is the plan's, as
/// `next waypoint` shows it before); "plan waypoints reached: 3 more, next 12" when several are counted at
/// once; nothing otherwise (a new plan starts its count again).
inline std::optional<std::string> plan_reached_text(const flightplan::PlanProgress& before,
                                                    const flightplan::PlanProgress& after) {
    if (after.waypoints_reached <= before.waypoints_reached) {
        return std::nullopt;
    }
    const auto more = after.waypoints_reached - before.waypoints_reached;
    if (more == 1) {
        return fmt::format("plan waypoint {} reached", before.next_waypoint);
    }
    return fmt::format("plan waypoints reached: {} more, next {}", more, after.next_waypoint);
}

/// The plan last announced to the ground: which one, and how many plans had been appended to it then.
struct AnnouncedPlan {
    std::uint32_t generation = 0;
    std::uint32_t extensions = 0;
    bool operator==(const AnnouncedPlan&) const = default;
};

/// "plan 'north field' started" (or "plan 'north field' loaded, paused") when a plan other than the one last
/// announced drives the vehicle: loaded, or resumed after a restart, even over a plan still running; "plan
/// 'north field' extended" when another plan was appended to the one announced (its waypoint count grew).
/// The ground's views ask for the plan's facts again on each (groundside::announces_plan); `announced` is
/// none before the first.
inline std::optional<std::string> plan_announcement_text(std::optional<AnnouncedPlan> announced,
                                                         const flightplan::PlanProgress& now) {
    if (!plan_drives_mission(now.state)) {
        return std::nullopt;
    }
    if (!announced || announced->generation != now.generation) {
        return fmt::format("plan '{}' {}", now.name,
                           now.state == flightplan::PlanState::Paused ? "loaded, paused" : "started");
    }
    if (now.extensions != announced->extensions) {
        return fmt::format("plan '{}' extended", now.name);
    }
    return std::nullopt;
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

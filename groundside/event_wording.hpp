#pragma once
// The words of the vehicle's events on the ground, shared by airseg-ground's live map, `airsegctl watch` and
// `airsegctl log`, so the three say the same thing. Events are said in plan terms, once per happening:
//
// - "plan waypoint 7 reached" (the plan's 0-based index) is "waypoint 8 of 12 reached": numbered from 1 as
//   the map numbers the plan's waypoints, "of N" when the plan's waypoint count is known (the map's hub asks
//   the vehicle for it; watch and log, which poll nothing, say "waypoint 8 reached").
// - While a plan drives the autopilot (running or paused), the autopilot's mission is the plan's rolling
//   window: its slot events ("mission slot 3 reached") and the board's texts about it ("Reached waypoint #3",
//   "Flight plan received", "Mission: ...") are debug lines. A vehicle folds them itself; these rules also
//   fold what an older vehicle still sends.
// - A mode change that changes nothing ("autopilot mode MANUAL -> MANUAL") is a debug line.
// - The same words again within a few seconds, or a waypoint already said reached, are debug lines.
//
// A debug line keeps the vehicle's own text (slot numbers and all): shown only in a debug view.
//
// Where the plan is, said as the map says it (ground/map/web/map.js showProgress): "running — waypoint 4 of
// 12 — scan 'north field' — 2.1 km left (about 3 min)". The telemetry gives the state, the next waypoint's
// index and the top-level element; the plan's count and its elements' names come from plan.show, its
// waypoints (for the distance left) from plan.geometry: PlanFacts holds what is known of them.
#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::groundside {

struct WordedEvent {
    groundlink::protocol::Event::Severity severity = groundlink::protocol::Event::Severity::Info;
    std::string text;    // what the operator reads
    std::string raw;     // what the vehicle sent (the debug view's words)
    bool debug = false;  // no happening of its own: shown only in a debug view
};

/// The words of one event given what is known of the plan; stateless (no de-duplication).
/// `plan_state` is the telemetry's code (0 none, 1 running, 2 paused, ...); `waypoints` the plan's count.
WordedEvent word_event(const groundlink::protocol::Event& e, std::uint8_t plan_state,
                       std::optional<std::uint64_t> waypoints);

/// The vehicle's announcement that another plan drives it ("plan 'north field' started", "plan 'x' loaded,
/// paused"; groundlink/event_text.hpp), or that a plan was appended to it ("plan 'x' extended"): what the
/// ground knew of the plan (its count, its elements) is no longer true.
bool announces_plan(std::string_view text);

/// The announcement of an append ("plan 'x' extended"): the same plan goes on, with more waypoints.
bool extends_plan(std::string_view text);

/// "waypoint 8 of 12" (index 7, 12 waypoints), "waypoint 8" without a count: the plan's numbering.
std::string waypoint_words(std::uint64_t index, std::optional<std::uint64_t> waypoints);

/// What the ground knows of the running plan beyond the telemetry; each part may be missing.
struct PlanFacts {
    struct Element {
        std::string path;  // "plan.elements[2]"
        std::string kind;  // waypoint, scan, hold, orbit
        std::string name;  // empty when it has none
    };
    /// The expanded plan's waypoint count (none when unknown or endless).
    std::optional<std::uint64_t> waypoints;
    /// Its top-level elements in order: the telemetry's plan_element indexes them.
    std::vector<Element> top;
    /// Its waypoints in plan order, {lat, lon}, when they number exactly `waypoints` (else empty).
    std::vector<std::pair<double, double>> route;
};

/// The facts in plan.show's result (its "elements", each with "waypoints": null when endless) and, when
/// given, plan.geometry's result (its elements' points, a scan's lines); anything malformed is left out.
PlanFacts plan_facts(const nlohmann::json& show, const nlohmann::json& geometry = nlohmann::json());

/// "running — waypoint 4 of 12 — scan 'north field' — 2.1 km left (about 3 min)" from a telemetry sample
/// and what is known of its plan: the parts not known are left out; "no plan running" without a plan.
std::string progress_words(const groundlink::protocol::Telemetry& t, const PlanFacts& plan);

/// "2.1 km", "140 m": a distance as the map says it.
std::string distance_words(double metres);

/// The events of one vehicle in order, worded and de-duplicated: each happening once.
class EventWording {
  public:
    using Clock = std::chrono::steady_clock;
    /// The same words again within this span is the same happening said twice.
    static constexpr auto kRepeatSpan = std::chrono::seconds(5);

    /// The plan state from the latest telemetry sample; a change of plan starts the waypoint count again.
    void set_plan_state(std::uint8_t plan_state);
    /// The plan's waypoint count when known (a new plan: nothing until it is known again).
    void set_waypoints(std::optional<std::uint64_t> waypoints) { waypoints_ = waypoints; }
    /// Takes the plan state from a telemetry message; events are worded (a plan's announcement forgets the
    /// count, set_waypoints tells the new one); anything else is ignored.
    std::optional<WordedEvent> take(const groundlink::protocol::Message& m, Clock::time_point now);
    WordedEvent word(const groundlink::protocol::Event& e, Clock::time_point now);

    [[nodiscard]] std::uint8_t plan_state() const { return plan_state_; }
    [[nodiscard]] std::optional<std::uint64_t> waypoints() const { return waypoints_; }

  private:
    std::uint8_t plan_state_ = 0;
    std::optional<std::uint64_t> waypoints_;
    std::optional<std::uint64_t> last_reached_;  // the last plan index said reached, in this plan
    std::string last_text_;
    Clock::time_point last_at_{};
};

}  // namespace airseg::groundside

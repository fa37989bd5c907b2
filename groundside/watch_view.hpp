#pragma once
// airsegctl watch over the radio: what the vehicle pushes (telemetry samples, its link statistics, events)
// gathered into one picture, and that picture as a screen of text or as one JSON line. The sample and event
// in JSON (telemetry_json, event_severity_name) are also what airseg-ground's fleet bridge publishes.
#include <chrono>
#include <deque>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "groundside/event_wording.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::groundside {

class WatchState {
  public:
    using Clock = std::chrono::steady_clock;
    static constexpr std::size_t kRecentEvents = 8;

    /// Takes one message from the vehicle, received at `now`.
    void take(const groundlink::protocol::Message& message, Clock::time_point now);
    /// The ground end's own view of the link (RadioClient::link_stats()).
    void set_ground_link(nlohmann::json stats) { ground_link_ = std::move(stats); }
    /// What is known of the plan beyond the telemetry (plan.show, plan.geometry): its progress is then said
    /// as the map says it ("waypoint 4 of 12", the element by name, the distance left), and its events too.
    void set_plan(PlanFacts plan);
    [[nodiscard]] const PlanFacts& plan() const { return plan_; }
    /// Also list the events that say nothing new (debug lines, in the vehicle's own words).
    void set_debug(bool on) { debug_ = on; }

    /// Samples per second over the last few seconds.
    [[nodiscard]] double sample_rate(Clock::time_point now) const;
    [[nodiscard]] std::uint64_t samples() const { return samples_; }
    [[nodiscard]] const std::optional<groundlink::protocol::Telemetry>& latest() const { return latest_; }

    [[nodiscard]] std::string render(Clock::time_point now) const;
    [[nodiscard]] nlohmann::json to_json(Clock::time_point now) const;

  private:
    std::optional<groundlink::protocol::Telemetry> latest_;
    Clock::time_point latest_at_{};
    std::deque<Clock::time_point> sample_times_;
    std::uint64_t samples_ = 0;
    std::optional<groundlink::protocol::LinkStatsReport> vehicle_link_;
    std::deque<std::string> events_;
    EventWording wording_;  // events in plan terms, each happening once
    PlanFacts plan_;
    bool debug_ = false;
    nlohmann::json ground_link_ = nlohmann::json::object();
};

/// The telemetry's plan state code by name: none, running, paused, done, interrupted, failed.
const char* plan_state_name(std::uint8_t code);
/// A telemetry sample as JSON (state and mode by name, position, speeds, battery, GPS, plan progress).
nlohmann::json telemetry_json(const groundlink::protocol::Telemetry& t);
/// "info", "warning" or "error".
const char* event_severity_name(groundlink::protocol::Event::Severity s);
/// An event as one line for people: "warning: text".
std::string event_line(const groundlink::protocol::Event& e);
/// A worded event as one line: "info: waypoint 8 reached"; in a debug view, a debug line is marked and in
/// the vehicle's words ("info: (debug) mission slot 3 reached"), a reworded one shows them after its own.
std::string event_line(const WordedEvent& e, bool debug_view);

}  // namespace airseg::groundside

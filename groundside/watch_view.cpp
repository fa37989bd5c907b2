#include "groundside/watch_view.hpp"

#include <fmt/format.h>

#include "services/autopilot/ardupilot/rover_modes.hpp"

namespace airseg::groundside {

namespace proto = groundlink::protocol;

namespace {

constexpr auto kRateWindow = std::chrono::seconds(5);

// The wire carries the autopilot's mode number; its name comes from the autopilot's own table, and a number
// without one (or the "no mode" code) shows as "?".
const char* mode_name(std::uint8_t code) {
    const char* name = autopilot::ardupilot::rover_mode_known_name(code);
    return name != nullptr ? name : "?";
}

double seconds(std::chrono::steady_clock::duration d) {
    return std::chrono::duration<double>(d).count();
}

}  // namespace

const char* plan_state_name(std::uint8_t s) {
    switch (s) {
        case 1:
            return "running";
        case 2:
            return "paused";
        case 3:
            return "done";
        case 4:
            return "interrupted";
        case 5:
            return "failed";
        default:
            return "none";
    }
}

nlohmann::json telemetry_json(const proto::Telemetry& t) {
    nlohmann::json j{{"state", proto::vehicle_state_name(t.vehicle_state)},
                     {"mode", mode_name(t.mode)},
                     {"lat", t.lat_deg},
                     {"lon", t.lon_deg},
                     {"alt_m", t.alt_m},
                     {"ground_speed_mps", t.ground_speed_mps},
                     {"heading_deg", t.heading_deg},
                     {"roll_deg", t.roll_deg},
                     {"pitch_deg", t.pitch_deg},
                     {"battery_v", t.battery_v},
                     {"gps_fix", t.gps_fix},
                     {"satellites", t.satellites},
                     {"position_valid", !t.no_position}};
    if (t.no_position) {
        // No fix: no place, never 0,0 (a consumer drawing it would draw a line to the Gulf of Guinea).
        j["lat"] = nullptr;
        j["lon"] = nullptr;
    }
    j["battery_pct"] = t.battery_pct ? nlohmann::json(*t.battery_pct) : nlohmann::json();
    if (t.plan_state != 0) {
        j["plan"] = {{"state", plan_state_name(t.plan_state)},
                     {"element", t.plan_element},
                     {"next_waypoint", t.next_waypoint}};
    }
    return j;
}

const char* event_severity_name(proto::Event::Severity s) {
    switch (s) {
        case proto::Event::Severity::Warning:
            return "warning";
        case proto::Event::Severity::Error:
            return "error";
        default:
            return "info";
    }
}

std::string event_line(const proto::Event& e) {
    return fmt::format("{}: {}", event_severity_name(e.severity), e.text);
}

std::string event_line(const WordedEvent& e, bool debug_view) {
    const char* severity = event_severity_name(e.severity);
    if (!debug_view) {
        return fmt::format("{}: {}", severity, e.text);
    }
    if (e.debug) {
        return fmt::format("{}: (debug) {}", severity, e.raw);
    }
    return e.raw == e.text ? fmt::format("{}: {}", severity, e.text)
                           : fmt::format("{}: {} [{}]", severity, e.text, e.raw);
}

void WatchState::set_plan(PlanFacts plan) {
    wording_.set_waypoints(plan.waypoints);
    plan_ = std::move(plan);
}

void WatchState::take(const proto::Message& message, Clock::time_point now) {
    if (auto worded = wording_.take(message, now)) {
        if (announces_plan(worded->raw)) {
            plan_ = {};  // the last plan's facts are not this one's; set_plan tells the new ones
        }
        if (!worded->debug || debug_) {
            events_.push_back(event_line(*worded, debug_));
            while (events_.size() > kRecentEvents) {
                events_.pop_front();
            }
        }
        return;
    }
    if (const auto* t = std::get_if<proto::Telemetry>(&message)) {
        latest_ = *t;
        latest_at_ = now;
        ++samples_;
        sample_times_.push_back(now);
        while (!sample_times_.empty() && now - sample_times_.front() > kRateWindow) {
            sample_times_.pop_front();
        }
    } else if (const auto* s = std::get_if<proto::LinkStatsReport>(&message)) {
        vehicle_link_ = *s;
    }
}

double WatchState::sample_rate(Clock::time_point now) const {
    std::size_t n = 0;
    for (auto t : sample_times_) {
        n += now - t <= kRateWindow ? 1 : 0;
    }
    return static_cast<double>(n) / seconds(kRateWindow);
}

std::string WatchState::render(Clock::time_point now) const {
    std::string out = "airsegctl watch  (Ctrl-C to quit)\n\n";
    if (!latest_) {
        out += "vehicle     no telemetry yet\n";
    } else {
        const auto& t = *latest_;
        out += fmt::format("state       {:<20} mode {}\n", proto::vehicle_state_name(t.vehicle_state),
                           mode_name(t.mode));
        if (t.gps_fix < 2) {
            out += "position    no GPS fix\n";
        } else if (t.no_position) {
            out += "position    none valid (the vehicle refused what the autopilot reported)\n";
        } else {
            out += fmt::format("position    {:.7f} {:.7f}  alt {:.1f} m\n", t.lat_deg, t.lon_deg, t.alt_m);
        }
        out += fmt::format("speed       {:.2f} m/s  heading {:.1f}°  roll {}° pitch {}°\n",
                           t.ground_speed_mps, t.heading_deg, t.roll_deg, t.pitch_deg);
        out += fmt::format(
            "battery     {:.2f} V  {}\n", t.battery_v,
            t.battery_pct ? fmt::format("{} %", *t.battery_pct) : std::string("remaining unknown"));
        out += fmt::format("gps         fix {}  {} satellites\n", t.gps_fix, t.satellites);
        if (t.plan_state != 0) {
            // The numbers plan.skip takes (the index counts from 0), then the plan in plan terms as the map
            // says it.
            out += fmt::format("plan        {}  element {}  next waypoint {} (index {})\n",
                               plan_state_name(t.plan_state), t.plan_element, t.next_waypoint + 1,
                               t.next_waypoint);
            out += fmt::format("progress    {}\n", progress_words(t, plan_));
        }
        out += fmt::format("telemetry   {:.1f} samples/s, last {:.1f} s ago, {} received\n", sample_rate(now),
                           seconds(now - latest_at_), samples_);
    }
    out += "\nlink        ";
    if (vehicle_link_) {
        const auto& l = *vehicle_link_;
        out += fmt::format("vehicle: rtt {} ms, loss {:.1f} %, goodput {} B/s, {} retransmissions\n",
                           l.rtt_ms, l.loss_permille / 10.0, l.goodput_bps, l.retransmissions);
        out += "            ";
    }
    // Loss as a percentage, as the vehicle's side above and the map show it (the ground end gives a
    // fraction).
    out += fmt::format("ground: {} rtt {} ms, loss {:.1f} %, {} frames received, {} crc errors\n",
                       ground_link_.value("link", std::string("?")), ground_link_.value("rtt_ms", 0.0),
                       ground_link_.value("loss", 0.0) * 100, ground_link_.value("frames_received", 0),
                       ground_link_.value("crc_errors", 0));
    out += "\nrecent events\n";
    if (events_.empty()) {
        out += "  (none)\n";
    }
    for (const auto& e : events_) {
        out += "  " + e + "\n";
    }
    return out;
}

nlohmann::json WatchState::to_json(Clock::time_point now) const {
    nlohmann::json j{{"samples", samples_}, {"sample_rate", sample_rate(now)}, {"ground_link", ground_link_}};
    j["vehicle"] = latest_ ? telemetry_json(*latest_) : nlohmann::json();
    if (latest_ && latest_->plan_state != 0) {
        j["vehicle"]["plan"]["progress"] = progress_words(*latest_, plan_);
        j["vehicle"]["plan"]["waypoints"] =
            plan_.waypoints ? nlohmann::json(*plan_.waypoints) : nlohmann::json();
    }
    if (vehicle_link_) {
        j["vehicle_link"] = {{"rtt_ms", vehicle_link_->rtt_ms},
                             {"loss_permille", vehicle_link_->loss_permille},
                             {"goodput_bps", vehicle_link_->goodput_bps},
                             {"retransmissions", vehicle_link_->retransmissions}};
    }
    j["events"] = events_;
    return j;
}

}  // namespace airseg::groundside

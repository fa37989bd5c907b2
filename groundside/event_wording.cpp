#include "groundside/event_wording.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>

#include "groundside/watch_view.hpp"

namespace airseg::groundside {

namespace proto = groundlink::protocol;

namespace {

bool plan_drives(std::uint8_t plan_state) {
    return plan_state == 1 || plan_state == 2;  // running, paused: the board's mission is the plan's window
}

/// A whole number at the start of `s`, advancing past it.
std::optional<std::uint64_t> number(std::string_view& s) {
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end == s.data()) {
        return std::nullopt;
    }
    s.remove_prefix(static_cast<std::size_t>(end - s.data()));
    return value;
}

bool eat(std::string_view& s, std::string_view prefix) {
    if (!s.starts_with(prefix)) {
        return false;
    }
    s.remove_prefix(prefix.size());
    return true;
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (auto& c : out) {
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    return out;
}

/// "plan waypoint 7 reached": 7.
std::optional<std::uint64_t> plan_reached(std::string_view s) {
    if (!eat(s, "plan waypoint ")) {
        return std::nullopt;
    }
    const auto index = number(s);
    return index && s == " reached" ? index : std::nullopt;
}

/// "plan waypoints reached: 3 more, next 12": {3, 12}.
std::optional<std::pair<std::uint64_t, std::uint64_t>> plan_reached_several(std::string_view s) {
    if (!eat(s, "plan waypoints reached: ")) {
        return std::nullopt;
    }
    const auto more = number(s);
    if (!more || !eat(s, " more, next ")) {
        return std::nullopt;
    }
    const auto next = number(s);
    if (!next || !s.empty()) {
        return std::nullopt;
    }
    return std::pair{*more, *next};
}

/// The slot events and the board's texts the plan's rolling window causes on every waypoint.
bool window_noise(std::string_view s) {
    std::string_view rest = s;
    if (eat(rest, "mission slot ") && number(rest) && rest == " reached") {
        return true;
    }
    rest = s;
    if (!eat(rest, "autopilot: ")) {
        return false;
    }
    const std::string text = lower(rest);  // older boards say "flight plan received"
    return text.starts_with("reached waypoint #") || text.starts_with("flight plan received") ||
           text.starts_with("mission: ");
}

/// "autopilot mode MANUAL -> MANUAL" (with or without the note of who asked): nothing changed.
bool same_mode(std::string_view s) {
    if (!eat(s, "autopilot mode ")) {
        return false;
    }
    const auto arrow = s.find(" -> ");
    if (arrow == std::string_view::npos) {
        return false;
    }
    const auto from = s.substr(0, arrow);
    auto to = s.substr(arrow + 4);
    to = to.substr(0, to.find(','));
    return !from.empty() && from == to;
}

/// Great-circle metres on Leaflet's sphere (radius 6371000 m, its map.distance): the map's measure, so the
/// distance left reads the same on the map and in a terminal.
double map_distance(std::pair<double, double> a, std::pair<double, double> b) {
    constexpr double kRadius = 6371000.0;
    constexpr double kRad = M_PI / 180.0;
    const double dlat = (b.first - a.first) * kRad;
    const double dlon = (b.second - a.second) * kRad;
    const double h = std::sin(dlat / 2) * std::sin(dlat / 2) + std::cos(a.first * kRad) *
                                                                   std::cos(b.first * kRad) *
                                                                   std::sin(dlon / 2) * std::sin(dlon / 2);
    return 2.0 * kRadius * std::atan2(std::sqrt(h), std::sqrt(1.0 - h));
}

std::string text_of(const nlohmann::json& j, const char* key) {
    const auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// [[lat, lon], ...] as pairs; false if any point is malformed.
bool points_of(const nlohmann::json& j, std::vector<std::pair<double, double>>& out) {
    if (!j.is_array()) {
        return false;
    }
    for (const auto& p : j) {
        if (!p.is_array() || p.size() < 2 || !p[0].is_number() || !p[1].is_number()) {
            return false;
        }
        out.emplace_back(p[0].get<double>(), p[1].get<double>());
    }
    return true;
}

/// The plan's waypoints in plan order as the map numbers them (map.js planRoute): the points of the main
/// list's elements (a scan's lines), when they are exactly the plan's count; otherwise none.
std::vector<std::pair<double, double>> route_of(const nlohmann::json& geometry, std::uint64_t waypoints) {
    std::vector<std::pair<double, double>> route;
    const auto elements = geometry.find("elements");
    if (!geometry.is_object() || geometry.value("truncated", true) || elements == geometry.end() ||
        !elements->is_array()) {
        return {};
    }
    for (const auto& e : *elements) {
        if (!e.is_object() || text_of(e, "path").starts_with("plan.blocks")) {
            continue;
        }
        const auto pts = e.find(e.value("closed", false) ? "lines" : "points");
        if (pts == e.end() || !points_of(*pts, route) || route.size() > waypoints) {
            return {};
        }
    }
    return route.size() == waypoints ? route : std::vector<std::pair<double, double>>{};
}

}  // namespace

PlanFacts plan_facts(const nlohmann::json& show, const nlohmann::json& geometry) {
    PlanFacts facts;
    const auto elements = show.is_object() ? show.find("elements") : show.end();
    if (!show.is_object() || elements == show.end() || !elements->is_array()) {
        return facts;
    }
    std::uint64_t total = 0;
    bool counted = true;
    for (const auto& e : *elements) {
        if (!e.is_object()) {
            return {};
        }
        facts.top.push_back({text_of(e, "path"), text_of(e, "kind"), text_of(e, "name")});
        const auto n = e.find("waypoints");
        if (n != e.end() && n->is_number_unsigned()) {
            total += n->get<std::uint64_t>();
        } else {
            counted = false;  // an endless repeat: no count
        }
    }
    if (counted) {
        facts.waypoints = total;
        facts.route = route_of(geometry, total);
    }
    return facts;
}

std::string distance_words(double metres) {
    return metres >= 1000 ? fmt::format("{:.1f} km", metres / 1000)
                          : fmt::format("{} m", std::lround(metres));
}

std::string progress_words(const proto::Telemetry& t, const PlanFacts& plan) {
    if (t.plan_state == 0) {
        return "no plan running";
    }
    std::string out = plan_state_name(t.plan_state);
    if (!plan_drives(t.plan_state)) {
        return out;
    }
    out += " — " + waypoint_words(t.next_waypoint, plan.waypoints);
    if (t.plan_element < plan.top.size()) {
        const auto& e = plan.top[t.plan_element];
        out += " — " + e.kind + (e.name.empty() ? " " + e.path : " '" + e.name + "'");
    }
    if (!t.no_position && t.next_waypoint < plan.route.size()) {
        double left = map_distance({t.lat_deg, t.lon_deg}, plan.route[t.next_waypoint]);
        for (std::size_t i = t.next_waypoint + 1; i < plan.route.size(); ++i) {
            left += map_distance(plan.route[i - 1], plan.route[i]);
        }
        out += " — " + distance_words(left) + " left";
        if (t.ground_speed_mps > 0.3) {
            const double s = left / t.ground_speed_mps;  // at the present speed
            out += s < 90 ? fmt::format(" (about {} s)", std::max(1L, std::lround(s)))
                          : fmt::format(" (about {} min)", std::lround(s / 60));
        }
    }
    return out;
}

bool announces_plan(std::string_view text) {
    return text.starts_with("plan '") && (text.ends_with("' started") || text.ends_with("' loaded, paused") ||
                                          extends_plan(text));
}

bool extends_plan(std::string_view text) {
    return text.starts_with("plan '") && text.ends_with("' extended");
}

std::string waypoint_words(std::uint64_t index, std::optional<std::uint64_t> waypoints) {
    if (waypoints && index < *waypoints) {
        return fmt::format("waypoint {} of {}", index + 1, *waypoints);
    }
    return fmt::format("waypoint {}", index + 1);
}

WordedEvent word_event(const proto::Event& e, std::uint8_t plan_state,
                       std::optional<std::uint64_t> waypoints) {
    WordedEvent out{e.severity, e.text, e.text, false};
    if (const auto index = plan_reached(e.text)) {
        out.text = waypoint_words(*index, waypoints) + " reached";
    } else if (const auto several = plan_reached_several(e.text)) {
        out.text = fmt::format("{} waypoints reached, heading for {}", several->first,
                               waypoint_words(several->second, waypoints));
    } else if (plan_drives(plan_state) && window_noise(e.text)) {
        out.debug = true;
    } else if (same_mode(e.text)) {
        out.debug = true;
    }
    return out;
}

void EventWording::set_plan_state(std::uint8_t plan_state) {
    if (plan_state != plan_state_ && !(plan_drives(plan_state) && plan_drives(plan_state_))) {
        last_reached_.reset();  // a plan started, ended or was replaced: its waypoints are new happenings
    }
    plan_state_ = plan_state;
}

std::optional<WordedEvent> EventWording::take(const proto::Message& m, Clock::time_point now) {
    if (const auto* t = std::get_if<proto::Telemetry>(&m)) {
        set_plan_state(t->plan_state);
        return std::nullopt;
    }
    if (const auto* e = std::get_if<proto::Event>(&m)) {
        return word(*e, now);
    }
    return std::nullopt;
}

WordedEvent EventWording::word(const proto::Event& e, Clock::time_point now) {
    auto out = word_event(e, plan_state_, waypoints_);
    if (out.debug) {
        return out;
    }
    if (announces_plan(e.text)) {
        waypoints_.reset();  // its count is not known yet
        if (!extends_plan(e.text)) {
            last_reached_.reset();  // another plan: its waypoints are new happenings
        }
    } else if (const auto index = plan_reached(e.text)) {
        if (last_reached_ == *index) {
            out.debug = true;  // said already (a redelivery, a second path to the same vehicle)
            return out;
        }
        last_reached_ = *index;
    } else if (const auto several = plan_reached_several(e.text); several && several->second > 0) {
        last_reached_ = several->second - 1;
    }
    if (out.text == last_text_ && now - last_at_ < kRepeatSpan) {
        out.debug = true;
        return out;
    }
    last_text_ = out.text;
    last_at_ = now;
    return out;
}

}  // namespace airseg::groundside

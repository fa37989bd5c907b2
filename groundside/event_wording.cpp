#include "groundside/event_wording.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>

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

}  // namespace

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
    if (const auto index = plan_reached(e.text)) {
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

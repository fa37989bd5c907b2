#pragma once
#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace airseg::daemon {

/// Parses a duration written for people: "1500ms", "3s", "0.5s", "2m", "1h". A bare number is refused so
/// that "3" can never silently mean milliseconds in one place and seconds in another.
std::optional<std::chrono::milliseconds> parse_duration(std::string_view text);

/// The shortest exact spelling: 1500ms, 3s, 2m.
std::string format_duration(std::chrono::milliseconds d);

}  // namespace airseg::daemon

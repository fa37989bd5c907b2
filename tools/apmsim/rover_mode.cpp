#include "tools/apmsim/rover_mode.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <utility>

namespace airseg::apmsim {

namespace {

constexpr std::array<std::pair<RoverMode, std::string_view>, 11> kNames{{
    {RoverMode::Manual, "MANUAL"},
    {RoverMode::Acro, "ACRO"},
    {RoverMode::Learning, "LEARNING"},
    {RoverMode::Steering, "STEERING"},
    {RoverMode::Hold, "HOLD"},
    {RoverMode::Loiter, "LOITER"},
    {RoverMode::Auto, "AUTO"},
    {RoverMode::Rtl, "RTL"},
    {RoverMode::SmartRtl, "SMART_RTL"},
    {RoverMode::Guided, "GUIDED"},
    {RoverMode::Initialising, "INITIALISING"},
}};

bool same_ignoring_case(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) {
        return false;
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::toupper(static_cast<unsigned char>(a[i])) !=
            std::toupper(static_cast<unsigned char>(b[i]))) {
            return false;
        }
    }
    return true;
}

}  // namespace

std::string_view mode_name(RoverMode mode) {
    for (const auto& [m, name] : kNames) {
        if (m == mode) {
            return name;
        }
    }
    return "UNKNOWN";
}

std::optional<RoverMode> mode_from_number(std::uint32_t number) {
    for (const auto& [m, name] : kNames) {
        if (static_cast<std::uint32_t>(m) == number) {
            return m;
        }
    }
    return std::nullopt;
}

std::optional<RoverMode> parse_mode(std::string_view text) {
    for (const auto& [m, name] : kNames) {
        if (same_ignoring_case(text, name)) {
            return m;
        }
    }
    std::uint32_t number = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
    if (ec == std::errc() && end == text.data() + text.size() && !text.empty()) {
        return mode_from_number(number);
    }
    return std::nullopt;
}

bool is_navigating(RoverMode mode) {
    return mode == RoverMode::Auto || mode == RoverMode::Rtl || mode == RoverMode::SmartRtl ||
           mode == RoverMode::Guided;
}

}  // namespace airseg::apmsim

#include "daemon/duration.hpp"

#include <charconv>
#include <cmath>

namespace airseg::daemon {

std::optional<std::chrono::milliseconds> parse_duration(std::string_view text) {
    struct Unit {
        std::string_view suffix;
        double ms;
    };
    // "ms" must be tried before "m" and "s".
    static constexpr Unit kUnits[] = {{"ms", 1.0}, {"s", 1000.0}, {"m", 60'000.0}, {"h", 3'600'000.0}};
    for (const auto& unit : kUnits) {
        if (text.size() <= unit.suffix.size() || !text.ends_with(unit.suffix)) {
            continue;
        }
        auto number = text.substr(0, text.size() - unit.suffix.size());
        double value = 0;
        auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
        if (ec != std::errc{} || end != number.data() + number.size() || !(value >= 0) ||
            !std::isfinite(value)) {
            return std::nullopt;
        }
        const double ms = value * unit.ms;
        if (ms > 1e15) {
            return std::nullopt;
        }
        return std::chrono::milliseconds(static_cast<long long>(std::llround(ms)));
    }
    return std::nullopt;
}

std::string format_duration(std::chrono::milliseconds d) {
    const auto ms = d.count();
    if (ms != 0 && ms % 3'600'000 == 0) {
        return std::to_string(ms / 3'600'000) + "h";
    }
    if (ms != 0 && ms % 60'000 == 0) {
        return std::to_string(ms / 60'000) + "m";
    }
    if (ms != 0 && ms % 1000 == 0) {
        return std::to_string(ms / 1000) + "s";
    }
    return std::to_string(ms) + "ms";
}

}  // namespace airseg::daemon

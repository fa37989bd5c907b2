#include "cli/values.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

namespace airseg::cli {

namespace {

[[noreturn]] void fail(std::string_view option, std::string_view text, std::string_view wanted) {
    throw UsageError(std::string(option) + ": expected " + std::string(wanted) + ", got '" +
                     std::string(text) + "'");
}

/// A bound as people write it: 100, 0.1, 1e+09 (not 100.000000).
std::string bound(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

Duration from_seconds(double s) {
    return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s));
}

}  // namespace

std::uint64_t parse_unsigned(std::string_view option, std::string_view text, std::uint64_t min,
                             std::uint64_t max) {
    std::uint64_t v = 0;
    auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() || v < min || v > max) {
        fail(option, text,
             "a whole number within [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    return v;
}

double parse_double(std::string_view option, std::string_view text, double min, double max) {
    double v = 0;
    auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() || !std::isfinite(v) ||
        v < min || v > max) {
        fail(option, text, "a number within [" + bound(min) + ", " + bound(max) + "]");
    }
    return v;
}

double parse_probability(std::string_view option, std::string_view text) {
    return parse_double(option, text, 0.0, 1.0);
}

Duration parse_seconds(std::string_view option, std::string_view text) {
    return from_seconds(parse_double(option, text, 0.0, 1e7));
}

Duration parse_milliseconds(std::string_view option, std::string_view text) {
    return from_seconds(parse_double(option, text, 0.0, 1e9) / 1000.0);
}

Window parse_window(std::string_view option, std::string_view text) {
    const auto colon = text.find(':');
    if (colon == std::string_view::npos) {
        fail(option, text, "START:DURATION in seconds");
    }
    Window w{parse_seconds(option, text.substr(0, colon)), parse_seconds(option, text.substr(colon + 1))};
    if (w.length <= Duration::zero()) {
        fail(option, text, "a positive DURATION in START:DURATION");
    }
    return w;
}

}  // namespace airseg::cli

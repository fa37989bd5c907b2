#pragma once
// Command-line values shared by every program (also the simulators' control commands): every failure names
// the option and the bad text.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "base/time.hpp"

namespace airseg::cli {

/// Thrown by the parsers below; what() is ready to print after the program's name.
class UsageError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// Whole number within [min, max].
std::uint64_t parse_unsigned(std::string_view option, std::string_view text, std::uint64_t min,
                             std::uint64_t max);
/// Finite decimal number within [min, max].
double parse_double(std::string_view option, std::string_view text, double min, double max);
/// Probability within [0, 1].
double parse_probability(std::string_view option, std::string_view text);
/// Non-negative seconds with a fraction ("2", "0.5").
Duration parse_seconds(std::string_view option, std::string_view text);
/// Non-negative milliseconds with a fraction.
Duration parse_milliseconds(std::string_view option, std::string_view text);

struct Window {
    Duration start{0};
    Duration length{0};
};
/// "START:DURATION" in seconds, e.g. "60:30"; the duration must be positive.
Window parse_window(std::string_view option, std::string_view text);

}  // namespace airseg::cli

#pragma once
// Blink patterns as pure functions of time (no timer, no GPIO): what level a line shows at time t after the
// pattern started, and when it next changes. A pattern is one cycle of on/off steps that repeats; what a
// pattern means belongs to its owner (the status LED's meanings are in services/autopilot/status_led.hpp).
#include <span>

#include "base/time.hpp"

namespace airseg::hal {

/// One segment of a pattern's cycle.
struct BlinkStep {
    bool on;
    Duration length;
};

/// One cycle of steps, repeated forever. An empty cycle, or one of zero length, is dark and never changes.
using BlinkPattern = std::span<const BlinkStep>;

/// Length of one cycle.
Duration blink_period(BlinkPattern pattern) noexcept;
/// Level `elapsed` after the pattern started (negative elapsed counts as 0).
bool blink_level(BlinkPattern pattern, Duration elapsed) noexcept;
/// Time since the pattern started at which the level next changes after `elapsed`; Duration::max() if never.
Duration next_blink_change(BlinkPattern pattern, Duration elapsed) noexcept;

}  // namespace airseg::hal

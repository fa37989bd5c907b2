#pragma once
// Status LED patterns as pure functions of time (no timer, no GPIO): what level the LED shows at time t
// after the pattern started, and when it next changes. The daemon's status LED driver (through
// autopilot::StatusLed) drives a GpioLine from these.
#include <iosfwd>
#include <span>

#include "services/common/time.hpp"

namespace airseg::hal {

/// What the status LED tells someone looking at the vehicle.
enum class LedPattern {
    Off,
    Booting,  ///< fast even blink, 100 ms on / 100 ms off: the daemon is starting
    Ready,    ///< slow even blink, 1 s on / 1 s off: autopilot connected, no ground link
    LinkUp,   ///< on, with a 100 ms dark blip every 2 s: ground link up (the blip shows the daemon is alive)
    Fault,    ///< double flash every second: a service reports a fault
};

/// One segment of a pattern's cycle.
struct BlinkStep {
    bool on;
    Duration length;
};

/// One cycle of `pattern`; the cycle repeats. Off is a single dark step.
std::span<const BlinkStep> blink_steps(LedPattern pattern) noexcept;
/// Length of one cycle.
Duration blink_period(LedPattern pattern) noexcept;
/// LED level `elapsed` after the pattern started (negative elapsed counts as 0).
bool led_level(LedPattern pattern, Duration elapsed) noexcept;
/// Time since the pattern started at which the level next changes after `elapsed`; Duration::max() if never.
Duration next_led_change(LedPattern pattern, Duration elapsed) noexcept;

const char* to_string(LedPattern pattern) noexcept;
std::ostream& operator<<(std::ostream& os, LedPattern pattern);

}  // namespace airseg::hal

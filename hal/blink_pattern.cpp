#include "hal/blink_pattern.hpp"

namespace airseg::hal {
namespace {

// A pattern whose steps all show one level, or that takes no time, never changes (and has no cycle to
// take a remainder of).
bool is_constant(BlinkPattern steps) {
    if (blink_period(steps) <= Duration::zero()) {
        return true;
    }
    for (const auto& s : steps) {
        if (s.on != steps.front().on) {
            return false;
        }
    }
    return true;
}

}  // namespace

Duration blink_period(BlinkPattern pattern) noexcept {
    Duration total{0};
    for (const auto& s : pattern) {
        total += s.length;
    }
    return total;
}

bool blink_level(BlinkPattern pattern, Duration elapsed) noexcept {
    const Duration period = blink_period(pattern);
    if (period <= Duration::zero()) {
        return false;
    }
    Duration in_cycle = elapsed < Duration::zero() ? Duration::zero() : elapsed % period;
    for (const auto& s : pattern) {
        if (in_cycle < s.length) {
            return s.on;
        }
        in_cycle -= s.length;
    }
    return pattern.back().on;
}

Duration next_blink_change(BlinkPattern pattern, Duration elapsed) noexcept {
    if (is_constant(pattern)) {
        return Duration::max();
    }
    if (elapsed < Duration::zero()) {
        elapsed = Duration::zero();
    }
    const Duration period = blink_period(pattern);
    const Duration cycle_start = elapsed - elapsed % period;
    const bool current = blink_level(pattern, elapsed);
    // Walk step boundaries across at most two cycles: a constant pattern was excluded, so a change is found.
    Duration boundary = cycle_start;
    for (int cycle = 0; cycle < 2; ++cycle) {
        for (const auto& s : pattern) {
            if (boundary > elapsed && s.on != current) {
                return boundary;
            }
            boundary += s.length;
        }
    }
    return Duration::max();
}

}  // namespace airseg::hal

#include "hal/blink_pattern.hpp"

#include <array>
#include <ostream>

namespace airseg::hal {
namespace {

using std::chrono::milliseconds;

constexpr std::array<BlinkStep, 1> kOff = {{{false, milliseconds(1000)}}};
constexpr std::array<BlinkStep, 2> kBooting = {{{true, milliseconds(100)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 2> kReady = {{{true, milliseconds(1000)}, {false, milliseconds(1000)}}};
constexpr std::array<BlinkStep, 2> kLinkUp = {{{true, milliseconds(1900)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 4> kFault = {{{true, milliseconds(100)},
                                              {false, milliseconds(100)},
                                              {true, milliseconds(100)},
                                              {false, milliseconds(700)}}};

bool is_constant(std::span<const BlinkStep> steps) {
    for (const auto& s : steps) {
        if (s.on != steps.front().on) {
            return false;
        }
    }
    return true;
}

}  // namespace

std::span<const BlinkStep> blink_steps(LedPattern pattern) noexcept {
    switch (pattern) {
        case LedPattern::Off:
            return kOff;
        case LedPattern::Booting:
            return kBooting;
        case LedPattern::Ready:
            return kReady;
        case LedPattern::LinkUp:
            return kLinkUp;
        case LedPattern::Fault:
            return kFault;
    }
    return kOff;
}

Duration blink_period(LedPattern pattern) noexcept {
    Duration total{0};
    for (const auto& s : blink_steps(pattern)) {
        total += s.length;
    }
    return total;
}

bool led_level(LedPattern pattern, Duration elapsed) noexcept {
    const auto steps = blink_steps(pattern);
    Duration in_cycle = elapsed < Duration::zero() ? Duration::zero() : elapsed % blink_period(pattern);
    for (const auto& s : steps) {
        if (in_cycle < s.length) {
            return s.on;
        }
        in_cycle -= s.length;
    }
    return steps.back().on;
}

Duration next_led_change(LedPattern pattern, Duration elapsed) noexcept {
    const auto steps = blink_steps(pattern);
    if (is_constant(steps)) {
        return Duration::max();
    }
    if (elapsed < Duration::zero()) {
        elapsed = Duration::zero();
    }
    const Duration period = blink_period(pattern);
    const Duration cycle_start = elapsed - elapsed % period;
    const bool current = led_level(pattern, elapsed);
    // Walk step boundaries across at most two cycles: a constant pattern was excluded, so a change is found.
    Duration boundary = cycle_start;
    for (int cycle = 0; cycle < 2; ++cycle) {
        for (const auto& s : steps) {
            if (boundary > elapsed && s.on != current) {
                return boundary;
            }
            boundary += s.length;
        }
    }
    return Duration::max();
}

const char* to_string(LedPattern pattern) noexcept {
    switch (pattern) {
        case LedPattern::Off:
            return "off";
        case LedPattern::Booting:
            return "booting";
        case LedPattern::Ready:
            return "ready";
        case LedPattern::LinkUp:
            return "link up";
        case LedPattern::Fault:
            return "fault";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& os, LedPattern pattern) {
    return os << to_string(pattern);
}

}  // namespace airseg::hal

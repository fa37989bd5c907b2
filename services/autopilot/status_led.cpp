#include "services/autopilot/status_led.hpp"

#include <array>
#include <ostream>

namespace airseg::autopilot {
namespace {

using hal::BlinkStep;

constexpr std::array<BlinkStep, 1> kOff = {{{false, milliseconds(1000)}}};
constexpr std::array<BlinkStep, 2> kBooting = {{{true, milliseconds(100)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 2> kReady = {{{true, milliseconds(1000)}, {false, milliseconds(1000)}}};
constexpr std::array<BlinkStep, 2> kLinkUp = {{{true, milliseconds(1900)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 4> kFault = {{{true, milliseconds(100)},
                                              {false, milliseconds(100)},
                                              {true, milliseconds(100)},
                                              {false, milliseconds(700)}}};

}  // namespace

hal::BlinkPattern blink_steps(LedPattern pattern) noexcept {
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

StatusLed::StatusLed(TimePoint now) : since_(now) {}

void StatusLed::autopilot(const AutopilotStatus& s, TimePoint now) {
    if (link_up_ && !s.link_up) {
        link_lost_ = true;
    }
    link_up_ = s.link_up;
    ready_ = s.ready;
    pulses_ = s.reset_pulses;
    if (ready_) {
        link_lost_ = false;
        pulses_at_ready_ = pulses_;
    }
    choose(now);
}

void StatusLed::ground_link(bool up, TimePoint now) {
    ground_ = up;
    choose(now);
}

void StatusLed::choose(TimePoint now) {
    LedPattern p = LedPattern::Booting;
    if (!ready_ && (link_lost_ || pulses_ > pulses_at_ready_)) {
        p = LedPattern::Fault;
    } else if (ready_) {
        p = ground_ ? LedPattern::LinkUp : LedPattern::Ready;
    }
    if (p != pattern_) {
        pattern_ = p;
        since_ = now;
    }
}

bool StatusLed::level(TimePoint now) const {
    return hal::blink_level(blink_steps(pattern_), now - since_);
}

TimePoint StatusLed::next_change(TimePoint now) const {
    const Duration after = hal::next_blink_change(blink_steps(pattern_), now - since_);
    return after == Duration::max() ? kNever : since_ + after;
}

}  // namespace airseg::autopilot

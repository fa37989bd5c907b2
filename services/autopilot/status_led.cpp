#include "services/autopilot/status_led.hpp"

namespace airseg::autopilot {

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
    hal::LedPattern p = hal::LedPattern::Booting;
    if (!ready_ && (link_lost_ || pulses_ > pulses_at_ready_)) {
        p = hal::LedPattern::Fault;
    } else if (ready_) {
        p = ground_ ? hal::LedPattern::LinkUp : hal::LedPattern::Ready;
    }
    if (p != pattern_) {
        pattern_ = p;
        since_ = now;
    }
}

bool StatusLed::level(TimePoint now) const {
    return hal::led_level(pattern_, now - since_);
}

TimePoint StatusLed::next_change(TimePoint now) const {
    const Duration after = hal::next_led_change(pattern_, now - since_);
    return after == Duration::max() ? kNever : since_ + after;
}

}  // namespace airseg::autopilot

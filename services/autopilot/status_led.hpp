#pragma once
// StatusLed: what the vehicle's status LED shows, sans-IO. It takes the autopilot status and the ground link
// state as they change, with the time, and answers which pattern is on, the LED level at any time and when
// that level next changes (patterns from hal/blink_pattern.hpp). A thin adapter in the daemon drives a GPIO
// line from it with one timer.
//
// Patterns, most important first:
//   Fault    double flash: the autopilot link was up and is lost (heartbeats stopped, port unplugged), or
//            the autopilot needed reset pulses and is not READY; until it is READY again
//   Booting  fast blink: the daemon is starting, or the autopilot is connecting (boot, parameters, mission)
//   LinkUp   on with a short dark blip: autopilot READY and the ground link up
//   Ready    slow blink: autopilot READY, no ground link
// A pattern starts its cycle when it is chosen, so a person sees it from its beginning.
#include "hal/blink_pattern.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/common/time.hpp"

namespace airseg::autopilot {

class StatusLed {
  public:
    /// The daemon starts: Booting.
    explicit StatusLed(TimePoint now);

    void autopilot(const AutopilotStatus& status, TimePoint now);
    void ground_link(bool up, TimePoint now);

    hal::LedPattern pattern() const { return pattern_; }
    /// When the current pattern was chosen.
    TimePoint since() const { return since_; }
    /// LED level at `now` (not before since()).
    bool level(TimePoint now) const;
    /// The first time after `now` at which the level changes; kNever for a steady pattern.
    TimePoint next_change(TimePoint now) const;

  private:
    void choose(TimePoint now);

    hal::LedPattern pattern_ = hal::LedPattern::Booting;
    TimePoint since_;
    bool ready_ = false;
    bool link_up_ = false;
    bool link_lost_ = false;  // up once, down now, not READY since
    bool ground_ = false;
    unsigned pulses_at_ready_ = 0;
    unsigned pulses_ = 0;
};

}  // namespace airseg::autopilot

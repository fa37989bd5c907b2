#pragma once
// StatusLed: what the vehicle's status LED shows, sans-IO. It takes the autopilot status and the ground link
// state as they change, with the time, and answers which pattern is on, the LED level at any time and when
// that level next changes (played by hal/blink_pattern.hpp). A thin adapter in the daemon drives a GPIO line
// from it with one timer.
//
// Patterns, most important first:
//   Fault    double flash: the autopilot link was up and is lost (heartbeats stopped, port unplugged), or
//            the autopilot needed reset pulses and is not READY; until it is READY again
//   Booting  fast blink: the daemon is starting, or the autopilot is connecting (boot, parameters, mission)
//   LinkUp   on with a short dark blip: autopilot READY and the ground link up
//   Ready    slow blink: autopilot READY, no ground link
// A pattern starts its cycle when it is chosen, so a person sees it from its beginning.
#include <iosfwd>

#include "base/time.hpp"
#include "hal/blink_pattern.hpp"
#include "services/autopilot/autopilot.hpp"

namespace airseg::autopilot {

/// What the status LED tells someone looking at the vehicle.
enum class LedPattern {
    Off,
    Booting,  ///< fast even blink, 100 ms on / 100 ms off: the daemon is starting
    Ready,    ///< slow even blink, 1 s on / 1 s off: autopilot connected, no ground link
    LinkUp,   ///< on, with a 100 ms dark blip every 2 s: ground link up (the blip shows the daemon is alive)
    Fault,    ///< double flash every second: a service reports a fault
};

/// How `pattern` blinks: one cycle, repeated. Off is a single dark step.
hal::BlinkPattern blink_steps(LedPattern pattern) noexcept;

const char* to_string(LedPattern pattern) noexcept;
std::ostream& operator<<(std::ostream& os, LedPattern pattern);

class StatusLed {
  public:
    /// The daemon starts: Booting.
    explicit StatusLed(TimePoint now);

    void autopilot(const AutopilotStatus& status, TimePoint now);
    void ground_link(bool up, TimePoint now);

    LedPattern pattern() const { return pattern_; }
    /// When the current pattern was chosen.
    TimePoint since() const { return since_; }
    /// LED level at `now` (not before since()).
    bool level(TimePoint now) const;
    /// The first time after `now` at which the level changes; kNever for a steady pattern.
    TimePoint next_change(TimePoint now) const;

  private:
    void choose(TimePoint now);

    LedPattern pattern_ = LedPattern::Booting;
    TimePoint since_;
    bool ready_ = false;
    bool link_up_ = false;
    bool link_lost_ = false;  // up once, down now, not READY since
    bool ground_ = false;
    unsigned pulses_at_ready_ = 0;
    unsigned pulses_ = 0;
};

}  // namespace airseg::autopilot

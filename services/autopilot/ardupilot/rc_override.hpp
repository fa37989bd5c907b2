#pragma once
// RcOverride: turns ground joystick input into RC_CHANNELS_OVERRIDE frames, sans-IO.
//
// While enabled (the vehicle is in MANUAL_NAVIGATION) and the last input is younger than input_timeout,
// a frame with the steering and throttle channels goes out at rate_hz. As soon as the input is older than
// that, or driving is disabled, the channels are released (0 on channels 1-8: "back to the RC
// receiver") with release_repeats frames, then nothing more is sent: a lost ground link cannot leave the
// vehicle driving on a stale command.
//
// Contract: set_input()/set_enabled() any time; poll(now) when poll_timeout() is due or after an input,
// sending what it returns.
#include <optional>

#include "base/time.hpp"
#include "services/autopilot/autopilot_config.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::autopilot::ardupilot {

class RcOverride {
  public:
    RcOverride(RcOverrideConfig config, std::uint8_t target_sysid, std::uint8_t target_compid);

    /// steering and throttle in -1..1 (clamped; NaN reads as centre).
    void set_input(double steering, double throttle, TimePoint now);
    void set_enabled(bool enabled, TimePoint now);

    std::optional<mavlink::RcChannelsOverride> poll(TimePoint now);
    TimePoint poll_timeout() const;

    bool enabled() const { return enabled_; }
    /// True while frames carrying joystick values are being sent.
    bool driving(TimePoint now) const;
    std::uint64_t frames_sent() const { return frames_sent_; }
    std::uint64_t releases() const { return releases_; }

  private:
    std::uint16_t pwm(double v) const;
    mavlink::RcChannelsOverride frame(bool release) const;

    RcOverrideConfig config_;
    std::uint8_t target_sysid_;
    std::uint8_t target_compid_;
    Duration period_;
    bool enabled_ = false;
    std::optional<TimePoint> input_at_;
    double steering_ = 0.0;
    double throttle_ = 0.0;
    bool was_driving_ = false;
    std::optional<TimePoint> last_drive_send_;
    unsigned release_left_ = 0;
    TimePoint next_send_ = kNever;
    std::uint64_t frames_sent_ = 0;
    std::uint64_t releases_ = 0;
};

}  // namespace airseg::autopilot::ardupilot

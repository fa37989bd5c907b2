#include "services/autopilot/ardupilot/rc_override.hpp"

#include <algorithm>
#include <cmath>

namespace airseg::autopilot::ardupilot {

RcOverride::RcOverride(RcOverrideConfig config, std::uint8_t target_sysid, std::uint8_t target_compid)
    : config_(config),
      target_sysid_(target_sysid),
      target_compid_(target_compid),
      period_(std::chrono::duration_cast<Duration>(std::chrono::duration<double>(1.0 / config.rate_hz))) {}

void RcOverride::set_input(double steering, double throttle, TimePoint now) {
    steering_ = std::isnan(steering) ? 0.0 : std::clamp(steering, -1.0, 1.0);
    throttle_ = std::isnan(throttle) ? 0.0 : std::clamp(throttle, -1.0, 1.0);
    input_at_ = now;
    if (enabled_ && !was_driving_) {
        next_send_ = now;  // start at once, not one period later
    }
}

void RcOverride::set_enabled(bool enabled, TimePoint now) {
    if (enabled == enabled_) {
        return;
    }
    enabled_ = enabled;
    next_send_ = now;
}

bool RcOverride::driving(TimePoint now) const {
    return enabled_ && input_at_ && now - *input_at_ < config_.input_timeout;
}

std::uint16_t RcOverride::pwm(double v) const {
    const double trim = config_.pwm_trim;
    const double span = v >= 0 ? config_.pwm_max - trim : trim - config_.pwm_min;
    return static_cast<std::uint16_t>(std::lround(trim + v * span));
}

mavlink::RcChannelsOverride RcOverride::frame(bool release) const {
    mavlink::RcChannelsOverride m;
    m.target_system = target_sysid_;
    m.target_component = target_compid_;
    // 0 on channels 1-8 hands them back to the RC receiver; 0 on 9-18 means "ignore this field".
    if (!release) {
        std::uint16_t* ch[8] = {&m.chan1_raw, &m.chan2_raw, &m.chan3_raw, &m.chan4_raw,
                                &m.chan5_raw, &m.chan6_raw, &m.chan7_raw, &m.chan8_raw};
        *ch[config_.steering_channel - 1] = pwm(steering_);
        *ch[config_.throttle_channel - 1] = pwm(throttle_);
    }
    return m;
}

std::optional<mavlink::RcChannelsOverride> RcOverride::poll(TimePoint now) {
    if (now < next_send_) {
        return std::nullopt;
    }
    const bool drive = driving(now);
    if (drive) {
        if (last_drive_send_ && now < *last_drive_send_ + period_) {
            next_send_ = std::min(*last_drive_send_ + period_, *input_at_ + config_.input_timeout);
            return std::nullopt;
        }
        last_drive_send_ = now;
        was_driving_ = true;
        release_left_ = config_.release_repeats;
        // Wake up when the input goes stale too, so the release is not a period late.
        next_send_ = std::min(now + period_, *input_at_ + config_.input_timeout);
        ++frames_sent_;
        return frame(false);
    }
    if (was_driving_ && release_left_ > 0) {
        if (release_left_ == config_.release_repeats) {
            ++releases_;
        }
        --release_left_;
        next_send_ = release_left_ > 0 ? now + period_ : kNever;
        if (release_left_ == 0) {
            was_driving_ = false;
        }
        ++frames_sent_;
        return frame(true);
    }
    next_send_ = kNever;
    return std::nullopt;
}

TimePoint RcOverride::poll_timeout() const {
    return next_send_;
}

}  // namespace airseg::autopilot::ardupilot

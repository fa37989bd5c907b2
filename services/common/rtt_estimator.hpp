#pragma once
// Round-trip time and retransmission timeout after RFC 6298 (SRTT, RTTVAR, RTO = SRTT + 4·RTTVAR), plus the
// receiver's acknowledgement delay and one frame time, clamped to [rto_min, rto_max]. Shared by the ground
// link's transport and the autopilot's mission client, each with its own bounds.
#include <algorithm>
#include <chrono>
#include <cstdint>

#include "base/time.hpp"

namespace airseg {

class RttEstimator {
  public:
    /// `frame_time`: air time of the largest frame; a lost acknowledgement is repaired by the next one, about
    /// a frame later, so the timeout leaves room for it. `variance_floor`: the least the 4·RTTVAR term adds,
    /// so that a perfectly steady link does not get a razor-thin timeout.
    RttEstimator(Duration initial, Duration min, Duration max, Duration ack_delay, Duration frame_time = {},
                 Duration variance_floor = milliseconds(10))
        : initial_(initial),
          min_(min),
          max_(max),
          ack_delay_(ack_delay + frame_time),
          variance_floor_(variance_floor) {}

    void sample(Duration rtt) {
        if (rtt < Duration::zero()) {
            return;
        }
        if (samples_ == 0) {
            srtt_ = rtt;
            rttvar_ = rtt / 2;
        } else {
            const Duration err = srtt_ > rtt ? srtt_ - rtt : rtt - srtt_;
            rttvar_ = (rttvar_ * 3 + err) / 4;
            srtt_ = (srtt_ * 7 + rtt) / 8;
        }
        ++samples_;
    }

    [[nodiscard]] Duration rto() const {
        if (samples_ == 0) {
            return std::clamp(initial_, min_, max_);
        }
        const Duration var = std::max<Duration>(rttvar_ * 4, variance_floor_);
        return std::clamp(srtt_ + var + ack_delay_, min_, max_);
    }
    /// The timeout after `backoff` consecutive expiries: doubled each time, capped at rto_max.
    [[nodiscard]] Duration rto(unsigned backoff) const {
        Duration d = rto();
        for (unsigned i = 0; i < backoff && d < max_; ++i) {
            d *= 2;
        }
        return std::min(d, max_);
    }

    [[nodiscard]] Duration srtt() const { return srtt_; }
    [[nodiscard]] Duration rttvar() const { return rttvar_; }
    [[nodiscard]] std::uint64_t samples() const { return samples_; }

  private:
    Duration initial_, min_, max_, ack_delay_, variance_floor_;
    Duration srtt_{};
    Duration rttvar_{};
    std::uint64_t samples_ = 0;
};

}  // namespace airseg

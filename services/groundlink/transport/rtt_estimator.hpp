#pragma once
// Round-trip time and retransmission timeout after RFC 6298 (SRTT, RTTVAR, RTO = SRTT + 4·RTTVAR), plus the
// receiver's acknowledgement delay and one frame time, clamped to [rto_min, rto_max].
#include <algorithm>
#include <chrono>

#include "services/common/time.hpp"

namespace airseg::groundlink {

class RttEstimator {
  public:
    /// `frame_time`: air time of the largest frame; a lost acknowledgement is repaired by the next one, about
    /// a frame later, so the timeout leaves room for it.
    RttEstimator(Duration initial, Duration min, Duration max, Duration ack_delay, Duration frame_time = {})
        : initial_(initial), min_(min), max_(max), ack_delay_(ack_delay + frame_time) {}

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
        const Duration var = std::max<Duration>(rttvar_ * 4, std::chrono::milliseconds(10));
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
    Duration initial_, min_, max_, ack_delay_;
    Duration srtt_{};
    Duration rttvar_{};
    std::uint64_t samples_ = 0;
};

}  // namespace airseg::groundlink

#pragma once
// Measures what share of the pushed telemetry the ground really receives: the vehicle counts what it pushes,
// the ground reports (at least once a second, cumulatively) what it received. Sans-IO: counts and time in, a
// loss estimate out.
//
// A report at time t is compared with what had been pushed by t − lag (messages pushed later cannot have
// arrived yet), over the longest span since an earlier report that covers at least kMinMessages pushed
// messages and at most kMaxSpan, so a slow rate still gets an estimate and a lost report only delays one.
#include <cstdint>
#include <deque>
#include <optional>

#include "base/time.hpp"

namespace airseg::groundlink {

class DeliveryMeter {
  public:
    static constexpr std::uint64_t kMinMessages = 16;
    static constexpr Duration kMaxSpan = std::chrono::seconds(60);

    /// One pushed telemetry message handed to the transport at `now`.
    void on_pushed(TimePoint now);
    /// The ground's cumulative count, received at `now`; `lag`: how long a message takes to arrive.
    void on_report(std::uint32_t received, TimePoint now, Duration lag);
    /// A new ground session: both counts start again.
    void reset();

    /// Fraction of pushed messages that did not arrive, over the latest span; nothing before enough data.
    [[nodiscard]] std::optional<double> loss() const { return loss_; }
    [[nodiscard]] std::uint64_t pushed() const { return pushed_; }

  private:
    [[nodiscard]] std::uint64_t pushed_by(TimePoint t) const;

    struct Report {
        TimePoint at;
        std::uint64_t received;
        std::uint64_t pushed;  // pushed by at − lag
    };
    std::deque<TimePoint> push_times_;  // within kMaxSpan, to count what was pushed by a given time
    std::uint64_t pushed_ = 0;
    std::deque<Report> reports_;
    std::optional<double> loss_;
};

}  // namespace airseg::groundlink

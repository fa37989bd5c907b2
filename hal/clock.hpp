#pragma once
// The clock seam: code that needs "now" outside a sans-IO core takes a hal::Clock&, so tests can drive time.
#include <atomic>

#include "base/time.hpp"

namespace airseg::hal {

class Clock {
  public:
    virtual ~Clock() = default;
    virtual TimePoint now() const = 0;
};

/// The real monotonic clock (std::chrono::steady_clock).
class SteadyClock final : public Clock {
  public:
    TimePoint now() const override { return std::chrono::steady_clock::now(); }
};

/// A clock that moves only when told to. Safe to read from any thread.
/// It starts one hour after the epoch, not at TimePoint{}, so code that treats a zero time point as
/// "never happened" is not fooled by a test clock.
class ManualClock final : public Clock {
  public:
    static constexpr TimePoint kDefaultStart = TimePoint{} + std::chrono::hours(1);

    explicit ManualClock(TimePoint start = kDefaultStart) : ticks_(start.time_since_epoch().count()) {}

    TimePoint now() const override { return TimePoint{Duration{ticks_.load(std::memory_order_acquire)}}; }

    /// Moves time forward by `d` (a negative `d` is ignored: a steady clock never goes back).
    void advance(Duration d) {
        if (d > Duration::zero()) {
            ticks_.fetch_add(d.count(), std::memory_order_acq_rel);
        }
    }

    /// Jumps to `t`. Tests may set any time, including an earlier one, to check how code copes.
    void set(TimePoint t) { ticks_.store(t.time_since_epoch().count(), std::memory_order_release); }

  private:
    std::atomic<Duration::rep> ticks_;
};

}  // namespace airseg::hal

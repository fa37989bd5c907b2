#pragma once
// Time as the protocol cores see it: a steady time point passed in by the caller, never read from a clock
// inside a core. Real adapters pass std::chrono::steady_clock::now(); tests and benchmarks pass simulated
// time.
#include <chrono>

namespace airseg {

using SteadyClock = std::chrono::steady_clock;
using TimePoint = SteadyClock::time_point;
using Duration = SteadyClock::duration;

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;

/// The "no deadline" value returned by poll_timeout() style functions.
inline constexpr TimePoint kNever = TimePoint::max();

/// The first multiple of `period` on the steady clock after `now`. Periodic timers of one period that all
/// expire on this grid expire together, so the process wakes once for all of them instead of once each (a
/// wake-up, not the work done in it, is what an idle daemon mostly spends its CPU on).
inline TimePoint next_on_grid(TimePoint now, Duration period) {
    const auto since_epoch = now.time_since_epoch();
    return TimePoint((since_epoch / period + 1) * period);
}

}  // namespace airseg

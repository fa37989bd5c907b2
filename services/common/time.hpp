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

}  // namespace airseg

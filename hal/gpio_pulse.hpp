#pragma once
// A timed pulse on an output line, e.g. holding the autopilot's reset line for a few milliseconds.
#include <functional>
#include <memory>
#include <system_error>

#include "base/time.hpp"
#include "hal/asio.hpp"
#include "hal/gpio.hpp"

namespace airseg::hal {

/// Drives `line` active now and inactive after `width`, without blocking. `done` (optional) runs on
/// `executor` once the line is back to inactive, with the first error either set() returned. The line is kept
/// alive until then. If the io_context is destroyed first, the line stays active and `done` never runs.
void pulse(const Executor& executor, std::shared_ptr<GpioLine> line, Duration width,
           std::function<void(std::error_code)> done = {});

}  // namespace airseg::hal

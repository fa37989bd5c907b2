#pragma once
// Drives a status LED line through a LedPattern with one asio timer.
#include <memory>

#include "hal/asio.hpp"
#include "hal/blink_pattern.hpp"
#include "hal/gpio.hpp"

namespace airseg::hal {

/// Shows a LedPattern on a GPIO line, waking only at level changes. set_pattern() restarts the cycle.
/// Threading: call from the executor given (a strand). Destruction stops the blinking and turns the LED off.
class LedBlinker {
  public:
    LedBlinker(Executor executor, std::shared_ptr<GpioLine> line);
    ~LedBlinker();
    LedBlinker(const LedBlinker&) = delete;
    LedBlinker& operator=(const LedBlinker&) = delete;

    void set_pattern(LedPattern pattern);
    LedPattern pattern() const;

  private:
    class Impl;
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::hal

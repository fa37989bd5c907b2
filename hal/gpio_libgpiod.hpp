#pragma once
// GPIO through the kernel's GPIO character device (/dev/gpiochipN), with libgpiod's v1 C API.
#include "hal/gpio.hpp"

namespace airseg::hal {

/// Requests lines from the kernel. A line stays requested (and its output level held) until the returned
/// GpioLine is destroyed; the kernel then releases it.
class LibgpiodFactory final : public GpioFactory {
  public:
    GpioRequestResult request(const GpioLineRequest& request) override;
};

}  // namespace airseg::hal

#pragma once
// Drives the status LED's GPIO line from the sans-IO StatusLed: the autopilot status and the ground link's
// status section come from the bus, one steady_timer wakes at each level change. Everything runs on the
// strand given. Destruction turns the LED off.
#include <memory>

#include "hal/gpio.hpp"
#include "services/autopilot/status_led.hpp"
#include "services/common/bus.hpp"

namespace airseg::daemon {

class StatusLedDriver {
  public:
    StatusLedDriver(Bus& bus, Strand strand, std::shared_ptr<hal::GpioLine> line);
    ~StatusLedDriver();
    StatusLedDriver(const StatusLedDriver&) = delete;
    StatusLedDriver& operator=(const StatusLedDriver&) = delete;

  private:
    void show();

    std::shared_ptr<hal::GpioLine> line_;
    autopilot::StatusLed led_;
    asio::steady_timer timer_;
    TimePoint armed_ = kNever;
    bool level_ = false;
    bool failed_ = false;  // the line refused a level once (logged once)
    Subscription autopilot_sub_;
    Subscription groundlink_sub_;
};

}  // namespace airseg::daemon

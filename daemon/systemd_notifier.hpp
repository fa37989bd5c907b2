#pragma once
// The daemon's side of systemd's notify protocol (sd_notify(3)). Outside systemd (no NOTIFY_SOCKET) every
// call is a cheap no-op, so the daemon runs the same in a terminal.
#include <chrono>
#include <optional>
#include <string>

namespace airseg::daemon {

class SystemdNotifier {
  public:
    SystemdNotifier();

    /// The watchdog period systemd expects pings within (WATCHDOG_USEC), if it asked for pings.
    std::optional<std::chrono::microseconds> watchdog_period() const { return watchdog_; }

    void ready();
    void status(const std::string& line);
    void watchdog();
    void stopping();
    void reloading();

  private:
    void send(const std::string& state);
    std::optional<std::chrono::microseconds> watchdog_;
};

}  // namespace airseg::daemon

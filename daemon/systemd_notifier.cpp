#include "daemon/systemd_notifier.hpp"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

namespace airseg::daemon {

SystemdNotifier::SystemdNotifier() {
    uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
        watchdog_ = std::chrono::microseconds(usec);
    }
}

void SystemdNotifier::send(const std::string& state) {
    const int r = sd_notify(0, state.c_str());
    if (r < 0) {
        spdlog::debug("systemd: sd_notify failed: {}", strerror(-r));
    }
}

void SystemdNotifier::ready() {
    send("READY=1");
}

void SystemdNotifier::status(const std::string& line) {
    send("STATUS=" + line);
}

void SystemdNotifier::watchdog() {
    send("WATCHDOG=1");
}

void SystemdNotifier::stopping() {
    send("STOPPING=1");
}

void SystemdNotifier::reloading() {
    send("RELOADING=1");
}

}  // namespace airseg::daemon

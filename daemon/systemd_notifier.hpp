#pragma once
// The daemon's side of systemd's notify protocol (sd_notify(3)), written against the protocol itself: one
// datagram per state change to the AF_UNIX socket named by NOTIFY_SOCKET. libsystemd would bring in
// libgcrypt, libgpg-error, libzstd, liblzma, liblz4 and libcap for this, about 1 MB of the daemon's resident
// memory (docs/performance.md). Outside systemd (no NOTIFY_SOCKET) every call is a cheap no-op, so the daemon
// runs the same in a terminal.
#include <sys/socket.h>
#include <sys/un.h>

#include <chrono>
#include <deque>
#include <optional>
#include <string>
#include <string_view>

namespace airseg::daemon {

class SystemdNotifier {
  public:
    /// Reads NOTIFY_SOCKET, WATCHDOG_USEC and WATCHDOG_PID from the environment.
    SystemdNotifier();
    ~SystemdNotifier();
    SystemdNotifier(const SystemdNotifier&) = delete;
    SystemdNotifier& operator=(const SystemdNotifier&) = delete;

    /// The watchdog period systemd expects pings within (WATCHDOG_USEC), if it asked this process for pings.
    std::optional<std::chrono::microseconds> watchdog_period() const { return watchdog_; }

    void ready();
    void status(const std::string& line);
    void watchdog();
    void stopping();
    void reloading();

  private:
    /// Never blocks: the notifier shares its thread with signal handling and the watchdog, and a full socket
    /// (systemd busy, or a reader that stalls) would otherwise hold them all. A state that must arrive
    /// (READY, STOPPING, RELOADING) waits for the next send; a ping or STATUS line that finds the socket full
    /// is dropped, as the next one replaces it.
    void send(std::string_view state, bool must_arrive);
    bool try_send(std::string_view state);
    int fd_ = -1;
    std::deque<std::string> unsent_;
    sockaddr_un address_{};
    socklen_t address_length_ = 0;
    std::optional<std::chrono::microseconds> watchdog_;
};

/// WATCHDOG_USEC as sd_watchdog_enabled(3) reads it: a positive number of microseconds, for this process only
/// when WATCHDOG_PID names another one. Empty when absent or malformed.
std::optional<std::chrono::microseconds> watchdog_period_from(const char* usec, const char* pid,
                                                              long own_pid);

}  // namespace airseg::daemon

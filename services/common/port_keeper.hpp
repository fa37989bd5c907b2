#pragma once
// Keeps one serial device open: opens it, reports bytes, and when it is missing or unplugged retries with
// exponential backoff (reconnect_min doubling up to reconnect_max) — a device error never stops the daemon.
#include <functional>
#include <span>
#include <string>

#include "base/time.hpp"
#include "hal/serial_port.hpp"
#include "services/common/asio.hpp"

namespace airseg {

struct PortKeeperConfig {
    hal::SerialConfig serial;
    Duration reconnect_min = std::chrono::milliseconds(500);
    Duration reconnect_max = std::chrono::seconds(10);
};

class PortKeeper {
  public:
    struct Handlers {
        std::function<void()> on_open;
        std::function<void(std::span<const std::uint8_t>)> on_bytes;
        /// The port is closed (or could not be opened); `reason` is short, for status: "no /dev/ttyACM0".
        std::function<void(const std::string& reason)> on_down;
    };

    PortKeeper(Strand strand, PortKeeperConfig config, Handlers handlers);

    void start();
    void stop();

    /// Tries to open the port now instead of waiting for the backoff (e.g. on an operator request).
    void retry_now();

    /// Uses `baud` from now on (probing a device whose rate is unknown). An open port is closed and opened
    /// again at once at the new rate: on_open runs again, on_down does not (the device did not go away) and
    /// it does not count as a reconnect. A closed port takes the rate at its next attempt.
    void reopen_at(unsigned baud);
    unsigned baud() const { return config_.serial.baud; }

    bool is_open() const { return port_.is_open(); }
    hal::WriteResult write(std::vector<std::uint8_t> bytes) { return port_.write(std::move(bytes)); }
    std::size_t queued_bytes() const { return port_.queued_bytes(); }
    const std::string& last_error() const { return last_error_; }
    hal::SerialPort& port() { return port_; }
    unsigned reconnects() const { return reconnects_; }

  private:
    void do_open();
    void schedule_retry();
    void went_down(std::string reason);

    Strand strand_;
    PortKeeperConfig config_;
    Handlers handlers_;
    hal::SerialPort port_;
    asio::steady_timer retry_timer_;
    Duration backoff_;
    std::string last_error_;
    bool running_ = false;
    bool was_open_ = false;
    unsigned reconnects_ = 0;
};

/// "no /dev/ttyACM0" for a missing device, otherwise the open error as the HAL words it.
std::string describe_open_failure(const hal::OpenResult& result, const std::string& path);

}  // namespace airseg

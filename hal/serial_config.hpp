#pragma once
// Settings of one serial port, checked before any device is touched.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace airseg::hal {

/// The baud rates a SerialPort accepts (the standard termios rates up to 921600 plus 500000, which some
/// telemetry radios use). Anything else is rejected by validate().
std::span<const unsigned> supported_bauds() noexcept;
bool is_supported_baud(unsigned baud) noexcept;

struct SerialConfig {
    /// Device path, e.g. /dev/ttyACM0 (yaml: device).
    std::string path;
    /// Line rate in bit/s, one of supported_bauds() (yaml: baud).
    unsigned baud = 57600;
    /// Hardware flow control RTS/CTS (yaml: flow_control: rtscts).
    bool rtscts = false;
    /// Drop DTR/RTS when the port is closed (yaml: hupcl).
    bool hupcl = true;
    /// Drive DTR after opening; unset leaves it as the driver set it (yaml: dtr).
    std::optional<bool> dtr_on_open;
    /// Drive RTS after opening (only without rtscts); unset leaves it (yaml: rts).
    std::optional<bool> rts_on_open;
    /// Ask the UART driver for low-latency mode; only warns if refused (yaml: low_latency).
    bool low_latency = false;
    /// Bound of the write queue in bytes (yaml: max_queued_bytes).
    std::size_t max_queued_bytes = 1 << 20;

    /// Every problem found, each naming the field and the bad value; empty when the config is usable.
    static std::vector<std::string> validate(const SerialConfig& config);
};

}  // namespace airseg::hal

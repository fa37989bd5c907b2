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
    std::string path;       ///< device path, e.g. /dev/ttyACM0 (yaml: device)
    unsigned baud = 57600;  ///< line rate in bit/s, one of supported_bauds() (yaml: baud)
    bool rtscts = false;    ///< hardware flow control RTS/CTS (yaml: flow_control: rtscts)
    bool hupcl = true;      ///< drop DTR/RTS when the port is closed (yaml: hupcl)
    std::optional<bool>
        dtr_on_open;  ///< drive DTR after opening; unset leaves it as the driver set it (yaml: dtr)
    std::optional<bool>
        rts_on_open;  ///< drive RTS after opening (only without rtscts); unset leaves it (yaml: rts)
    bool low_latency =
        false;  ///< ask the UART driver for low-latency mode; warns if refused (yaml: low_latency)
    std::size_t max_queued_bytes = 1 << 20;  ///< bound of the write queue (yaml: max_queued_bytes)

    /// Every problem found, each naming the field and the bad value; empty when the config is usable.
    static std::vector<std::string> validate(const SerialConfig& config);
};

}  // namespace airseg::hal

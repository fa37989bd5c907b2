#pragma once
// termios and modem-line ioctls on an already opened tty descriptor (used by SerialPort; kept apart so the
// async class stays about queues and handlers).
#include <string>
#include <system_error>
#include <vector>

#include "hal/serial_config.hpp"

namespace airseg::hal::termios_setup {

/// Puts `fd` in raw 8N1 mode at config.baud with the flow control and HUPCL settings of `config`, and
/// discards bytes already queued in either direction. On failure returns the errno and fills `what`.
std::error_code apply(int fd, const SerialConfig& config, std::string& what);

/// Raises (`on`) or drops one modem line (TIOCM_DTR, TIOCM_RTS). Ptys refuse these ioctls.
std::error_code set_modem_line(int fd, int line_bit, bool on);

/// Asks the UART driver for low-latency mode (ASYNC_LOW_LATENCY). Many USB and virtual ttys refuse it.
std::error_code set_low_latency(int fd);

/// Applies the optional settings of `config` (DTR, RTS, low latency); each one that fails adds a warning
/// naming it. Never fails the open.
std::vector<std::string> apply_optional(int fd, const SerialConfig& config);

}  // namespace airseg::hal::termios_setup

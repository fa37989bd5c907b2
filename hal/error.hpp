#pragma once
// Error codes and result types shared by the HAL's device classes.
#include <iosfwd>
#include <string>
#include <system_error>
#include <vector>

namespace airseg::hal {

/// HAL-specific error conditions. OS failures keep their errno (std::system_category) instead.
enum class HalError {
    Unplugged = 1,  ///< the device went away (EIO, ENODEV, ENXIO, end of file); the port has been closed
    ReadFailed,     ///< a read failed for another reason; the port has been closed
    WriteFailed,    ///< a write failed for another reason; the port has been closed
    InvalidConfig,  ///< the configuration did not pass validate()
    NotATerminal,   ///< the path opened fine but is not a tty (termios calls failed)
    PathOccupied,   ///< a file that is not a symlink sits where a pty link should go
};

const std::error_category& hal_category() noexcept;
std::error_code make_error_code(HalError e) noexcept;

/// Outcome of opening a device. `message` names the device and what went wrong; `warnings` lists optional
/// settings (modem lines, low-latency mode) that did not take effect, which never make an open fail.
struct OpenResult {
    std::error_code error;
    std::string message;
    std::vector<std::string> warnings;

    bool ok() const { return !error; }
    explicit operator bool() const { return ok(); }
};

/// The failed open of a configuration that validate() rejected: InvalidConfig, with all of `errors`.
OpenResult invalid_config(const std::vector<std::string>& errors);

/// Outcome of handing bytes to a device's write queue.
enum class WriteResult {
    Queued,     ///< accepted; will be written in order
    NotOpen,    ///< the device is closed; bytes dropped
    QueueFull,  ///< accepting them would exceed the queue bound; bytes dropped
    NoPeer,     ///< nobody is listening (pty with no peer, UDP with no known remote); bytes dropped
    TooLarge,   ///< a single datagram above the size bound; dropped
};

const char* to_string(WriteResult r) noexcept;
std::ostream& operator<<(std::ostream& os, WriteResult r);
std::ostream& operator<<(std::ostream& os, HalError e);

}  // namespace airseg::hal

template <>
struct std::is_error_code_enum<airseg::hal::HalError> : std::true_type {};

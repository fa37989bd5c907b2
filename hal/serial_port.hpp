#pragma once
// A serial port (UART, USB CDC-ACM, pty) driven asynchronously by Boost.Asio.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include "hal/asio.hpp"
#include "hal/error.hpp"
#include "hal/serial_config.hpp"

namespace airseg::hal {

/// One serial port in raw 8N1 mode.
///
/// Threading: build it with a strand and call every member from that strand; handlers run there too.
/// Destroy it on the strand or after the io_context has stopped.
///
/// Life cycle: open() → start_reading() → write()… The first read or write failure closes the port and is
/// reported once through on_error: HalError::Unplugged when the device went away (EIO, ENODEV, ENXIO, end of
/// file), ReadFailed/WriteFailed otherwise. Cancellation by close() is not reported. After a failure the
/// caller may open() again (typically from a backoff timer) and must call start_reading() again. Log lines
/// carry the prefix `serial[<path>]: `.
class SerialPort {
  public:
    using BytesHandler = std::function<void(std::span<const std::uint8_t> bytes)>;
    using ErrorHandler = std::function<void(std::error_code error, const std::string& what)>;

    /// Size of the buffer each read fills; a read delivers at most this many bytes.
    static constexpr std::size_t kReadChunk = 4096;

    explicit SerialPort(Executor executor);
    ~SerialPort();
    SerialPort(const SerialPort&) = delete;
    SerialPort& operator=(const SerialPort&) = delete;

    /// Validates `config`, opens the device (O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC), applies raw mode,
    /// then the optional settings, which only add warnings. Closes a port already open first.
    OpenResult open(const SerialConfig& config);
    /// Closes the port, dropping queued writes. Pending operations end silently.
    void close();
    bool is_open() const;
    /// Path of the last open() attempt.
    const std::string& path() const;

    /// Starts delivering received bytes; handlers are kept until replaced. Call again after each open().
    void start_reading(BytesHandler on_bytes, ErrorHandler on_error);
    /// Queues bytes; queued buffers are written in order, one write in flight at a time.
    WriteResult write(std::vector<std::uint8_t> bytes);
    /// Bytes accepted by write() and not yet handed to the kernel; the basis for pacing.
    std::size_t queued_bytes() const;
    /// Bytes received by the kernel and not read yet (FIONREAD); 0 when closed or when the driver cannot
    /// tell. A consumer judging the peer's silence asks this first: a starved reader's backlog is not
    /// silence.
    std::size_t bytes_waiting() const;

    /// Drives the DTR / RTS lines now (APM boards reset on a DTR edge). Ptys refuse these: the error says so.
    std::error_code set_dtr(bool on);
    std::error_code set_rts(bool on);

    Executor get_executor() const;

  private:
    class Impl;
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::hal

#pragma once
// A pseudo-terminal standing in for a serial device, for the simulators (APM, radio link).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "hal/asio.hpp"
#include "hal/error.hpp"

namespace airseg::hal {

struct PtyConfig {
    std::string link_path;  ///< symlink created to the slave, e.g. /tmp/apmsim/ttyACM0
    Duration peer_check_period = milliseconds(20);  ///< how often the slave's open state is sampled
    std::size_t max_queued_bytes = 1 << 20;         ///< bound of the master-side write queue

    static std::vector<std::string> validate(const PtyConfig& config);
};

/// A raw pseudo-terminal pair whose slave is published at a symlink (the "device path" a peer such as airsegd
/// opens), with the master side driven through asio.
///
/// Peer detection: the Pty keeps no slave descriptor open itself, so the kernel flags the master with POLLHUP
/// exactly while no process has the slave open. A process opening the slave clears the flag, but the kernel
/// wakes no waiter on the master when that happens, so there is no event to wait for: the Pty samples the
/// flag with a non-blocking poll() every peer_check_period and reports the edges through on_peer_open /
/// on_peer_close. A peer that opens and closes within one period can go unnoticed. A read on the master that
/// fails with EIO means the peer closed; it is reported as a peer close, not an error.
///
/// While no peer is present, write() drops bytes (WriteResult::NoPeer), as a real line does; queued writes
/// are dropped when the peer goes away.
///
/// Threading: build it with a strand and call every member from that strand; callbacks run there too.
/// Destroy it on the strand or after the io_context has stopped.
class Pty {
  public:
    using BytesHandler = std::function<void(std::span<const std::uint8_t> bytes)>;
    using PeerHandler = std::function<void()>;

    static constexpr std::size_t kReadChunk = 4096;

    Pty(Executor executor, PtyConfig config);
    ~Pty();  ///< unplug()
    Pty(const Pty&) = delete;
    Pty& operator=(const Pty&) = delete;

    /// Creates the pty pair in raw mode and points link_path at its slave, replacing a stale symlink (a
    /// regular file at link_path is left alone and reported as HalError::PathOccupied).
    OpenResult open();
    /// Simulates pulling the cable: removes the symlink and closes the master, so a peer's reads end
    /// (EOF/EIO) and its writes fail with EIO. No callback is made; peer_connected() turns false.
    void unplug();
    /// unplug() if needed, then open() a new pair behind the same link path.
    OpenResult replug();

    bool is_open() const;
    bool peer_connected() const;
    /// The baud rate the peer set on its end: on Linux the master reads the slave's termios, so a simulator
    /// can tell which rate the peer's UART would run at (a pty itself moves bytes at any rate). 0 when
    /// unplugged or not a standard rate.
    unsigned peer_baud() const;
    const std::string& link_path() const;
    /// /dev/pts/N of the current pair; empty while unplugged.
    const std::string& slave_path() const;

    void on_peer_open(PeerHandler handler);
    void on_peer_close(PeerHandler handler);
    /// Delivers bytes the peer writes, from now on and across replugs, whenever a peer is present.
    void start_reading(BytesHandler on_bytes);
    WriteResult write(std::vector<std::uint8_t> bytes);
    std::size_t queued_bytes() const;

  private:
    class Impl;
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::hal

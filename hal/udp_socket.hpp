#pragma once
// A UDP socket for the ground link's UDP mode: bind, optionally a fixed remote, datagrams in and out.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hal/asio.hpp"
#include "hal/error.hpp"

namespace airseg::hal {

struct UdpConfig {
    std::string bind_address = "0.0.0.0";  ///< local address (yaml: bind)
    std::uint16_t bind_port = 0;           ///< local port, 0 = any (yaml: port)
    std::string remote_address;            ///< fixed peer; empty = answer whoever sent last (yaml: remote)
    std::uint16_t remote_port = 0;         ///< fixed peer's port (yaml: remote_port)

    static std::vector<std::string> validate(const UdpConfig& config);
};

/// Datagrams up to kMaxDatagram bytes each way. A received datagram that is larger is dropped whole and
/// counted (oversize_dropped()), never delivered cut short. Without a fixed remote, send() goes to the
/// sender of the last datagram received.
///
/// Threading: build it with a strand and call every member from that strand; handlers run there too.
class UdpSocket {
  public:
    using Endpoint = boost::asio::ip::udp::endpoint;
    using DatagramHandler = std::function<void(std::span<const std::uint8_t> datagram, const Endpoint& from)>;
    using ErrorHandler = std::function<void(std::error_code error, const std::string& what)>;

    static constexpr std::size_t kMaxDatagram = 2048;
    /// A send goes straight to the kernel when none waits before it; when the kernel's buffer is full it
    /// waits, in order, and beyond this many waiting send() returns QueueFull.
    static constexpr std::size_t kMaxSendsInFlight = 64;

    explicit UdpSocket(Executor executor);
    ~UdpSocket();
    UdpSocket(const UdpSocket&) = delete;
    UdpSocket& operator=(const UdpSocket&) = delete;

    OpenResult open(const UdpConfig& config);
    void close();
    bool is_open() const;
    /// The bound address, with the port the kernel chose when bind_port was 0.
    Endpoint local_endpoint() const;
    /// Where send() goes: the fixed remote, else the last sender, else nothing.
    std::optional<Endpoint> remote() const;

    /// Starts delivering datagrams. A receive failure other than cancellation is reported once through
    /// on_error and stops receiving; the socket stays open for sending.
    void start_receiving(DatagramHandler on_datagram, ErrorHandler on_error);
    WriteResult send(std::vector<std::uint8_t> datagram);
    WriteResult send_to(std::vector<std::uint8_t> datagram, const Endpoint& to);

    std::size_t oversize_dropped() const;
    /// Datagrams the kernel refused to send (no route, buffer full); they are lost, as UDP loses them.
    std::size_t send_errors() const;

  private:
    class Impl;
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::hal

#pragma once
// GcsEndpoint: a MAVLink endpoint for standard ground stations (QGroundControl, Mission Planner, MAVProxy):
// UDP (every peer that sent something gets what the vehicle sends, plus an optional fixed destination) and
// TCP (any number of clients). Bytes from ground stations go through the project's MAVLink parser, one parser
// per peer, so only whole valid frames of known messages are passed on, each datagram's or read's frames in
// one call of ToVehicle.
//
// Threading: build it with a strand and call every member from that strand; ToVehicle runs there too. The
// sockets' handlers keep what they need alive, so the endpoint may be destroyed after stop() at any time.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/common/asio.hpp"

namespace airseg::autopilot {

struct GcsEndpointConfig {
    std::string udp = "0.0.0.0:14550";  // ADDRESS:PORT to bind; empty = no UDP; port 0 = any
    std::string tcp = "0.0.0.0:5760";   // ADDRESS:PORT to listen on; empty = no TCP; port 0 = any
    std::string udp_remote;             // HOST:PORT that always gets the vehicle's frames; empty = none

    /// Every problem, each naming its field; empty when usable.
    [[nodiscard]] std::vector<std::string> validate() const;
};

struct GcsEndpointStats {
    std::uint64_t frames_in = 0;    // valid frames from ground stations, passed on
    std::uint64_t invalid_in = 0;   // damaged frames and frames of unknown messages, dropped
    std::uint64_t bytes_out = 0;    // bytes sent to ground stations (each copy counted)
    std::uint64_t dropped_out = 0;  // sends dropped: a client too slow to keep up, a full UDP queue
    std::size_t udp_peers = 0;      // UDP peers heard within the last kPeerTimeout
    std::size_t tcp_clients = 0;
    std::uint64_t udp_peers_evicted = 0;  // peers forgotten to make room for a new one (kMaxUdpPeers)
    std::uint64_t tcp_refused = 0;        // connections closed at once: kMaxTcpClients already open
};

class GcsEndpoint {
  public:
    using ToVehicle =
        std::function<void(std::vector<std::uint8_t> frames)>;  // whole frames, parsed and checked
    /// A UDP peer silent this long gets nothing more until it sends again.
    static constexpr auto kPeerTimeout = std::chrono::seconds(30);
    /// Bytes waiting for one TCP client; beyond it the vehicle's frames are dropped for that client.
    static constexpr std::size_t kMaxTcpBacklog = 64 * 1024;
    /// UDP peers kept (each with its parser): a datagram from a new address when the table is full makes the
    /// endpoint forget the peer heard least recently (a ground station that keeps sending is back at its next
    /// heartbeat).
    static constexpr std::size_t kMaxUdpPeers = 16;
    /// TCP clients at once; a connection beyond is closed at once.
    static constexpr std::size_t kMaxTcpClients = 8;

    GcsEndpoint(asio::any_io_executor strand, GcsEndpointConfig config, ToVehicle to_vehicle);
    ~GcsEndpoint();
    GcsEndpoint(const GcsEndpoint&) = delete;
    GcsEndpoint& operator=(const GcsEndpoint&) = delete;

    std::string start();  // error for people or empty
    void stop();
    void from_vehicle(std::span<const std::uint8_t> frames);  // sent to every ground station
    std::uint16_t udp_port() const;
    std::uint16_t tcp_port() const;
    GcsEndpointStats stats() const;

    class Impl;

  private:
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::autopilot

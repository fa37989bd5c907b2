#pragma once
// Where the MAVLink endpoints for ground stations listen (GcsEndpoint on board, the ground hub's
// StationEndpoint), and what they count.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace airseg::autopilot {

struct GcsEndpointConfig {
    std::string udp = "0.0.0.0:14550";  // ADDRESS:PORT to bind; empty = no UDP; port 0 = any
    std::string tcp = "0.0.0.0:5760";   // ADDRESS:PORT to listen on; empty = no TCP; port 0 = any
    std::string udp_remote;             // HOST:PORT that always gets the vehicle's frames; empty = none

    /// Every problem, each naming its field; empty when usable.
    [[nodiscard]] std::vector<std::string> validate() const;
};

struct HostPort {
    std::string host;
    std::uint16_t port = 0;
};

/// "ADDRESS:PORT" (the address an IP address, the port 0..65535), or nothing.
std::optional<HostPort> parse_host_port(const std::string& text);

struct GcsEndpointStats {
    std::uint64_t frames_in = 0;    // valid frames from ground stations, passed on
    std::uint64_t invalid_in = 0;   // damaged frames and frames of unknown messages, dropped
    std::uint64_t bytes_out = 0;    // bytes sent to ground stations (each copy counted)
    std::uint64_t dropped_out = 0;  // sends dropped: a client too slow to keep up, a full UDP queue
    std::size_t udp_peers = 0;      // UDP peers heard within the last kPeerTimeout, and the fixed one
    std::size_t tcp_clients = 0;
    std::uint64_t udp_peers_evicted = 0;  // peers forgotten to make room for a new one (kMaxUdpPeers)
    std::uint64_t tcp_refused = 0;        // connections closed at once: kMaxTcpClients already open
};

}  // namespace airseg::autopilot

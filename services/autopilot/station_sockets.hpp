#pragma once
// StationSockets: the sockets under both MAVLink endpoints for standard ground stations (QGroundControl,
// Mission Planner, MAVProxy): the daemon's own (GcsEndpoint: every frame to every station) and the ground
// hub's (ground::StationEndpoint: routed as mavlink-router routes). Each UDP peer heard is a station, and so
// is the optional fixed destination (never forgotten); each TCP client is one. All of it is bounded
// (kMaxUdpPeers, kMaxTcpClients, a byte backlog per client), and each station's bytes go through a MAVLink
// parser of its own, so only whole valid frames of known messages come in, each datagram's or read's frames
// in one call.
//
// Threading: build it with a strand and call every member from that strand; the handlers run there too and
// never after stop(). The sockets' own handlers keep what they need alive, so it may be destroyed after
// stop() at any time.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "services/autopilot/gcs_endpoint_config.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/common/asio.hpp"

namespace airseg::autopilot {

using StationId = std::uint64_t;

/// A valid frame from a ground station: as parsed, and its bytes (re-encoded, unsigned).
struct StationFrame {
    mavlink::Frame frame;
    std::vector<std::uint8_t> bytes;
};

class StationSockets {
  public:
    struct Handlers {
        /// The valid frames of one datagram or one read from `station`.
        std::function<void(StationId station, std::vector<StationFrame> frames)> frames;
        /// A station is gone: its TCP client closed, its UDP peer silent past kPeerTimeout or evicted.
        std::function<void(StationId station)> gone;
    };
    /// A UDP peer silent this long gets nothing more until it sends again.
    static constexpr auto kPeerTimeout = std::chrono::seconds(30);
    /// UDP peers kept (each with its parser): a datagram from a new address when the table is full makes the
    /// endpoint forget the peer heard least recently (a ground station that keeps sending is back at its next
    /// heartbeat). The fixed destination is never the one forgotten.
    static constexpr std::size_t kMaxUdpPeers = 16;
    /// TCP clients at once; a connection beyond is closed at once.
    static constexpr std::size_t kMaxTcpClients = 8;
    /// A UDP datagram carries whole frames up to this many bytes (one longer frame alone).
    static constexpr std::size_t kMaxDatagram = 1400;

    /// `name` starts its log lines and errors ("gcs endpoint"); `tcp_backlog` bytes may wait for one TCP
    /// client, beyond which what is sent to it is dropped (counted).
    StationSockets(asio::any_io_executor strand, GcsEndpointConfig config, std::string name,
                   std::size_t tcp_backlog, Handlers handlers);
    ~StationSockets();
    StationSockets(const StationSockets&) = delete;
    StationSockets& operator=(const StationSockets&) = delete;

    std::string start();  // error for people or empty
    void stop();
    /// The stations there are now (UDP peers silent past kPeerTimeout forgotten first).
    std::vector<StationId> stations();
    /// Whole frames to one station: in datagrams of at most kMaxDatagram bytes, or queued for its client.
    void send(StationId station, std::span<const std::uint8_t> frames);
    std::uint16_t udp_port() const;
    std::uint16_t tcp_port() const;
    GcsEndpointStats stats() const;

    class Impl;

  private:
    std::shared_ptr<Impl> impl_;
};

}  // namespace airseg::autopilot

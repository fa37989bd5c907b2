#pragma once
// StationEndpoint: the hub's MAVLink endpoint for standard ground stations (QGroundControl, Mission Planner,
// MAVProxy) on the sockets the daemon's endpoint stands on too (autopilot::StationSockets: UDP peers and a
// fixed destination, TCP clients, each station's valid frames in one call), with routing as mavlink-router
// does it (MavlinkRouter): each station is learnt from the frames it sends, and a frame from the vehicle
// addressed to a system and component goes only to the stations that sent as it.
//
// Threading: build it with a strand and call every member from that strand; the callback runs there too.
// It may be destroyed after stop() at any time.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "ground/mavlink_router.hpp"
#include "services/autopilot/gcs_endpoint_config.hpp"
#include "services/autopilot/station_sockets.hpp"
#include "services/common/asio.hpp"

namespace airseg::ground {

using autopilot::StationFrame;

/// A frame from the vehicle, for routing: its addressee and its bytes.
struct VehicleFrame {
    std::optional<FrameTarget> target;
    std::vector<std::uint8_t> bytes;
};

struct StationEndpointStats {
    autopilot::GcsEndpointStats io;  // frames in, bytes out, drops, peers and clients (as GcsEndpoint)
    MavlinkRouterStats routing;
};

class StationEndpoint {
  public:
    using FromStation = std::function<void(StationId station, std::vector<StationFrame> frames)>;
    static constexpr auto kPeerTimeout = autopilot::StationSockets::kPeerTimeout;
    static constexpr std::size_t kMaxTcpBacklog = 256 * 1024;  // a parameter list from the cache fits
    static constexpr std::size_t kMaxUdpPeers = autopilot::StationSockets::kMaxUdpPeers;
    static constexpr std::size_t kMaxTcpClients = autopilot::StationSockets::kMaxTcpClients;
    static constexpr std::size_t kMaxDatagram = autopilot::StationSockets::kMaxDatagram;

    StationEndpoint(asio::any_io_executor strand, autopilot::GcsEndpointConfig config,
                    FromStation from_station);
    ~StationEndpoint();
    StationEndpoint(const StationEndpoint&) = delete;
    StationEndpoint& operator=(const StationEndpoint&) = delete;

    std::string start();  // error for people or empty
    void stop();
    /// Each frame to the stations its addressee was heard at (MavlinkRouter).
    void from_vehicle(const std::vector<VehicleFrame>& frames);
    /// Whole frames to one station (an answer of the hub's own, as the parameter cache gives).
    void to_station(StationId station, std::span<const std::uint8_t> frames);
    std::uint16_t udp_port() const;
    std::uint16_t tcp_port() const;
    StationEndpointStats stats() const;

  private:
    FromStation from_station_;
    MavlinkRouter router_;
    autopilot::StationSockets sockets_;  // last: its handlers use the router
};

}  // namespace airseg::ground

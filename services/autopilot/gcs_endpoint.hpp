#pragma once
// GcsEndpoint: the daemon's MAVLink endpoint for standard ground stations (QGroundControl, Mission Planner,
// MAVProxy) on its own sockets (StationSockets: UDP peers and a fixed destination, TCP clients): every
// station gets what the vehicle sends, and the valid frames of each datagram or read of a station go on in
// one call of ToVehicle.
//
// Threading: build it with a strand and call every member from that strand; ToVehicle runs there too. It may
// be destroyed after stop() at any time.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "services/autopilot/gcs_endpoint_config.hpp"
#include "services/autopilot/station_sockets.hpp"
#include "services/common/asio.hpp"

namespace airseg::autopilot {

class GcsEndpoint {
  public:
    using ToVehicle =
        std::function<void(std::vector<std::uint8_t> frames)>;  // whole frames, parsed and checked
    static constexpr auto kPeerTimeout = StationSockets::kPeerTimeout;
    static constexpr std::size_t kMaxUdpPeers = StationSockets::kMaxUdpPeers;
    static constexpr std::size_t kMaxTcpClients = StationSockets::kMaxTcpClients;
    /// Bytes waiting for one TCP client; beyond it the vehicle's frames are dropped for that client.
    static constexpr std::size_t kMaxTcpBacklog = 64 * 1024;

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

  private:
    StationSockets sockets_;
};

}  // namespace airseg::autopilot

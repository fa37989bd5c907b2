#pragma once
// The hub's MAVLink endpoint for standard ground stations (QGroundControl, Mission Planner, MAVProxy): the
// autopilot's frames the vehicle forwards over the radio (MavlinkFrames) go to the ground stations they are
// addressed to (StationEndpoint, routing as mavlink-router does), and theirs go back to the vehicle reliably,
// where the autopilot room checks them (docs/ground-station.md). Parameter requests the hub's cache can
// answer are answered at once from the ground (ParamCache).
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "ground/hub.hpp"
#include "ground/param_cache.hpp"
#include "ground/station_endpoint.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::ground {

struct GcsConfig {
    std::string udp_to =
        "127.0.0.1:14550";  // where ground stations listen (QGroundControl's default); "" = none
    std::string udp_listen = "127.0.0.1:0";  // where the hub hears them over UDP; "" = no UDP at all
    std::string tcp = "127.0.0.1:5760";      // ground stations connect here; "" = none
};

class GcsFeed {
  public:
    GcsFeed(asio::any_io_executor strand, Hub& hub, const GcsConfig& config);
    GcsFeed(const GcsFeed&) = delete;
    GcsFeed& operator=(const GcsFeed&) = delete;

    /// Opens the sockets; an error for people or empty.
    std::string start();
    void stop();
    /// One line for the log: where ground stations find the vehicle.
    std::string where() const;
    /// The counters for the hub's link statistics ("ground_stations").
    nlohmann::json stats() const;

  private:
    void from_station(StationId station, std::vector<StationFrame> frames);
    void from_vehicle(std::span<const std::uint8_t> bytes);
    void on_link(const groundlink::TransportEvent& event);

    Hub& hub_;
    GcsConfig config_;
    StationEndpoint endpoint_;
    mavlink::Parser vehicle_parser_;
    ParamCache params_;
    std::optional<std::chrono::steady_clock::time_point> down_since_;
    std::uint64_t refused_ = 0;
    LimitedLog log_;  // lines the vehicle's frames can make the hub write
};

}  // namespace airseg::ground

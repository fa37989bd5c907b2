#pragma once
// The hub's MAVLink endpoint for standard ground stations (QGroundControl, Mission Planner, MAVProxy): the
// autopilot's frames the vehicle forwards over the radio (MavlinkFrames) go to every ground station, and
// theirs go back to the vehicle reliably, where the autopilot room checks them (docs/ground-station.md).
#include <cstdint>
#include <string>

#include "ground/hub.hpp"
#include "services/autopilot/gcs_endpoint.hpp"

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

  private:
    Hub& hub_;
    GcsConfig config_;
    autopilot::GcsEndpoint endpoint_;
    std::uint64_t refused_ = 0;
};

}  // namespace airseg::ground

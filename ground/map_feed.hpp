#pragma once
// Feeds the live map from the hub: every telemetry sample and event as it arrives, the link statistics once a
// second, and the plan's shape (the vehicle's plan.geometry) whenever it may have changed: the link came up,
// the plan state changed, or a plan was loaded or appended through the hub. The map's buttons become hub
// commands.
#include <cstdint>

#include "ground/hub.hpp"
#include "ground/map/map_server.hpp"

namespace airseg::ground {

class MapFeed {
  public:
    /// Points of the plan asked for: enough for a survey, few enough that the answer takes seconds, not
    /// minutes, at 57600 baud.
    static constexpr int kPlanPoints = 1000;

    MapFeed(asio::any_io_executor strand, Hub& hub, MapConfig config);
    MapFeed(const MapFeed&) = delete;
    MapFeed& operator=(const MapFeed&) = delete;

    /// Starts the map's server and the feeding; an error for people or empty.
    std::string start();
    void stop();
    std::uint16_t port() const { return map_.port(); }

  private:
    void on_vehicle(const groundlink::protocol::Message& message);
    void refresh_plan();
    void tick();

    Hub& hub_;
    MapServer map_;
    asio::steady_timer timer_;
    bool link_up_ = false;
    std::optional<std::uint8_t> plan_state_;
    bool fetching_ = false;
    bool fetch_again_ = false;
    bool stopped_ = false;
};

}  // namespace airseg::ground

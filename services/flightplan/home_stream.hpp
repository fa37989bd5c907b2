#pragma once
// The stream of a return-home reaction: one waypoint at home, then the end (the feeder parks the vehicle
// there on a Stop item).
#include <optional>
#include <string>

#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

class HomeStream final : public WaypointStream {
  public:
    HomeStream(LatLon home, double speed, double arrival_radius);

    std::optional<Waypoint> next() override;
    bool seek(std::uint64_t index) override;
    bool jump_to(std::string_view) override { return false; }
    std::string element_path(std::uint32_t) const override { return "return-home"; }
    std::optional<std::string> error() const override { return std::nullopt; }

  private:
    Waypoint home_;
    bool given_ = false;
};

}  // namespace airseg::flightplan

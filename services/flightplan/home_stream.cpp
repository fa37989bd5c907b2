#include "services/flightplan/home_stream.hpp"

namespace airseg::flightplan {

HomeStream::HomeStream(LatLon home, double speed, double arrival_radius) {
    home_.position = home;
    home_.speed = speed;
    home_.arrival_radius = arrival_radius;
    home_.first_of_element = true;
    home_.last_of_element = true;
}

std::optional<Waypoint> HomeStream::next() {
    if (given_) {
        return std::nullopt;
    }
    given_ = true;
    return home_;
}

bool HomeStream::seek(std::uint64_t index) {
    if (index > 0) {
        return false;
    }
    given_ = false;
    return true;
}

}  // namespace airseg::flightplan

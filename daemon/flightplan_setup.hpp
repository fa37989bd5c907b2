#pragma once
// Turns the flightplan.* keys (and state_dir) of the daemon's configuration into the FlightplanService's
// configuration.
#include "daemon/config.hpp"
#include "services/flightplan/flightplan_service.hpp"

namespace airseg::daemon {

flightplan::FlightplanServiceConfig flightplan_setup(const Config& config);

}  // namespace airseg::daemon

#include "daemon/flightplan_setup.hpp"

namespace airseg::daemon {

flightplan::FlightplanServiceConfig flightplan_setup(const Config& config) {
    const auto& f = config.flightplan;
    flightplan::FlightplanServiceConfig s;
    s.feeder.window = static_cast<std::uint16_t>(f.window);  // the schema keeps it in 3..250
    s.feeder.retries = static_cast<std::uint32_t>(f.retries);
    s.feeder.request_timeout = f.request_timeout;
    s.feeder.resume_after_reboot = f.resume_after_reboot;
    s.load.default_vehicle =
        flightplan::VehicleProfile::defaults_for(f.vehicle).value_or(flightplan::VehicleProfile{});
    s.state_dir = config.state_dir;
    s.durability = f.fsync ? flightplan::Durability::Fsync : flightplan::Durability::NoFsync;
    s.command_timeout = f.command_timeout;
    return s;
}

}  // namespace airseg::daemon

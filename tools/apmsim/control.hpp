#pragma once
// Run-time commands of airseg-apmsim (see usage() in options.cpp) and the JSON views of the simulator.
// Sans-IO: text and simulated time in, reply out; pulling the cable is the driver's, reached through
// LinkControl.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

struct LinkControl {
    std::function<std::string()> unplug;  // returns "ok ..." or "error: ..."
    std::function<std::string()> replug;
};

/// Applies one command; returns JSON for the queries, "ok ..." or "error: ..." otherwise.
std::string apply_control(RoverSim& sim, std::string_view command, TimePoint now, const LinkControl& link);

/// Times are simulated seconds since the simulator started.
nlohmann::json state_json(const RoverSim& sim, TimePoint now);
nlohmann::json modes_json(const RoverSim& sim);
nlohmann::json stats_json(const RoverSim& sim);
/// Reached events number `from` on (at most `count`), each with the position of the item reached:
/// {"total":N,"first_kept":K,"reached":[{"n":..,"t":s,"seq":..,"lat":..,"lon":..,"distance":m,"passed":b}]}.
nlohmann::json reached_json(const RoverSim& sim, std::uint64_t from, std::uint64_t count);
/// Speed changes number `from` on (at most `count`):
/// {"total":N,"first_kept":K,"speeds":[{"n":..,"t":s,"speed":m/s,"cause":..,"seq":..}]}.
nlohmann::json speeds_json(const RoverSim& sim, std::uint64_t from, std::uint64_t count);

}  // namespace airseg::apmsim

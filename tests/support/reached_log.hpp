#pragma once
// What the simulated board reached, against what a plan expands to: the checks the flight plan end-to-end
// tests and the system suite share. Positions are compared as the autopilot stores them (1e-7 degrees).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/support/control_client.hpp"

namespace airseg::test {

using E7 = std::pair<std::int64_t, std::int64_t>;

struct Reached {
    std::uint64_t n = 0;  ///< the simulator's event number
    double t = 0;         ///< simulated seconds
    E7 at;
    std::uint16_t seq = 0;       ///< the mission slot
    double leg_s = 0;            ///< seconds in AUTO on the leg that ended here
    double median_speed = 0;     ///< the car's median speed over them, m/s
    std::uint16_t command = 16;  ///< the item's MAV_CMD
};

/// flightplan.window in config/airseg.yaml, which the system suite runs with.
inline constexpr int kDefaultWindow = 5;

/// The waypoints in a board's reached log: without its arrivals at a Stop (NAV_LOITER_UNLIM, 17), the barrier
/// after the last waypoint written (docs/flight-plan.md, "Mission layout"), which is no plan waypoint.
inline std::vector<Reached> plan_waypoints_of(std::vector<Reached> log) {
    std::erase_if(log, [](const Reached& r) { return r.command == 17; });
    return log;
}

/// The simulator's log of reached items numbered `from` on (it pages by 500).
inline std::vector<Reached> reached_log(ControlClient& sim, std::uint64_t from = 0) {
    std::vector<Reached> out;
    for (;;) {
        const auto page = sim.json("reached " + std::to_string(from) + " 500");
        if (!page.is_object() || !page["reached"].is_array()) {
            return out;
        }
        EXPECT_LE(page.value("first_kept", 0ull), from) << "the simulator's reached log overflowed";
        for (const auto& r : page["reached"]) {
            out.push_back(
                {r["n"].get<std::uint64_t>(),
                 r["t"].get<double>(),
                 {std::llround(r["lat"].get<double>() * 1e7), std::llround(r["lon"].get<double>() * 1e7)},
                 static_cast<std::uint16_t>(r.value("seq", 0)),
                 r.value("leg_s", 0.0),
                 r.value("median_speed", 0.0),
                 static_cast<std::uint16_t>(r.value("command", 16))});
        }
        if (page["reached"].size() < 500) {
            return out;
        }
        from = out.back().n + 1;
    }
}

inline std::uint64_t reached_total(ControlClient& sim) {
    return sim.json("reached 0 1").value("total", 0ull);
}

/// APM:Rover 2.x takes mission items as MISSION_ITEM, in float degrees: about 4e-6 degree (0.4 m) between
/// neighbouring floats at these latitudes. Waypoints are metres apart, so this still tells them apart.
inline bool same_place(const E7& a, const E7& b) {
    return std::llabs(a.first - b.first) <= 40 && std::llabs(a.second - b.second) <= 40;
}

/// The board's log around entry `at`, each entry with the plan waypoint it matches (searched near `at`), so a
/// failure shows whether the vehicle skipped, repeated or went back, and from which slot.
inline std::string describe_reached_around(const std::vector<Reached>& log, const std::vector<E7>& plan,
                                           std::size_t at, std::size_t span = 8) {
    std::ostringstream out;
    const std::size_t from = at > span ? at - span : 0;
    for (std::size_t i = from; i < log.size() && i <= at + span; ++i) {
        out << (i == at ? "> " : "  ") << "#" << i << " event " << log[i].n << " t=" << log[i].t << " slot "
            << log[i].seq << " at " << log[i].at.first << "," << log[i].at.second << ": ";
        const std::size_t lo = i > 4 * span ? i - 4 * span : 0;
        std::vector<std::size_t> matches;
        for (std::size_t k = lo; k < plan.size() && k <= i + 4 * span; ++k) {
            if (same_place(log[i].at, plan[k])) {
                matches.push_back(k);
            }
        }
        if (matches.empty()) {
            out << "no plan waypoint near";
        }
        for (const auto k : matches) {
            out << "plan waypoint " << k << " ";
        }
        out << "\n";
    }
    return out.str();
}

/// The positions a plan file expands to, as the autopilot stores them.
inline std::vector<E7> expected_positions(const std::string& plan_file) {
    auto loaded = flightplan::load_plan_file(plan_file);
    EXPECT_TRUE(loaded.ok()) << flightplan::to_string(loaded.errors);
    std::vector<E7> out;
    if (!loaded.ok()) {
        return out;
    }
    flightplan::Expander stream(loaded.plan);
    while (auto w = stream.next()) {
        out.emplace_back(std::llround(w->position.lat * 1e7), std::llround(w->position.lon * 1e7));
    }
    return out;
}

}  // namespace airseg::test

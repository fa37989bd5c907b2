#pragma once
// The yardstick of the flight plan manager's driving time: the same plan uploaded to the board as one plain
// mission, as a ground station would, and driven in AUTO with nobody writing to it. It runs the simulator's
// core in-process in simulated time (the airseg-apmsim binary runs the same core), so it costs a fraction of
// a second however long the plan is.
//
// The mission: home, then every waypoint with a position in plan order, a DO_CHANGE_SPEED before each
// waypoint whose leg speed differs from the one before (the first included), a timed hold as the waypoint's
// hold time (param1; a hold without a position adds to the waypoint before it) and a hold until released as
// a one-second hold (the daemon stops there too). Timed as the end-to-end cases time the daemon: from the
// first waypoint reached to the last, less the time held.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "tests/integration/apmsim/sim_harness.hpp"

namespace airseg::test {

struct PlainRun {
    double driving_s = 0;  // first waypoint reached to the last, less the holds
    double held_s = 0;
    std::size_t waypoints = 0;
    std::uint64_t restarts = 0;  // "Auto mission changed, restarted command": none is expected
    std::vector<apmsim::ReachedEvent> reached;
};

inline PlainRun drive_plainly(const std::string& plan_file, apmsim::Firmware firmware,
                              const std::vector<std::pair<std::string, float>>& params,
                              apmsim::GeoPoint home) {
    PlainRun run;
    auto loaded = flightplan::load_plan_file(plan_file);
    EXPECT_TRUE(loaded.ok()) << flightplan::to_string(loaded.errors);
    if (!loaded.ok()) {
        return run;
    }
    apmsim::RoverSimConfig config;
    config.home = home;
    config.mission_capacity = 1000;
    apmsim::test::SimHarness h(config);
    for (const auto& [name, value] : params) {
        EXPECT_TRUE(h.sim.set_param(name, value, h.now)) << name;
    }
    EXPECT_EQ(firmware, apmsim::Firmware::Modern) << "the plain mission is built for the modern board";
    h.boot_armed();

    namespace mv = mavlink;
    std::vector<mv::MissionItemInt> items{apmsim::test::waypoint(home, 0, 0)};
    double speed = -1;
    flightplan::Expander stream(loaded.plan);
    while (auto w = stream.next()) {
        const double hold = w->action == flightplan::WaypointAction::HoldFor             ? w->hold_seconds
                            : w->action == flightplan::WaypointAction::HoldUntilReleased ? 1.0
                                                                                         : 0.0;
        if (!w->has_position) {
            if (items.size() > 1) {
                items.back().param1 += static_cast<float>(std::ceil(hold));
            }
            continue;
        }
        if (w->speed > 0 && std::fabs(w->speed - speed) > 1e-6) {
            mv::MissionItemInt s;
            s.frame = 2;
            s.command = mavlink::kCmdDoChangeSpeed;
            s.param1 = 1;
            s.param2 = static_cast<float>(w->speed);
            s.param3 = -1;
            items.push_back(s);
            speed = w->speed;
        }
        mv::MissionItemInt m;
        m.frame = 3;
        m.command = mavlink::kCmdNavWaypoint;
        m.autocontinue = 1;
        m.x = static_cast<std::int32_t>(std::llround(w->position.lat * 1e7));
        m.y = static_cast<std::int32_t>(std::llround(w->position.lon * 1e7));
        m.param1 = static_cast<float>(std::ceil(hold));
        items.push_back(m);
        ++run.waypoints;
        run.held_s += std::ceil(hold);
    }
    EXPECT_EQ(h.upload(items), std::optional<std::uint8_t>(0));
    h.set_mode(apmsim::RoverMode::Auto);
    EXPECT_TRUE(h.run_until([&] { return h.sim.state().mode == apmsim::RoverMode::Hold; }, seconds(36000)));
    run.reached.assign(h.sim.reached().begin(), h.sim.reached().end());
    run.restarts = h.sim.counters().auto_restarts;
    if (run.reached.size() >= 2) {
        run.driving_s =
            std::chrono::duration<double>(run.reached.back().at - run.reached.front().at).count() -
            run.held_s;
    }
    return run;
}

}  // namespace airseg::test

// The control commands (sans-IO, simulated time), guided targets and the mission protocol under byte loss.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/control.hpp"
#include "tools/apmsim/options.hpp"

namespace airseg::apmsim::test {
namespace {

TEST(ApmsimControl, QueriesAndFaults) {
    SimHarness h;
    h.boot();
    int unplugs = 0;
    const LinkControl link{[&] {
                               ++unplugs;
                               return std::string("ok unplugged");
                           },
                           [] { return std::string("ok replugged"); }};
    const auto state = nlohmann::json::parse(apply_control(h.sim, "state", h.now, link));
    EXPECT_EQ(state["mode"], "MANUAL");
    EXPECT_EQ(state["phase"], "ready");
    EXPECT_EQ(state["armed"], false) << "ARMING_REQUIRE 1: disarmed until armed";
    EXPECT_EQ(state["gps_fix"], true);
    EXPECT_TRUE(state["failing_check"].is_null());
    EXPECT_EQ(state["restarts"], 0);
    EXPECT_EQ(state["mission_count"], 1);
    EXPECT_NEAR(state["lat"].get<double>(), h.sim.config().home.lat, 1e-9);

    EXPECT_EQ(apply_control(h.sim, "rcpilot hold", h.now, link), "ok mode HOLD");
    EXPECT_EQ(apply_control(h.sim, "rcpilot 15", h.now, link), "ok mode GUIDED");
    EXPECT_EQ(apply_control(h.sim, "rcpilot auto", h.now, link).rfind("error: rcpilot: AUTO refused", 0), 0u)
        << "no mission";
    EXPECT_EQ(apply_control(h.sim, "rcpilot FLY", h.now, link).rfind("error: rcpilot: unknown mode", 0), 0u);
    const auto modes = nlohmann::json::parse(apply_control(h.sim, "modes", h.now, link));
    ASSERT_EQ(modes.size(), 3u);
    EXPECT_EQ(modes[1]["cause"], "rc pilot");
    EXPECT_EQ(modes[2]["to"], "GUIDED");
    EXPECT_EQ(nlohmann::json::parse(apply_control(h.sim, "modes 1", h.now, link)).size(), 1u);

    EXPECT_EQ(apply_control(h.sim, "loss 0.25", h.now, link), "ok loss 0.25");
    EXPECT_DOUBLE_EQ(h.sim.faults().loss, 0.25);
    EXPECT_EQ(apply_control(h.sim, "loss 1.5", h.now, link).rfind("error: ", 0), 0u);
    EXPECT_DOUBLE_EQ(h.sim.faults().loss, 0.25) << "a bad value changes nothing";
    EXPECT_EQ(apply_control(h.sim, "loss 0.1 32", h.now, link), "ok loss 0.1 in bursts of 32 bytes");
    EXPECT_DOUBLE_EQ(h.sim.faults().loss_burst, 32.0);
    EXPECT_EQ(apply_control(h.sim, "loss 0.25", h.now, link), "ok loss 0.25");
    EXPECT_DOUBLE_EQ(h.sim.faults().loss_burst, 1.0) << "without BURST, bytes are lost one by one";
    EXPECT_EQ(apply_control(h.sim, "corrupt 0", h.now, link), "ok corrupt 0");
    EXPECT_EQ(apply_control(h.sim, "ignore-mission on", h.now, link), "ok ignore-mission on");
    EXPECT_TRUE(h.sim.faults().ignore_mission);
    EXPECT_EQ(apply_control(h.sim, "ignore-mission maybe", h.now, link).rfind("error: ", 0), 0u);
    EXPECT_EQ(apply_control(h.sim, "freeze on", h.now, link), "ok freeze on");
    EXPECT_TRUE(h.sim.frozen());
    EXPECT_EQ(nlohmann::json::parse(apply_control(h.sim, "state", h.now, link))["frozen"], true);
    EXPECT_EQ(apply_control(h.sim, "freeze off", h.now, link), "ok freeze off");
    EXPECT_FALSE(h.sim.frozen());
    EXPECT_EQ(apply_control(h.sim, "freeze", h.now, link).rfind("error: ", 0), 0u);
    EXPECT_EQ(apply_control(h.sim, "slow 250", h.now, link), "ok slow 250 ms");
    EXPECT_EQ(h.sim.faults().slow, milliseconds(250));
    EXPECT_EQ(apply_control(h.sim, "param WP_RADIUS 3", h.now, link), "ok param WP_RADIUS 3");
    EXPECT_EQ(nlohmann::json::parse(apply_control(h.sim, "param WP_RADIUS", h.now, link))["value"], 3.0);
    EXPECT_EQ(apply_control(h.sim, "param NOPE", h.now, link).rfind("error: ", 0), 0u);
    EXPECT_EQ(apply_control(h.sim, "unplug", h.now, link), "ok unplugged");
    EXPECT_EQ(unplugs, 1);
    EXPECT_EQ(apply_control(h.sim, "", h.now, link), "error: empty command");
    EXPECT_EQ(apply_control(h.sim, "dance", h.now, link).rfind("error: unknown command 'dance'", 0), 0u);

    EXPECT_EQ(apply_control(h.sim, "hbstall 3", h.now, link), "ok no heartbeats for 3 s");
    EXPECT_EQ(apply_control(h.sim, "reboot 4", h.now, link), "ok reboot in 4 s");
    h.run_for(seconds(5));
    EXPECT_EQ(h.sim.state().boots, 2u);
    EXPECT_EQ(apply_control(h.sim, "reboot", h.now, link), "ok rebooting");
    EXPECT_EQ(h.sim.state().boots, 3u);
    EXPECT_EQ(apply_control(h.sim, "rcpilot HOLD", h.now, link).rfind("error: ", 0), 0u) << "still booting";
}

TEST(ApmsimControl, OptionsParse) {
    const auto o = parse_options({"--link", "/tmp/t", "--home", "40.5,-3.25", "--speedup", "50", "--param",
                                  "CRUISE_SPEED=4", "--reached-style", "text", "--hb-stall", "10:5", "--slow",
                                  "200", "--mission-capacity", "30"});
    ASSERT_TRUE(o);
    EXPECT_DOUBLE_EQ(o->sim.home.lat, 40.5);
    EXPECT_DOUBLE_EQ(o->sim.home.lon, -3.25);
    EXPECT_DOUBLE_EQ(o->speedup, 50);
    EXPECT_EQ(o->sim.reached_style, ReachedStyle::TextOnly);
    EXPECT_EQ(o->sim.mission_capacity, 30u);
    ASSERT_EQ(o->hb_stalls.size(), 1u);
    EXPECT_EQ(o->hb_stalls[0].start, seconds(10));
    EXPECT_EQ(o->faults.slow, milliseconds(200));
    EXPECT_FALSE(parse_options({"--help"}));
    EXPECT_THROW(parse_options({"--home", "1,2"}), cli::UsageError) << "--link is required";
    EXPECT_THROW(parse_options({"--link", "x", "--home", "95,2"}), cli::UsageError);
    EXPECT_THROW(parse_options({"--link", "x", "--reached-style", "loud"}), cli::UsageError);
    EXPECT_THROW(parse_options({"--link", "x", "--param", "CRUISE_SPEED"}), cli::UsageError);
}

TEST(ApmsimGuided, GoToHereOnlyInGuided) {
    SimHarness h;
    h.boot_armed();
    auto go = waypoint(h.sim.config().home, 0, 30);
    go.current = 2;
    std::size_t from = h.received.size();
    h.send(go);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 1) << "refused outside GUIDED";
    h.set_mode(RoverMode::Guided);
    from = h.received.size();
    h.send(go);
    EXPECT_EQ(h.last<mv::MissionAck>(from)->type, 0);
    ASSERT_TRUE(h.wait_text("Reached Destination", seconds(60)));
    EXPECT_LT(distance_m(h.sim.state().position, waypoint_point(go)), 3.0);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Guided) << "GUIDED stays, stopped at the target";
    EXPECT_EQ(h.sim.mission().count(), 1u) << "a guided target is not a mission item";
}

TEST(ApmsimLossy, UploadSurvivesByteLossThroughRerequests) {
    RoverSimConfig c;
    c.seed = 3;
    SimHarness h(c);
    h.boot();
    h.sim.faults().loss = 0.01;
    const auto items = line_mission(h.sim.config().home, 40, 5);
    h.upload(items);  // the final ACK itself may be lost: judge by what the board stored
    EXPECT_EQ(h.sim.mission().count(), items.size());
    EXPECT_GT(h.sim.mission_stats().rerequests, 0u);
    EXPECT_GT(h.sim.counters().bytes_lost, 0u);
    for (std::size_t i = 1; i < items.size(); ++i) {
        EXPECT_EQ(h.sim.mission().at(i).lat_e7, items[i].x) << i;
    }
}

TEST(ApmsimLossy, CorruptedFramesAreDroppedNotMisread) {
    SimHarness h;
    h.boot();
    h.sim.faults().corrupt = 0.02;
    mv::ParamSet s;
    mv::set_text(s.param_id, "CRUISE_SPEED");
    s.param_value = 4.0F;
    for (int i = 0; i < 50; ++i) {
        h.send(s);
    }
    h.run_for(seconds(1));
    EXPECT_GT(h.sim.counters().bytes_corrupted, 0u);
    EXPECT_FLOAT_EQ(h.sim.params().get("CRUISE_SPEED", 0), 4.0F);
    for (const auto& v : h.all<mv::ParamValue>()) {
        EXPECT_EQ(mv::text_of(v.param_id), "CRUISE_SPEED");
    }
}

}  // namespace
}  // namespace airseg::apmsim::test

namespace airseg::apmsim::test {
namespace {

TEST(ApmsimCommands, HomeVersionArmRebootAndUnknown) {
    SimHarness h;
    h.boot();
    mv::CommandLong c;
    c.command = 512;  // MAV_CMD_REQUEST_MESSAGE
    c.param1 = static_cast<float>(mv::HomePosition::kId);
    std::size_t from = h.received.size();
    h.send(c);
    const auto home = h.last<mv::HomePosition>(from);
    ASSERT_TRUE(home);
    EXPECT_EQ(home->latitude, static_cast<std::int32_t>(std::lround(h.sim.config().home.lat * 1e7)));
    EXPECT_EQ(home->altitude, 5000);
    EXPECT_EQ(h.last<mv::CommandAck>(from)->result, 0);

    c.command = 520;  // MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES
    from = h.received.size();
    h.send(c);
    const auto version = h.last<mv::AutopilotVersion>(from);
    ASSERT_TRUE(version);
    EXPECT_TRUE(version->capabilities & 0x4) << "MISSION_INT";

    c.command = 400;  // arm, then disarm
    c.param1 = 1;
    h.send(c);
    EXPECT_TRUE(h.sim.state().armed);
    auto hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->base_mode & 128, 128);
    c.param1 = 0;
    h.send(c);
    EXPECT_FALSE(h.sim.state().armed);
    hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->base_mode & 128, 0);
    EXPECT_EQ(hb->system_status, 4) << "MANUAL: ACTIVE, armed or not";

    c.command = 31000;
    from = h.received.size();
    h.send(c);
    EXPECT_EQ(h.last<mv::CommandAck>(from)->result, 3) << "UNSUPPORTED";

    c.command = 246;  // MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN
    c.param1 = 1;
    from = h.received.size();
    h.send(c);
    ASSERT_TRUE(h.last<mv::CommandAck>(from));
    EXPECT_EQ(h.last<mv::CommandAck>(from)->command, 246);
    EXPECT_EQ(h.sim.state().phase, BootPhase::Silent);
    EXPECT_EQ(h.sim.state().boots, 2u);
}

TEST(ApmsimCommands, MessagesForAnotherSystemAreIgnored) {
    SimHarness h;
    h.boot();
    mv::CommandLong c;
    c.target_system = 7;
    c.command = 176;
    c.param1 = 1;
    c.param2 = 4;
    const std::size_t from = h.received.size();
    h.send(c);
    EXPECT_FALSE(h.last<mv::CommandAck>(from));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Manual);
}

}  // namespace
}  // namespace airseg::apmsim::test

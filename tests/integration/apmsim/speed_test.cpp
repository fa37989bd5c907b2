// The speed the simulated rover drives at: modern, WP_SPEED as it was when AUTO was entered; rover2,
// CRUISE_SPEED (PARAM_SET applies at once); MAV_CMD_DO_CHANGE_SPEED as a command and as a mission item, the
// speed log, and a HOLD forced by the board mid-plan; for both firmware profiles, in simulated time.
#include <gtest/gtest.h>

#include <memory>

#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/control.hpp"

namespace airseg::apmsim::test {
namespace {

std::unique_ptr<SimHarness> booted(Firmware f) {
    auto h = std::make_unique<SimHarness>(RoverSimConfig::for_firmware(f));
    if (f == Firmware::Rover2) {
        h->gcs.set_version(mv::Version::V1);
    }
    h->boot_armed();
    return h;
}

void param_set(SimHarness& h, const char* name, float value) {
    mv::ParamSet p;
    mv::set_text(p.param_id, name);
    p.param_value = value;
    p.param_type = 9;  // MAV_PARAM_TYPE_REAL32
    h.send(p);
}

/// Home and one place `north` metres away: a long straight leg.
std::vector<mv::MissionItem> long_leg(const SimHarness& h, double north) {
    return {to_float(waypoint(h.sim.config().home, 0, 0)), to_float(waypoint(h.sim.config().home, north, 0))};
}

std::vector<SpeedChange> log_of(const RoverSim& sim) {
    return {sim.speed_log().begin(), sim.speed_log().end()};
}

void cruise_speed_is_followed(Firmware f) {
    SCOPED_TRACE(std::string(firmware_name(f)));
    auto h = booted(f);
    ASSERT_EQ(log_of(h->sim).size(), 1u);
    EXPECT_EQ(h->sim.speed_log().front().cause, "power on");
    EXPECT_EQ(h->sim.speed_log().front().speed, 2.0);

    param_set(*h, "CRUISE_SPEED", 3);
    ASSERT_EQ(h->upload_float(long_leg(*h, 400)), 0);
    h->set_mode_message(RoverMode::Auto);
    h->run_for(seconds(10));
    EXPECT_NEAR(h->sim.state().speed, 3.0, 0.05);

    const TimePoint changed = h->now;
    param_set(*h, "CRUISE_SPEED", 5);
    EXPECT_EQ(h->sim.cruise_speed(), 5.0) << "at once";
    h->run_for(seconds(2));
    EXPECT_NEAR(h->sim.state().speed, 5.0, 0.05) << "2 m/s of acceleration: one second to get there";
    const auto log = log_of(h->sim);
    ASSERT_EQ(log.size(), 3u);
    EXPECT_EQ(log[1].speed, 3.0);
    EXPECT_EQ(log[1].cause, "param");
    EXPECT_EQ(log[2].speed, 5.0);
    EXPECT_EQ(log[2].cause, "param");
    EXPECT_EQ(log[2].at, changed);

    EXPECT_TRUE(h->sim.set_param("CRUISE_SPEED", 4, h->now));
    EXPECT_EQ(h->sim.speed_log().back().cause, "control");
    const auto json = speeds_json(h->sim, 1, 2);
    EXPECT_EQ(json["total"], 4);
    ASSERT_EQ(json["speeds"].size(), 2u);
    EXPECT_EQ(json["speeds"][0]["n"], 1);
    EXPECT_EQ(json["speeds"][1]["speed"], 5.0);
}

// Current Rover: AR_WPNav takes WP_SPEED when AUTO is entered (ModeAuto::_enter() → AR_WPNav::init()); a
// later WP_SPEED waits for the next entry, and CRUISE_SPEED is not the AUTO speed at all.
TEST(ApmsimSpeed, ModernAutoDrivesAtWpSpeedAsItWasWhenAutoWasEntered) {
    auto h = booted(Firmware::Modern);
    ASSERT_EQ(h->sim.speed_log().size(), 1u);
    EXPECT_EQ(h->sim.speed_log().front().speed, 2.0);
    param_set(*h, "WP_SPEED", 3);
    param_set(*h, "CRUISE_SPEED", 5);
    ASSERT_EQ(h->upload_float(long_leg(*h, 600)), 0);
    h->set_mode(RoverMode::Auto);
    h->run_for(seconds(10));
    EXPECT_NEAR(h->sim.state().speed, 3.0, 0.05) << "WP_SPEED, not CRUISE_SPEED";
    param_set(*h, "WP_SPEED", 4);
    h->run_for(seconds(3));
    EXPECT_NEAR(h->sim.state().speed, 3.0, 0.05) << "read when AUTO is entered, not while in it";
    h->set_mode(RoverMode::Hold);
    h->set_mode(RoverMode::Auto);
    h->run_for(seconds(10));
    EXPECT_NEAR(h->sim.state().speed, 4.0, 0.05);
    const auto log = log_of(h->sim);
    ASSERT_EQ(log.size(), 3u) << speeds_json(h->sim, 0, 10).dump();
    EXPECT_EQ(log[1].speed, 3.0);
    EXPECT_EQ(log[1].cause, "param") << "before any AUTO, WP_SPEED is what AUTO will take";
    EXPECT_EQ(log[2].speed, 4.0);
    EXPECT_EQ(log[2].cause, "mode");
}

TEST(ApmsimSpeed, AutoFollowsCruiseSpeedAndParamSetAppliesAtOnceRover2) {
    cruise_speed_is_followed(Firmware::Rover2);
}

TEST(ApmsimSpeed, ModernDoChangeSpeedCommandHoldsUntilAutoIsEnteredAgain) {
    auto h = booted(Firmware::Modern);
    ASSERT_EQ(h->upload_float(long_leg(*h, 400)), 0);
    h->set_mode(RoverMode::Auto);
    h->run_for(seconds(5));
    mv::CommandLong c;
    c.command = 178;  // MAV_CMD_DO_CHANGE_SPEED
    c.param1 = 1;     // ground speed
    c.param2 = 4;
    c.param3 = -1;  // throttle: no change
    std::size_t from = h->received.size();
    h->send(c);
    ASSERT_TRUE(h->last<mv::CommandAck>(from));
    EXPECT_EQ(h->last<mv::CommandAck>(from)->result, 0);
    EXPECT_EQ(h->sim.speed_log().back().cause, "command");
    h->run_for(seconds(3));
    EXPECT_NEAR(h->sim.state().speed, 4.0, 0.05);
    c.param2 = -3;
    from = h->received.size();
    h->send(c);
    EXPECT_EQ(h->last<mv::CommandAck>(from)->result, 4) << "a negative speed fails";
    c.param2 = 0.04F;
    from = h->received.size();
    h->send(c);
    EXPECT_EQ(h->last<mv::CommandAck>(from)->result, 4) << "below AR_WPNav's 0.05 m/s fails";
    c.param1 = 2;  // climb speed
    c.param2 = 3;
    from = h->received.size();
    h->send(c);
    EXPECT_EQ(h->last<mv::CommandAck>(from)->result, 2) << "DENIED";
    EXPECT_NEAR(h->sim.cruise_speed(), 4.0, 1e-6);

    h->set_mode(RoverMode::Hold);
    c.param1 = 1;
    c.param2 = 3;
    from = h->received.size();
    h->send(c);
    EXPECT_EQ(h->last<mv::CommandAck>(from)->result, 4) << "HOLD takes no speed (Mode::set_desired_speed())";
    h->set_mode(RoverMode::Auto);
    EXPECT_EQ(h->sim.cruise_speed(), 2.0) << "entering AUTO forgets the command's speed: WP_SPEED";
    EXPECT_EQ(h->sim.speed_log().back().cause, "mode");
}

TEST(ApmsimSpeed, ModernDoChangeSpeedItemRunsWhileHeadingToTheNextPlace) {
    auto h = booted(Firmware::Modern);
    const GeoPoint home = h->sim.config().home;
    ASSERT_EQ(h->upload_float({to_float(waypoint(home, 0, 0)), to_float(waypoint(home, 30, 0)),
                               command_item(178, 1, 4.5F, -1), to_float(waypoint(home, 200, 0))}),
              0);
    h->set_mode(RoverMode::Auto);
    ASSERT_TRUE(h->run_until([&] { return h->sim.reached_total() == 1; }, seconds(60)));
    const SpeedChange& change = h->sim.speed_log().back();
    EXPECT_EQ(change.cause, "mission");
    EXPECT_EQ(change.speed, 4.5);
    EXPECT_EQ(change.seq, 2);
    EXPECT_EQ(change.at, h->sim.reached().back().at) << "when the place before it is reached";
    h->run_for(seconds(5));
    EXPECT_NEAR(h->sim.state().speed, 4.5, 0.05);
    EXPECT_EQ(h->sim.state().current_seq, 3);
}

TEST(ApmsimSpeed, Rover2DoChangeSpeedItemSetsWholeMetresInRamOnly) {
    auto h = booted(Firmware::Rover2);
    const GeoPoint home = h->sim.config().home;
    ASSERT_EQ(h->upload_float({to_float(waypoint(home, 0, 0)), to_float(waypoint(home, 20, 0)),
                               command_item(178, 0, 3.7F, -1), to_float(waypoint(home, 100, 0)),
                               command_item(178, 1, 1.0F, -1),  // speed type 1: 2.x ignores it
                               to_float(waypoint(home, 140, 0))}),
              0);
    const std::size_t from = h->received.size();
    h->set_mode_message(RoverMode::Auto);
    ASSERT_TRUE(h->run_until([&] { return h->sim.state().mode == RoverMode::Hold; }, seconds(120)));
    std::vector<SpeedChange> mission;
    for (const auto& c : log_of(h->sim)) {
        if (c.cause == "mission") {
            mission.push_back(c);
        }
    }
    ASSERT_EQ(mission.size(), 1u);
    EXPECT_EQ(mission[0].speed, 3.0) << "param2 is stored as a whole number";
    EXPECT_EQ(mission[0].seq, 2);
    ASSERT_EQ(h->sim.reached().size(), 3u);
    EXPECT_EQ(mission[0].at, h->sim.reached()[0].at) << "run after item 1, while heading to item 3";
    EXPECT_EQ(h->sim.params().get("CRUISE_SPEED", 0), 3.0F);
    bool text = false;
    for (const auto& t : h->texts(from)) {
        text = text || t == "Cruise speed: 3.0";
    }
    EXPECT_TRUE(text);

    h->sim.reboot(h->now);
    h->boot();
    EXPECT_EQ(h->sim.params().get("CRUISE_SPEED", 0), 2.0F) << "g.speed_cruise.set() did not save it";
    EXPECT_EQ(h->sim.speed_log().back().cause, "reboot");
}

void board_forces_hold_mid_plan(Firmware f) {
    SCOPED_TRACE(std::string(firmware_name(f)));
    auto h = booted(f);
    ASSERT_EQ(h->upload_float(long_leg(*h, 400)), 0);
    h->set_mode_message(RoverMode::Auto);
    h->run_for(seconds(5));
    ASSERT_GT(h->sim.state().speed, 1.0);
    const LinkControl link;
    EXPECT_EQ(apply_control(h->sim, "mode HOLD", h->now, link), "ok mode HOLD");
    EXPECT_EQ(h->sim.mode_history().back().cause, "board");
    h->run_for(seconds(3));
    EXPECT_EQ(h->sim.state().speed, 0);
    const GeoPoint stopped = h->sim.state().position;
    h->run_for(seconds(3));
    EXPECT_EQ(distance_m(stopped, h->sim.state().position), 0);
    EXPECT_EQ(h->last<mv::Heartbeat>()->custom_mode, 4u);
    EXPECT_EQ(h->sim.speed_log().size(), 1u) << "HOLD does not change the cruise speed";
}

TEST(ApmsimSpeed, BoardForcesHoldMidPlanModern) {
    board_forces_hold_mid_plan(Firmware::Modern);
}

TEST(ApmsimSpeed, BoardForcesHoldMidPlanRover2) {
    board_forces_hold_mid_plan(Firmware::Rover2);
}

}  // namespace
}  // namespace airseg::apmsim::test

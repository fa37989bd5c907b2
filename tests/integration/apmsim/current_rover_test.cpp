// The modern profile's ArduPilot Rover 4.x behaviours, in simulated time: arming and its checks, the mission
// change detector and its restarts, and S-curve cornering (corner speeds, stops at legs of no length, at the
// end and at held waypoints). docs/simulators.md names the source of each.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/control.hpp"
#include "tools/apmsim/mission_change_detector.hpp"

namespace airseg::apmsim::test {
namespace {

bool has_text(const SimHarness& h, std::size_t from, std::string_view text) {
    const auto texts = h.texts(from);
    return std::find(texts.begin(), texts.end(), text) != texts.end();
}

std::size_t count_text(const SimHarness& h, std::size_t from, std::string_view text) {
    const auto texts = h.texts(from);
    return static_cast<std::size_t>(std::count(texts.begin(), texts.end(), text));
}

/// Rewrites item `seq` with a one-item partial write, as the daemon's window does.
void rewrite(SimHarness& h, std::uint16_t seq, mv::MissionItemInt item) {
    mv::MissionWritePartialList p;
    p.start_index = static_cast<std::int16_t>(seq);
    p.end_index = static_cast<std::int16_t>(seq);
    h.send(p);
    item.seq = seq;
    h.send(item);
}

mv::MissionItemInt jump_to(std::uint16_t target) {
    mv::MissionItemInt j;
    j.command = kCmdDoJump;
    j.frame = 2;
    j.param1 = target;
    j.param2 = -1;
    return j;
}

/// The lowest speed of the car within `radius` metres of `point` while `until` does not hold.
double slowest_near(SimHarness& h, GeoPoint point, double radius, const std::function<bool()>& until,
                    Duration limit) {
    double slowest = 1e9;
    h.run_until(
        [&] {
            const auto s = h.sim.state();
            if (distance_m(s.position, point) <= radius) {
                slowest = std::min(slowest, s.speed);
            }
            return until();
        },
        limit);
    return slowest;
}

// ---- arming
// ------------------------------------------------------------------------------------------------

TEST(CurrentRoverArming, BootsDisarmedAndAutoStartsTheMissionButDrivesNothingUntilArmed) {
    SimHarness h;
    h.boot();
    EXPECT_FALSE(h.sim.state().armed);
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 20)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_EQ(h.last<mv::CommandAck>()->result, 0) << "AUTO may be entered disarmed";
    const GeoPoint start = h.sim.state().position;
    h.run_for(seconds(20));
    EXPECT_EQ(h.sim.state().current_seq, 1) << "the mission started";
    EXPECT_TRUE(h.sim.reached().empty()) << "no waypoint completes disarmed";
    EXPECT_EQ(distance_m(start, h.sim.state().position), 0.0);
    auto hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->system_status, 4) << "AUTO: ACTIVE although disarmed";
    EXPECT_EQ(hb->base_mode & 128, 0);

    const std::size_t from = h.received.size();
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(0));
    EXPECT_TRUE(has_text(h, from, "Throttle armed"));
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(120)));
    EXPECT_EQ(h.sim.reached().size(), 3u);
    EXPECT_TRUE(h.sim.state().armed) << "the end of the mission does not disarm";
    hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->base_mode & 128, 128);
    EXPECT_EQ(hb->system_status, 3) << "HOLD: STANDBY";
}

TEST(CurrentRoverArming, NoGpsFixRefusesArmingInAutoWithItsReasonAndReportsItAsPreArm) {
    SimHarness h;
    h.boot();
    const LinkControl link;
    EXPECT_EQ(apply_control(h.sim, "gps lose", h.now, link), "ok gps lose");
    EXPECT_EQ(nlohmann::json::parse(apply_control(h.sim, "state", h.now, link))["gps_fix"], false);
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(0)) << "MANUAL needs no position";
    EXPECT_EQ(h.arm(false), std::optional<std::uint8_t>(0));
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 2, 20)), 0);
    h.set_mode(RoverMode::Auto);
    std::size_t from = h.received.size();
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(4)) << "MAV_RESULT_FAILED";
    EXPECT_TRUE(has_text(h, from, "Arm: Need Position Estimate"));
    const auto arm_text = h.all<mv::Statustext>(from);
    ASSERT_FALSE(arm_text.empty());
    EXPECT_EQ(arm_text.front().severity, mavlink::kSeverityCritical);
    EXPECT_FALSE(h.sim.state().armed);
    EXPECT_EQ(h.sim.counters().arm_refused, 1u);

    // The pass -> fail change (MANUAL -> AUTO) is reported about 4 s after the last report, then every 30 s.
    from = h.received.size();
    h.run_for(seconds(61));
    EXPECT_EQ(count_text(h, from, "PreArm: Need Position Estimate"), 2u);
    from = h.received.size();
    h.run_for(seconds(30));
    EXPECT_EQ(count_text(h, from, "PreArm: Need Position Estimate"), 1u);

    apply_control(h.sim, "gps fix", h.now, link);
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(0));
    from = h.received.size();
    h.run_for(seconds(61));
    EXPECT_EQ(count_text(h, from, "PreArm: Need Position Estimate"), 0u) << "armed: no PreArm reports";
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() == 2; }, seconds(60)));
}

TEST(CurrentRoverArming, AFailedCheckIsReportedInEveryModeAndArmingChecksZeroSkipsIt) {
    SimHarness h;
    h.boot();
    const LinkControl link;
    EXPECT_EQ(apply_control(h.sim, "fail-check Compass not calibrated", h.now, link),
              "ok fail-check Compass not calibrated");
    std::size_t from = h.received.size();
    h.run_for(seconds(31));
    EXPECT_EQ(count_text(h, from, "PreArm: Compass not calibrated"), 1u) << "first report 30 s after boot";
    from = h.received.size();
    EXPECT_EQ(apply_control(h.sim, "arm", h.now, link).rfind("error: arm: refused", 0), 0u);
    h.run_for(milliseconds(1));  // what the board sent meanwhile
    EXPECT_TRUE(has_text(h, from, "Arm: Compass not calibrated"));
    EXPECT_TRUE(h.sim.set_param("ARMING_CHECK", 0, h.now));
    from = h.received.size();
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(0));
    EXPECT_TRUE(has_text(h, from, "Warning: Arming Checks Disabled"));
    EXPECT_EQ(apply_control(h.sim, "disarm", h.now, link), "ok disarmed");
    EXPECT_TRUE(h.sim.set_param("ARMING_CHECK", 1, h.now));
    EXPECT_EQ(apply_control(h.sim, "fail-check off", h.now, link), "ok fail-check off");
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(0));
}

TEST(CurrentRoverArming, RtlIsNotArmableUnlessForcedAndArmingRequireZeroIsArmedFromBoot) {
    SimHarness h;
    h.boot();
    h.set_mode(RoverMode::Rtl);
    ASSERT_EQ(h.sim.state().mode, RoverMode::Rtl);
    const std::size_t from = h.received.size();
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(4));
    EXPECT_TRUE(has_text(h, from, "Arm: Mode not armable"));
    EXPECT_EQ(h.arm(true, 21196), std::optional<std::uint8_t>(0)) << "the force code skips the checks";

    SimHarness unrequired;
    unrequired.sim.set_param("ARMING_REQUIRE", 0, unrequired.now);
    unrequired.boot();
    EXPECT_TRUE(unrequired.sim.state().armed);
    EXPECT_EQ(unrequired.arm(false), std::optional<std::uint8_t>(0));
    EXPECT_TRUE(unrequired.sim.state().armed) << "AP_Arming::is_armed(): always, without ARMING_REQUIRE";
}

TEST(CurrentRoverArming, Rover2IsArmedFromBootAndHasNoArmingCommand) {
    SimHarness h(RoverSimConfig::for_firmware(Firmware::Rover2));
    h.gcs.set_version(mv::Version::V1);
    h.boot();
    EXPECT_TRUE(h.sim.state().armed);
    EXPECT_EQ(h.arm(), std::optional<std::uint8_t>(3)) << "UNSUPPORTED";
}

// ---- the mission change detector ------------------------------------------------------------------------

TEST(CurrentRoverChangeDetector, WatchesTheCurrentNavigationCommandAndTheNextTwoFollowingJumps) {
    StoredItem home;
    MissionStore store(50, home);
    auto wp = [](int i) {
        StoredItem s;
        s.lat_e7 = 412756000 + i * 1000;
        s.lon_e7 = 19866000;
        return s;
    };
    for (int i = 1; i <= 6; ++i) {
        store.write(static_cast<std::size_t>(i), wp(i));
    }
    std::vector<std::int32_t> jumps(store.count(), 0);
    MissionChangeDetector d;
    EXPECT_FALSE(d.check(store, 2, jumps)) << "the first look only notes";
    store.write(5, wp(50));
    EXPECT_FALSE(d.check(store, 2, jumps)) << "item 5 is past 2, 3, 4";
    store.write(4, wp(4));
    EXPECT_FALSE(d.check(store, 2, jumps)) << "written again, the same: no change";
    store.write(4, wp(40));
    EXPECT_TRUE(d.check(store, 2, jumps));
    EXPECT_FALSE(d.check(store, 2, jumps)) << "reported once";
    store.write(5, wp(5));
    EXPECT_FALSE(d.check(store, 3, jumps)) << "a change seen as the current command moves is absorbed";

    // A DO_JUMP after item 4 back to 2: from 4 the watched commands are 4, 2, 3.
    StoredItem jump;
    jump.command = kCmdDoJump;
    jump.param1 = 2;
    jump.param2 = -1;
    store.write(5, jump);
    EXPECT_EQ(next_nav_cmd(store, 5, jumps), std::optional<std::uint16_t>(2));
    EXPECT_FALSE(d.check(store, 4, jumps));
    store.write(3, wp(30));
    EXPECT_TRUE(d.check(store, 4, jumps)) << "item 3, after the jump, is watched";
    // A jump that has run its repeats is stepped over.
    jump.param2 = 1;
    store.write(5, jump);
    jumps[5] = 1;
    EXPECT_EQ(next_nav_cmd(store, 5, jumps), std::optional<std::uint16_t>(6));
}

TEST(CurrentRoverChangeDetector, ARewriteInsideTheLookAheadRestartsTheLegWithASpeedDipOutsideItNothing) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint home = h.sim.config().home;
    ASSERT_EQ(h.upload(line_mission(home, 6, 60)), 0);
    h.set_mode(RoverMode::Auto);
    h.run_for(seconds(15));
    ASSERT_EQ(h.sim.state().current_seq, 1);
    ASSERT_NEAR(h.sim.state().speed, 2.0, 0.05);

    rewrite(h, 4, waypoint(home, 240, 5));  // 1, 2, 3 are watched: 4 is not
    h.run_for(seconds(1));
    EXPECT_EQ(h.sim.counters().auto_restarts, 0u);
    rewrite(h, 3, waypoint(home, 180, 0));  // the same content again
    h.run_for(seconds(1));
    EXPECT_EQ(h.sim.counters().auto_restarts, 0u);

    const std::size_t from = h.received.size();
    rewrite(h, 3, waypoint(home, 180, 5));
    double slowest = 9;
    h.run_until(
        [&] {
            slowest = std::min(slowest, h.sim.state().speed);
            return false;
        },
        seconds(3));
    EXPECT_EQ(h.sim.counters().auto_restarts, 1u);
    EXPECT_TRUE(has_text(h, from, "Auto mission changed, restarted command"));
    for (const auto& t : h.all<mv::Statustext>(from)) {
        if (mv::text_of(t.text) == "Auto mission changed, restarted command") {
            EXPECT_EQ(t.severity, mavlink::kSeverityCritical);
        }
    }
    // Re-planned from rest at ATC_ACCEL_MAX (1 m/s²) while the car brakes at 2 m/s²: 2 -> about 0.67.
    EXPECT_NEAR(slowest, 0.67, 0.1);
    h.run_for(seconds(5));
    EXPECT_NEAR(h.sim.state().speed, 2.0, 0.05) << "back to speed";
    EXPECT_EQ(h.sim.state().current_seq, 1) << "the same command, restarted";
    const auto stats = nlohmann::json::parse(apply_control(h.sim, "stats", h.now, LinkControl{}));
    EXPECT_EQ(stats["auto_restarts"], 1);
}

TEST(CurrentRoverChangeDetector, NoRestartWhileHoldingAtAWaypointOrWithTheDetectorOff) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint home = h.sim.config().home;
    auto items = line_mission(home, 4, 20);
    items[1].param1 = 10;  // hold 10 s at item 1
    ASSERT_EQ(h.upload(items), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() == 1; }, seconds(60)));
    rewrite(h, 2, waypoint(home, 40, 5));
    h.run_for(seconds(2));
    EXPECT_EQ(h.sim.counters().auto_restarts, 0u) << "holding: the Loiter submode";

    RoverSimConfig off;
    off.firmware.mission_change_restart = false;
    SimHarness g(off);
    g.boot_armed();
    ASSERT_EQ(g.upload(line_mission(home, 4, 60)), 0);
    g.set_mode(RoverMode::Auto);
    g.run_for(seconds(10));
    rewrite(g, 2, waypoint(home, 120, 5));
    g.run_for(seconds(2));
    EXPECT_EQ(g.sim.counters().auto_restarts, 0u);
}

// ---- cornering -----------------------------------------------------------------------------------------

TEST(CurrentRoverCornering, AZeroLengthNextLegStopsTheCarAtTheWaypointAStraightOneDoesNot) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint home = h.sim.config().home;
    ASSERT_EQ(h.upload({waypoint(home, 0, 0), waypoint(home, 40, 0), waypoint(home, 80, 0),
                        waypoint(home, 120, 0)}),
              0);
    h.set_mode(RoverMode::Auto);
    const double straight = slowest_near(
        h, waypoint_point(waypoint(home, 80, 0)), 2.0, [&] { return h.sim.reached().size() >= 2; },
        seconds(60));
    EXPECT_NEAR(straight, 2.0, 0.05) << "straight on: no slowing";

    // The ring's wrap: the waypoint twice, then the jump back. The next leg after the first copy has no
    // length, found through the DO_JUMP too.
    SimHarness r;
    r.boot_armed();
    ASSERT_EQ(r.upload({waypoint(home, 0, 0), waypoint(home, 40, 0), waypoint(home, 80, 0),
                        waypoint(home, 80, 0), jump_to(1), waypoint(home, 120, 0)}),
              0);
    r.set_mode(RoverMode::Auto);
    const double wrap = slowest_near(
        r, waypoint_point(waypoint(home, 80, 0)), 2.0, [&] { return r.sim.reached().size() >= 3; },
        seconds(60));
    EXPECT_LT(wrap, 0.15) << "a full stop at the duplicated point";
    EXPECT_EQ(r.sim.state().current_seq, 1) << "then on through the jump";
    // Through the jump as well: the last item of the ring followed by a jump to an item at its place.
    SimHarness j;
    j.boot_armed();
    ASSERT_EQ(j.upload({waypoint(home, 0, 0), waypoint(home, 40, 0), waypoint(home, 80, 0), jump_to(4),
                        waypoint(home, 80, 0), waypoint(home, 120, 0)}),
              0);
    j.set_mode(RoverMode::Auto);
    const double through_jump = slowest_near(
        j, waypoint_point(waypoint(home, 80, 0)), 2.0, [&] { return j.sim.reached().size() >= 3; },
        seconds(60));
    EXPECT_LT(through_jump, 0.15);
}

TEST(CurrentRoverCornering, CornersAreTakenAtTheSpeedOfTheirArcAndAUturnOrTheLastWaypointStops) {
    SimHarness h;
    h.boot_armed();
    h.sim.set_param("WP_SPEED", 5, h.now);
    const GeoPoint home = h.sim.config().home;
    ASSERT_EQ(h.upload({waypoint(home, 0, 0), waypoint(home, 60, 0), waypoint(home, 60, 60),
                        waypoint(home, 60, 0), waypoint(home, 120, 0)}),
              0);
    h.set_mode(RoverMode::Auto);
    // 90°: an arc of WP_RADIUS / tan(45°) = 2 m at ATC_TURN_MAX_G 0.6 g: sqrt(5.88 * 2) = 3.4 m/s.
    const double corner = slowest_near(
        h, waypoint_point(waypoint(home, 60, 0)), 2.5, [&] { return h.sim.reached().size() >= 1; },
        seconds(60));
    EXPECT_NEAR(corner, std::sqrt(0.6 * 9.80665 * 2.0), 0.2);
    // Back the way it came: a stop.
    const double uturn = slowest_near(
        h, waypoint_point(waypoint(home, 60, 60)), 2.0, [&] { return h.sim.reached().size() >= 2; },
        seconds(60));
    EXPECT_LT(uturn, 0.15);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(120)));
    EXPECT_LT(distance_m(h.sim.state().position, waypoint_point(waypoint(home, 120, 0))), 0.5)
        << "stopped on the last waypoint";
    EXPECT_LT(h.sim.reached().back().distance, 0.5);
}

TEST(CurrentRoverCornering, AWaypointWithAHoldTimeStopsAndHoldsThenGoesOn) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint home = h.sim.config().home;
    auto items = line_mission(home, 3, 30);
    items[2].param1 = 8;
    ASSERT_EQ(h.upload(items), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() == 2; }, seconds(60)));
    const TimePoint arrived = h.now;
    EXPECT_LT(h.sim.state().speed, 0.15);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().speed > 0.5; }, seconds(30)));
    EXPECT_NEAR(std::chrono::duration<double>(h.now - arrived).count(), 8.5, 0.7);
    EXPECT_EQ(h.sim.state().current_seq, 3);
}

TEST(CurrentRoverCornering, TheReachedLogTimesEachLegAndItsMedianSpeed) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 60)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() == 3; }, seconds(120)));
    const auto& r = h.sim.reached();
    EXPECT_NEAR(r[1].median_speed, 2.0, 0.01);
    EXPECT_NEAR(r[1].leg_s, 30.0, 0.5);
    const auto json = reached_json(h.sim, 1, 1);
    EXPECT_NEAR(json["reached"][0]["median_speed"].get<double>(), 2.0, 0.01);
}

TEST(CurrentRoverCornering, Rover2KeepsDrivingThroughAZeroLengthLeg) {
    SimHarness h(RoverSimConfig::for_firmware(Firmware::Rover2));
    h.gcs.set_version(mv::Version::V1);
    h.boot();
    const GeoPoint home = h.sim.config().home;
    ASSERT_EQ(h.upload_float(to_float({waypoint(home, 0, 0), waypoint(home, 40, 0), waypoint(home, 80, 0),
                                       waypoint(home, 80, 0), waypoint(home, 120, 0)})),
              0);
    h.set_mode_message(RoverMode::Auto);
    const double slowest = slowest_near(
        h, waypoint_point(waypoint(home, 80, 0)), 2.0, [&] { return h.sim.reached().size() >= 3; },
        seconds(60));
    EXPECT_GT(slowest, 1.5);
}

}  // namespace
}  // namespace airseg::apmsim::test

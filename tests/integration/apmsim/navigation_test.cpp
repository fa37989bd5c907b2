// RoverSim driving missions in simulated time: reached events, HOLD at the end, retargeting, mode history.
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/integration/apmsim/sim_harness.hpp"

namespace airseg::apmsim::test {
namespace {

std::vector<std::uint16_t> reached_seqs(const SimHarness& h, std::size_t from = 0) {
    std::vector<std::uint16_t> seqs;
    for (const auto& r : h.all<mv::MissionItemReached>(from)) {
        seqs.push_back(r.seq);
    }
    return seqs;
}

TEST(ApmsimNav, DrivesTheMissionInOrderThenHolds) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 5, 20)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_EQ(h.last<mv::CommandAck>()->result, 0);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(120)));
    EXPECT_EQ(reached_seqs(h), (std::vector<std::uint16_t>{1, 2, 3, 4, 5}));
    std::vector<std::string> texts;
    for (const auto& t : h.all<mv::Statustext>()) {
        const auto s = std::string(mv::text_of(t.text));
        if (s.find("waypoint #") != std::string::npos) {
            texts.push_back(s);
        }
    }
    ASSERT_EQ(texts.size(), 5u);
    EXPECT_EQ(texts[0].rfind("Reached waypoint #1 dist ", 0), 0u) << texts[0];
    // 100 m at CRUISE_SPEED 2 m/s: about 50 s of simulated time.
    EXPECT_GT(h.now - kStart, seconds(45));
    const auto& hist = h.sim.mode_history();
    EXPECT_EQ(hist.back().to, RoverMode::Hold);
    EXPECT_EQ(hist.back().cause, "mission end");
    EXPECT_EQ(hist.back().mission_count, 6u);
    EXPECT_NEAR(distance_m(h.sim.state().position, offset(h.sim.config().home, 0, 100)), 0, 3.0);
}

TEST(ApmsimNav, TextOnlyStyleSendsNoReachedMessage) {
    RoverSimConfig c;
    c.reached_style = ReachedStyle::TextOnly;
    SimHarness h(c);
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 2, 10)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(60)));
    EXPECT_TRUE(h.all<mv::MissionItemReached>().empty());
    EXPECT_EQ(h.sim.reached().size(), 2u);
    int reached_texts = 0;
    for (const auto& t : h.all<mv::Statustext>()) {
        reached_texts += mv::text_of(t.text).find("Reached waypoint #") != std::string_view::npos ? 1 : 0;
    }
    EXPECT_EQ(reached_texts, 2);
}

TEST(ApmsimNav, SetCurrentRetargetsAtOnce) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 5, 30)), 0);
    h.set_mode(RoverMode::Auto);
    h.run_for(seconds(3));
    EXPECT_EQ(h.sim.state().current_seq, 1);
    mv::MissionSetCurrent sc;
    sc.seq = 4;
    std::size_t from = h.received.size();
    h.send(sc);
    auto cur = h.last<mv::MissionCurrent>(from);
    ASSERT_TRUE(cur);
    EXPECT_EQ(cur->seq, 4);
    const auto s = h.sim.state();
    EXPECT_EQ(s.current_seq, 4);
    ASSERT_TRUE(s.target);
    EXPECT_NEAR(distance_m(*s.target, offset(h.sim.config().home, 0, 120)), 0, 0.5);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(200)));
    EXPECT_EQ(reached_seqs(h, from), (std::vector<std::uint16_t>{4, 5}));
}

// A board without the mission change detector (FirmwareProfile::mission_change_restart off) keeps driving to
// the copy of its target; the current one restarts the command instead (the next test).
TEST(ApmsimNav, NewMissionKeepsTheTargetBeingDrivenTo) {
    RoverSimConfig c;
    c.firmware.mission_change_restart = false;
    SimHarness h(c);
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 40)), 0);
    h.set_mode(RoverMode::Auto);
    h.run_for(seconds(5));
    const auto before = h.sim.state();
    ASSERT_EQ(before.current_seq, 1);
    // A different mission, eastwards: the rover still drives to the old item 1 first.
    std::vector<mv::MissionItemInt> east{waypoint(h.sim.config().home, 0, 0)};
    for (int i = 1; i <= 3; ++i) {
        east.push_back(waypoint(h.sim.config().home, 0, 40.0 * i));
    }
    ASSERT_EQ(h.upload(east), 0);
    const auto after = h.sim.state();
    ASSERT_TRUE(after.target);
    EXPECT_NEAR(distance_m(*after.target, offset(h.sim.config().home, 0, 40)), 0, 0.5);
    const std::size_t from = h.received.size();
    ASSERT_TRUE(h.run_until([&] { return !h.sim.reached().empty(); }, seconds(60)));
    EXPECT_NEAR(distance_m(h.sim.state().position, offset(h.sim.config().home, 0, 40)), 0, 3.0);
    // Then it carries on with the new item 2.
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() >= 2; }, seconds(120)));
    EXPECT_NEAR(distance_m(h.sim.state().position, waypoint_point(east[2])), 0, 3.0);
    (void)from;
}

// ModeAuto's change detector: the new mission rewrites the current command, which restarts at its new place
// ("Auto mission changed, restarted command"), re-planned from where the car is.
TEST(ApmsimNav, NewMissionUnderAutoRestartsTheCurrentCommandAtItsNewPlace) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 40)), 0);
    h.set_mode(RoverMode::Auto);
    h.run_for(seconds(5));
    ASSERT_EQ(h.sim.state().current_seq, 1);
    std::vector<mv::MissionItemInt> east{waypoint(h.sim.config().home, 0, 0)};
    for (int i = 1; i <= 3; ++i) {
        east.push_back(waypoint(h.sim.config().home, 0, 40.0 * i));
    }
    const std::size_t from = h.received.size();
    ASSERT_EQ(h.upload(east), 0);
    h.run_for(milliseconds(100));
    EXPECT_GE(h.sim.counters().auto_restarts, 1u);
    const auto texts = h.texts(from);
    EXPECT_NE(std::find(texts.begin(), texts.end(), "Auto mission changed, restarted command"), texts.end());
    ASSERT_TRUE(h.sim.state().target);
    EXPECT_NEAR(distance_m(*h.sim.state().target, waypoint_point(east[1])), 0, 0.5);
    ASSERT_TRUE(h.run_until([&] { return !h.sim.reached().empty(); }, seconds(60)));
    EXPECT_NEAR(distance_m(h.sim.state().position, waypoint_point(east[1])), 0, 3.0);
}

// A frozen vehicle stays where it is however much time passes, while the board still talks (heartbeats, the
// mission protocol); released, it carries on from the same place to the same target without catching up.
TEST(ApmsimNav, AFrozenVehicleKeepsItsPlaceWhileTheLinkGoesOnAndCarriesOnWhenReleased) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 4, 40)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return !h.sim.reached().empty(); }, seconds(60)));
    h.sim.freeze(true, h.now);
    EXPECT_TRUE(h.sim.frozen());
    const auto held = h.sim.state();
    const std::size_t from = h.received.size();
    h.run_for(seconds(120));
    EXPECT_EQ(h.sim.reached().size(), 1u);
    EXPECT_EQ(distance_m(h.sim.state().position, held.position), 0.0);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto);
    EXPECT_GE(h.all<mv::Heartbeat>(from).size(), 100u) << "the link goes on";
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 4, 40)), 0) << "and so does the mission protocol";
    EXPECT_EQ(distance_m(h.sim.state().position, held.position), 0.0);

    h.sim.freeze(false, h.now);
    h.run_for(milliseconds(100));
    EXPECT_LT(distance_m(h.sim.state().position, held.position), 1.0) << "a frozen spell is not caught up";
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(120)));
    EXPECT_EQ(reached_seqs(h), (std::vector<std::uint16_t>{1, 2, 3, 4}));
}

TEST(ApmsimNav, RebootStopsTheMissionAndResumesNothing) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 3, 30)), 0);
    h.set_mode(RoverMode::Auto);
    h.run_for(seconds(5));
    h.sim.reboot(h.now);
    h.boot();
    const auto s = h.sim.state();
    EXPECT_EQ(s.mode, RoverMode::Manual);
    EXPECT_EQ(s.current_seq, 0);
    const auto& hist = h.sim.mode_history();
    ASSERT_GE(hist.size(), 3u);
    EXPECT_EQ(hist[hist.size() - 2].cause, "reboot");
    EXPECT_EQ(hist[hist.size() - 2].to, RoverMode::Initialising);
    EXPECT_EQ(hist.back().to, RoverMode::Manual);
}

TEST(ApmsimNav, RtlDrivesHomeThenHolds) {
    SimHarness h;
    h.boot_armed();
    ASSERT_EQ(h.upload(line_mission(h.sim.config().home, 1, 30)), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(60)));
    h.set_mode(RoverMode::Rtl);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().mode == RoverMode::Hold; }, seconds(60)));
    EXPECT_EQ(h.sim.mode_history().back().cause, "rtl end");
    EXPECT_LT(distance_m(h.sim.state().position, h.sim.config().home), 3.0);
}

TEST(ApmsimNav, DeterministicWithTheSameSeed) {
    auto run = [](std::uint64_t seed) {
        RoverSimConfig c;
        c.seed = seed;
        SimHarness h(c);
        h.sim.faults().loss = 0.01;
        h.boot();
        h.send(mv::ParamRequestList{});
        h.run_for(seconds(3));
        return std::make_pair(h.sim.counters().bytes_lost, h.received.size());
    };
    EXPECT_EQ(run(7), run(7));
    EXPECT_NE(run(7), run(8));
}

TEST(ApmsimNav, HeartbeatStall) {
    SimHarness h;
    h.boot();
    h.sim.stall_heartbeats(seconds(5), h.now);
    std::size_t from = h.received.size();
    h.run_for(milliseconds(4900));
    EXPECT_TRUE(h.all<mv::Heartbeat>(from).empty());
    from = h.received.size();
    h.run_for(seconds(2));
    EXPECT_FALSE(h.all<mv::Heartbeat>(from).empty());
}

TEST(ApmsimNav, ScheduledReboot) {
    SimHarness h;
    h.boot();
    h.sim.schedule_reboot(h.now + seconds(10));
    h.run_for(seconds(9));
    EXPECT_EQ(h.sim.state().boots, 1u);
    h.run_for(seconds(2));
    EXPECT_EQ(h.sim.state().boots, 2u);
    EXPECT_EQ(h.sim.state().phase, BootPhase::Silent);
}

}  // namespace
}  // namespace airseg::apmsim::test

namespace airseg::apmsim::test {
namespace {

// A client feeding the mission while the rover drives it (the rolling window of the seed's navigation loop):
// each reached event appends one more item with a partial write; the rover never stops until the feed does.
TEST(ApmsimNav, FeedingItemsWhileDrivingNeverHoldsEarly) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint home = h.sim.config().home;
    ASSERT_EQ(h.upload(line_mission(home, 3, 15)), 0);
    h.set_mode(RoverMode::Auto);
    int appended = 0;
    std::size_t seen = 0;
    while (h.sim.state().mode == RoverMode::Auto) {
        ASSERT_TRUE(h.run_until(
            [&] { return h.sim.reached().size() > seen || h.sim.state().mode != RoverMode::Auto; },
            seconds(60)));
        seen = h.sim.reached().size();
        if (appended < 7 && h.sim.state().mode == RoverMode::Auto) {
            const auto next = static_cast<std::int16_t>(h.sim.mission().count());
            mv::MissionWritePartialList p;
            p.start_index = next;
            p.end_index = next;
            h.send(p);
            auto item = waypoint(home, 15.0 * next, 0);
            item.seq = static_cast<std::uint16_t>(next);
            h.send(item);
            ++appended;
        }
    }
    ASSERT_EQ(h.sim.reached().size(), 10u);
    for (std::size_t i = 0; i < 10; ++i) {
        EXPECT_EQ(h.sim.reached()[i].seq, i + 1);
    }
    int holds = 0;
    for (const auto& m : h.sim.mode_history()) {
        holds += m.to == RoverMode::Hold ? 1 : 0;
    }
    EXPECT_EQ(holds, 1);
    EXPECT_EQ(h.sim.mode_history().back().cause, "mission end");
    EXPECT_EQ(h.sim.mode_history().back().current_seq, 10);
}

}  // namespace
}  // namespace airseg::apmsim::test

namespace airseg::apmsim::test {
namespace {

// The rolling window's mission shape: a ring of waypoints closed by DO_JUMP (repeat -1), and a
// NAV_LOITER_UNLIM where the vehicle stays once it gets there.
TEST(ApmsimNav, DoJumpForeverLoopsTheRingAndLoiterUnlimitedStaysPut) {
    SimHarness h;
    h.boot_armed();
    auto items = line_mission(h.sim.config().home, 3, 15);
    mv::MissionItemInt jump;
    jump.command = kCmdDoJump;
    jump.frame = 2;
    jump.param1 = 1;
    jump.param2 = -1;
    items.push_back(jump);
    ASSERT_EQ(h.upload(items), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.reached().size() >= 7; }, seconds(300)));
    EXPECT_EQ(reached_seqs(h), (std::vector<std::uint16_t>{1, 2, 3, 1, 2, 3, 1}));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto);  // never ran off the end

    h.set_mode(RoverMode::Hold);
    auto loiter = line_mission(h.sim.config().home, 2, 15);
    loiter[2].command = kCmdNavLoiterUnlimited;
    ASSERT_EQ(h.upload(loiter), 0);
    h.set_mode(RoverMode::Auto);
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().current_seq == 2 && h.sim.reached().back().seq == 2; },
                            seconds(300)));
    const auto reached = h.sim.reached().size();
    h.run_for(seconds(30));
    EXPECT_EQ(h.sim.state().mode, RoverMode::Auto);
    EXPECT_EQ(h.sim.state().current_seq, 2);
    EXPECT_EQ(h.sim.state().speed, 0.0);
    EXPECT_EQ(h.sim.reached().size(), reached);  // reached once, then it stays
}

}  // namespace
}  // namespace airseg::apmsim::test

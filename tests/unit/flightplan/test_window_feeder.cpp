// WindowFeeder against the simulated autopilot: ordering, starvation, impairments, reboot, replace, skip,
// pause and holds, all in simulated time.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

#include "tests/support/tree_paths.hpp"
#include "tests/unit/flightplan/sim_autopilot.hpp"

namespace airseg::flightplan {
namespace {

using test::Harness;
using test::Impairments;
using test::SyntheticStream;

std::vector<std::uint64_t> iota(std::uint64_t from, std::uint64_t to) {
    std::vector<std::uint64_t> v(to - from);
    std::iota(v.begin(), v.end(), from);
    return v;
}

void expect_visited(const Harness& h, double base_lat, std::uint64_t from, std::uint64_t to,
                    std::size_t at = 0) {
    ASSERT_GE(h.ap.visited().size(), at + (to - from));
    for (std::uint64_t i = from; i < to; ++i) {
        ASSERT_EQ(h.ap.visited()[at + (i - from)], SyntheticStream::position_of(base_lat, i))
            << "waypoint " << i;
    }
}

/// A board driven by hand, one place at a time: the vehicle reaches at most one place per step, so it
/// outruns the feeder, which falls behind to the frontier.
struct OutrunningBoard {
    std::map<std::uint16_t, autopilot::MissionItem> items;
    std::uint16_t target = 1;

    /// Takes an answered upload or set-current; a write is the caller's.
    void take(const FeederRequest& r) {
        if (const auto* up = std::get_if<autopilot::UploadMission>(&r.op)) {
            for (std::size_t k = 0; k < up->items.size(); ++k) {
                items[static_cast<std::uint16_t>(k + 1)] = up->items[k];
            }
        } else if (const auto* sc = std::get_if<autopilot::SetMissionCurrent>(&r.op)) {
            target = sc->slot;
        }
    }
    /// 100 ms on: the feeder's next request, taken (a write is the caller's); without one the vehicle drives
    /// one place and `drain` reads the feeder's events.
    template <class Drain>
    std::optional<FeederRequest> step(WindowFeeder& f, TimePoint& now, Drain&& drain) {
        now += milliseconds(100);
        auto r = f.poll_request(now);
        if (!r) {
            drive_one(f, now);
            drain();
            return std::nullopt;
        }
        take(*r);
        return r;
    }
    /// Drives to the target if it holds a waypoint (a barrier, or nothing, holds the vehicle there) and
    /// reports it reached and the next target, through the wrap's jump.
    void drive_one(WindowFeeder& f, TimePoint now) {
        const auto at = items.find(target);
        if (at == items.end() || at->second.kind != autopilot::MissionItem::Kind::Waypoint) {
            return;
        }
        f.on_reached(target, now);
        target = static_cast<std::uint16_t>(target + 1);
        if (const auto next = items.find(target);
            next != items.end() && next->second.kind == autopilot::MissionItem::Kind::JumpTo) {
            target = next->second.jump_slot;
        }
        f.on_current(target, now);
    }
};

TEST(FlightplanFeeder, ConfigRejectsWindowBelowThree) {
    FeederConfig c;
    c.window = 2;
    EXPECT_TRUE(c.validate().has_value());
    c.window = 3;
    EXPECT_FALSE(c.validate().has_value());
}

TEST(FlightplanFeeder, LongPlanReachedOnceInOrderWithoutStarvation) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(2500), h.now);
    const int steps = h.run_until_done(6000);
    ASSERT_LT(steps, 6000);
    for (int i = 0; i < 3; ++i) {
        h.step();
    }
    EXPECT_EQ(h.reached, iota(0, 2500));
    expect_visited(h, 41.0, 0, 2500);
    EXPECT_EQ(h.ap.visited().size(), 2500u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.ap.hold_requests(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
    EXPECT_EQ(h.feeder.progress().waypoints_reached, 2500u);
    EXPECT_TRUE(h.ap.parked());  // on the Stop item after the last waypoint
    EXPECT_EQ(h.count(FeederEvent::Kind::PlanDone), 1u);
}

TEST(FlightplanFeeder, TheRingWrapsOnBothCommandProcessorsWithoutARestartOrAStop) {
    for (const bool legacy : {false, true}) {
        Harness h;
        h.ap.legacy = legacy;
        h.feeder.replace_plan(test::synthetic(300), h.now);
        ASSERT_LT(h.run_until_done(1000), 1000) << "legacy " << legacy;
        EXPECT_EQ(h.reached, iota(0, 300)) << "legacy " << legacy;
        expect_visited(h, 41.0, 0, 300);
        EXPECT_EQ(h.ap.visited().size(), 300u) << "each waypoint driven once, the wrap's place never";
        EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
        EXPECT_EQ(h.ap.stop_holds(), legacy ? 1 : 0) << "only at the plan's end";
        EXPECT_EQ(h.ap.hold_requests(), 0);
        // Every write after a reached waypoint lands outside the change detector's look-ahead.
        EXPECT_EQ(h.ap.restarts(), 0) << "legacy " << legacy;
        EXPECT_EQ(h.feeder.progress().frontier_stops, 0u) << "legacy " << legacy;
    }
}

TEST(FlightplanFeeder, MinimumWindowOfThreeKeepsUp) {
    FeederConfig c;
    c.window = 3;
    Impairments imp;
    imp.requests_per_step = 1;
    Harness h(c, imp);
    h.feeder.replace_plan(test::synthetic(300), h.now);
    ASSERT_LT(h.run_until_done(2000), 2000);
    EXPECT_EQ(h.reached, iota(0, 300));
    expect_visited(h, 41.0, 0, 300);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
}

TEST(FlightplanFeeder, LateAndDuplicateReachedReportsAreAbsorbed) {
    Impairments imp;
    imp.duplicate_reached = 0.2;
    imp.delay_reached = 0.2;
    Harness h({}, imp, 7);
    h.feeder.replace_plan(test::synthetic(2000), h.now);
    ASSERT_LT(h.run_until_done(6000), 6000);
    EXPECT_EQ(h.reached, iota(0, 2000));
    expect_visited(h, 41.0, 0, 2000);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
    EXPECT_GT(h.feeder.progress().ignored_reached, 100u);
}

TEST(FlightplanFeeder, LostReachedReportsAreRecoveredFromCurrentTarget) {
    Impairments imp;
    imp.drop_reached = 0.15;
    Harness h({}, imp, 11);
    h.feeder.replace_plan(test::synthetic(2000), h.now);
    ASSERT_LT(h.run_until_done(6000), 6000);
    EXPECT_EQ(h.reached, iota(0, 2000));
    expect_visited(h, 41.0, 0, 2000);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

TEST(FlightplanFeeder, FailedRequestsAreRetried) {
    Impairments imp;
    imp.fail_request = 0.2;
    imp.requests_per_step = 3;
    Harness h({}, imp, 3);
    h.feeder.replace_plan(test::synthetic(1000), h.now);
    ASSERT_LT(h.run_until_done(6000), 6000);
    EXPECT_EQ(h.reached, iota(0, 1000));
    expect_visited(h, 41.0, 0, 1000);
    EXPECT_GT(h.feeder.progress().retries, 10u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

TEST(FlightplanFeeder, PersistentWriteFailuresHoldTheVehicleUntilTheWindowIsBack) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(300), h.now);
    for (int i = 0; i < 30; ++i) {
        h.step();
    }
    h.impairments().fail_writes = true;
    for (int i = 0; i < 40; ++i) {
        h.step();
    }
    EXPECT_GE(h.count(FeederEvent::Kind::RequestFailed), 1u);
    EXPECT_FALSE(h.ap.in_auto());
    EXPECT_GE(h.ap.hold_requests(), 1);
    const auto reached_while_failing = h.reached.size();
    EXPECT_LT(reached_while_failing, 30u + 5u);  // at most the window's worth went by
    h.impairments().fail_writes = false;
    ASSERT_LT(h.run_until_done(2000), 2000);
    EXPECT_EQ(h.reached, iota(0, 300));
    expect_visited(h, 41.0, 0, 300);  // never drove to a stale slot
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

TEST(FlightplanFeeder, RebootMidPlanRebuildsTheWindowAndCarriesOn) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(800), h.now);
    for (int i = 0; i < 300; ++i) {
        h.step();
    }
    const auto before = h.reached.size();
    ASSERT_GT(before, 250u);
    h.ap.reboot();
    h.feeder.on_autopilot_rebooted(h.now);
    EXPECT_EQ(h.feeder.progress().next_waypoint, before);
    ASSERT_LT(h.run_until_done(3000), 3000);
    EXPECT_EQ(h.reached, iota(0, 800));
    expect_visited(h, 41.0, 0, 800);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

// The daemon declares a reboot 1.5 s after the board's clock went back (docs/autopilot.md, Reboots); under
// qemu-armel that was after the board's boot heartbeats (INITIALISING, then MANUAL) had been read, and the
// feeder, seeing MANUAL mid-plan, asked for AUTO: the board started its stored mission at slot 1 and drove
// back to a waypoint of an old turn of the window (reached 0 1 2 3 4 2 5 …). A board seen booting holds no
// window the feeder can count on.
TEST(FlightplanFeeder, ABoardSeenBootingIsNotPutInAutoBeforeItsWindowIsWrittenAgain) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(800), h.now);
    for (int i = 0; i < 300; ++i) {
        h.step();
    }
    const auto visited = h.ap.visited().size();
    const auto next = *h.feeder.progress().next_waypoint;
    ASSERT_NE(h.ap.slots()[1].lat, SyntheticStream::position_of(41.0, next).lat) << "slot 1 holds an old one";
    h.ap.boot_keeping_mission();
    ASSERT_LT(h.run_until_done(3000), 3000);
    ASSERT_GT(h.ap.visited().size(), visited);
    EXPECT_EQ(h.ap.visited()[visited], SyntheticStream::position_of(41.0, next))
        << "the first place driven after the boot is the first waypoint not reached";
    EXPECT_EQ(h.reached, iota(0, 800));
    expect_visited(h, 41.0, next, 800, visited);
}

TEST(FlightplanFeeder, ReplacePlanKeepsCurrentTargetThenFollowsNewPlanWithoutStopping) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(1000, 41.0), h.now);
    for (int i = 0; i < 100; ++i) {
        h.step();
    }
    const auto target = *h.feeder.progress().next_waypoint;
    const auto visited_before = h.ap.visited().size();
    h.feeder.replace_plan(test::synthetic(200, 43.0), h.now);
    h.drain();
    ASSERT_LT(h.run_until_done(2000), 2000);
    // The old current target, then the whole new plan.
    ASSERT_EQ(h.ap.visited().size(), visited_before + 1 + 200);
    EXPECT_EQ(h.ap.visited()[visited_before], SyntheticStream::position_of(41.0, target));
    expect_visited(h, 43.0, 0, 200, visited_before + 1);
    EXPECT_EQ(h.ap.hold_requests(), 0);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().waypoints_reached, 200u);
    EXPECT_EQ(h.feeder.progress().generation, 2u);
}

TEST(FlightplanFeeder, SkipHeadsForTheRequestedWaypointNow) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(1000), h.now);
    for (int i = 0; i < 50; ++i) {
        h.step();
    }
    const auto visited_before = h.ap.visited().size();
    const auto target = *h.feeder.progress().next_waypoint;
    ASSERT_TRUE(h.feeder.skip_to(600, h.now));
    EXPECT_FALSE(h.feeder.skip_to(5000, h.now));
    ASSERT_LT(h.run_until_done(2000), 2000);
    // At most the target it was heading for (here a step is a whole leg, and the new head takes three
    // writes and a set-current), then 600 onwards.
    const bool finished_leg = h.ap.visited()[visited_before] == SyntheticStream::position_of(41.0, target);
    expect_visited(h, 41.0, 600, 1000, visited_before + (finished_leg ? 1 : 0));
    EXPECT_EQ(h.ap.visited().size(), visited_before + (finished_leg ? 1 : 0) + 400);
    EXPECT_EQ(h.reached.back(), 999u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

TEST(FlightplanFeeder, JumpToNamedElementContinuesThere) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    const auto visited_before = h.ap.visited().size();
    const auto target = *h.feeder.progress().next_waypoint;
    ASSERT_TRUE(h.feeder.jump_to("second-half", h.now));
    EXPECT_FALSE(h.feeder.jump_to("nowhere", h.now));
    ASSERT_LT(h.run_until_done(500), 500);
    const bool finished_leg = h.ap.visited()[visited_before] == SyntheticStream::position_of(41.0, target);
    expect_visited(h, 41.0, 50, 100, visited_before + (finished_leg ? 1 : 0));
}

TEST(FlightplanFeeder, PauseHoldsTheVehicleAndResumeContinues) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    h.feeder.pause();
    EXPECT_EQ(h.feeder.progress().state, PlanState::Paused);
    h.step();
    const auto reached_when_paused = h.reached.size();
    for (int i = 0; i < 30; ++i) {
        h.step();
    }
    EXPECT_LE(h.reached.size(), reached_when_paused + 1);
    EXPECT_FALSE(h.ap.in_auto());
    h.feeder.resume();
    ASSERT_LT(h.run_until_done(500), 500);
    EXPECT_EQ(h.reached, iota(0, 100));
    expect_visited(h, 41.0, 0, 100);
}

TEST(FlightplanFeeder, ResumeAfterTheOperatorDroveTheVehicleByHandPutsItBackOnThePlan) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    ASSERT_TRUE(h.ap.in_auto());
    h.ap.operator_takes_over();  // e.g. MANUAL_NAVIGATION and a joystick session from the ground
    const auto reached_by_hand = h.reached.size();
    for (int i = 0; i < 30; ++i) {
        h.step();
    }
    EXPECT_EQ(h.reached.size(), reached_by_hand) << "out of AUTO the vehicle follows no plan";
    h.feeder.resume();
    ASSERT_LT(h.run_until_done(500), 500) << "resume must bring the vehicle back to AUTO";
    EXPECT_EQ(h.reached, iota(0, 100));
}

TEST(FlightplanFeeder, TheBoardsOwnHoldMidPlanIsUndoneAndThePlanGoesOnInOrder) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    ASSERT_TRUE(h.ap.in_auto());
    const auto target_before = h.ap.current();
    h.ap.board_holds();
    h.step();
    EXPECT_EQ(h.count(FeederEvent::Kind::Interrupted), 1u);
    EXPECT_NE(h.feeder.progress().interruption.find("HOLD by itself"), std::string::npos)
        << h.feeder.progress().interruption;
    // Within a few steps (the daemon's second each) the vehicle is back in AUTO at the same target.
    EXPECT_LT(h.run_until_auto(5), 5) << "the plan must continue by itself after the board's own HOLD";
    EXPECT_EQ(h.count(FeederEvent::Kind::Continued), 1u);
    EXPECT_EQ(h.feeder.progress().state, PlanState::Running);
    (void)target_before;
    ASSERT_LT(h.run_until_done(500), 500);
    EXPECT_EQ(h.reached, iota(0, 100));
    expect_visited(h, 41.0, 0, 100);
    EXPECT_EQ(h.feeder.progress().interruptions, 1u);
}

// A failsafe while the vehicle waits at the frontier: on a board that stays in AUTO on a Stop, that HOLD is
// not the barrier's (a 2.x board's own stop there is), so it is said like any other and undone once the head
// is written.
TEST(FlightplanFeeder, TheBoardsOwnHoldWhileWaitingAtTheFrontierIsSaidAndUndone) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(50), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    h.impairments().requests_per_step = 0;  // the feeder falls behind: the vehicle parks on the barrier
    for (int i = 0; i < 8; ++i) {
        h.step();
    }
    ASSERT_TRUE(h.feeder.progress().held_at_frontier);
    ASSERT_TRUE(h.ap.in_auto()) << "parked on the barrier in AUTO";
    h.ap.board_holds();
    h.step();
    ASSERT_EQ(h.count(FeederEvent::Kind::Interrupted), 1u);
    const auto said = std::find_if(h.events.begin(), h.events.end(), [](const FeederEvent& e) {
        return e.kind == FeederEvent::Kind::Interrupted;
    });
    EXPECT_NE(said->detail.find("HOLD by itself"), std::string::npos) << said->detail;
    // Undone once the head and its barrier are written (two writes, a set-current, AUTO).
    h.impairments().requests_per_step = 2;
    EXPECT_LT(h.run_until_auto(8), 8) << "the plan must continue by itself after the board's own HOLD";
    EXPECT_EQ(h.count(FeederEvent::Kind::Continued), 1u);
    ASSERT_LT(h.run_until_done(200), 200);
    EXPECT_EQ(h.reached, iota(0, 50));
    expect_visited(h, 41.0, 0, 50);
    EXPECT_EQ(h.feeder.progress().interruptions, 1u);
}

TEST(FlightplanFeeder, AReachedReportThatCrossesTheBoardsOwnHoldStillCounts) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(40), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    // The vehicle reaches its target and the board holds by itself; the reached report arrives after the
    // mode change.
    const auto reached = h.ap.step();
    ASSERT_TRUE(reached.has_value());
    h.ap.board_holds();
    h.report_modes();
    h.feeder.on_reached(*reached, h.now);
    h.drain();
    ASSERT_LT(h.run_until_done(200), 200);
    EXPECT_EQ(h.reached, iota(0, 40));
    expect_visited(h, 41.0, 0, 40);
    EXPECT_EQ(h.ap.visited().size(), 40u) << "the waypoint reached before the HOLD is not driven again";
}

TEST(FlightplanFeeder, TheRcPilotTakingTheVehicleInterruptsThePlanUntilResume) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(60), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    h.ap.operator_takes_over();
    h.step();
    EXPECT_EQ(h.feeder.progress().state, PlanState::Interrupted);
    EXPECT_NE(h.feeder.progress().interruption.find("RC pilot"), std::string::npos);
    const auto reached = h.reached.size();
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    EXPECT_FALSE(h.ap.in_auto()) << "the RC pilot keeps the vehicle: no AUTO behind the pilot's back";
    EXPECT_EQ(h.ap.hold_requests(), 0) << "nor a HOLD";
    EXPECT_EQ(h.reached.size(), reached);
    h.feeder.resume();
    ASSERT_LT(h.run_until_done(300), 300);
    EXPECT_EQ(h.reached, iota(0, 60));
}

TEST(FlightplanFeeder, AnOperatorsParkingCommandPausesThePlan) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(60), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    h.ap.operator_parks();
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    EXPECT_EQ(h.feeder.progress().state, PlanState::Paused);
    EXPECT_FALSE(h.ap.in_auto());
    EXPECT_EQ(h.count(FeederEvent::Kind::Interrupted), 0u);
    h.feeder.resume();
    ASSERT_LT(h.run_until_done(300), 300);
    EXPECT_EQ(h.reached, iota(0, 60));
}

TEST(FlightplanFeeder, ANewPlanAfterTheOperatorParkedAFinishedOneDrives) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(8, 41.0), h.now);
    ASSERT_LT(h.run_until_done(100), 100);
    h.step();
    h.ap.operator_parks();
    for (int i = 0; i < 3; ++i) {
        h.step();
    }
    ASSERT_FALSE(h.ap.in_auto());
    h.feeder.resume();  // what plan.load does unless --paused
    h.feeder.replace_plan(test::synthetic(10, 42.0), h.now);
    ASSERT_LT(h.run_until_done(100), 100) << "the second plan must drive without a separate resume";
    ASSERT_EQ(h.ap.visited().size(), 18u);
    EXPECT_EQ(h.ap.visited().back(), test::SyntheticStream::position_of(42.0, 9));
}

TEST(FlightplanFeeder, AMissionTheAutopilotRefusesFailsThePlanInsteadOfRetryingForever) {
    Impairments imp;
    imp.refuse_missions = true;
    Harness h({}, imp);
    h.feeder.replace_plan(test::synthetic(30), h.now);
    for (int i = 0; i < 60; ++i) {
        h.step();
    }
    const auto p = h.feeder.progress();
    EXPECT_EQ(p.state, PlanState::Failed);
    EXPECT_NE(p.failure.find("UNSUPPORTED_FRAME"), std::string::npos) << p.failure;
    EXPECT_EQ(h.count(FeederEvent::Kind::PlanFailed), 1u);
    EXPECT_FALSE(h.feeder.poll_request(h.now).has_value()) << "nothing more is asked of the autopilot";
    // A new plan starts afresh (on a board that now takes it).
    h.impairments().refuse_missions = false;
    h.feeder.replace_plan(test::synthetic(20, 42.0), h.now);
    ASSERT_LT(h.run_until_done(200), 200);
    EXPECT_EQ(h.ap.visited().size(), 20u);
}

// The first write of a replacement is the barrier after the kept target. A vehicle that reaches its target
// before that write lands takes the old plan's next point: the feeder holds it rather than let it drive
// there.
TEST(FlightplanFeeder, AReplacementWhoseFirstWriteLandsJustAfterTheTargetIsReachedHoldsTheVehicle) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(40, 41.0), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    ASSERT_TRUE(h.ap.in_auto());
    const std::size_t a_done = h.ap.visited().size();
    h.feeder.replace_plan(test::synthetic(20, 42.0), h.now);
    auto write = h.feeder.poll_request(h.now);
    ASSERT_TRUE(write.has_value());
    ASSERT_TRUE(std::holds_alternative<autopilot::WriteMissionItems>(write->op)) << *write;
    // The vehicle reaches the kept target before the write of the slot after it has landed: it now heads
    // for that slot's old content (route A's next waypoint).
    const auto reached = h.ap.step();
    ASSERT_TRUE(reached.has_value());
    h.feeder.on_reached(*reached, h.now);
    h.feeder.on_current(h.ap.current(), h.now);
    h.drain();
    h.feeder.on_request_result(write->id, h.ap.apply(*write), h.now);
    h.drain();
    ASSERT_LT(h.run_until_done(200), 200);
    EXPECT_EQ(h.ap.hold_requests(), 1);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 1u);
    // A up to the kept target, then B from its first waypoint: never A's next one.
    ASSERT_EQ(h.ap.visited().size(), a_done + 1 + 20);
    for (std::uint64_t i = 0; i < 20; ++i) {
        EXPECT_EQ(h.ap.visited()[a_done + 1 + i], test::SyntheticStream::position_of(42.0, i)) << i;
    }
}

/// The three kinds of hold, at plan indices `at`: a timed hold at a waypoint, one until released, and a timed
/// hold without a position (held where the waypoint before it ends).
std::map<std::uint64_t, Waypoint> three_holds(std::array<std::uint64_t, 3> at, double timed_s,
                                              double here_s) {
    Waypoint timed;
    timed.action = WaypointAction::HoldFor;
    timed.hold_seconds = timed_s;
    Waypoint until;
    until.action = WaypointAction::HoldUntilReleased;
    Waypoint here;
    here.action = WaypointAction::HoldFor;
    here.hold_seconds = here_s;
    here.has_position = false;
    return {{at[0], timed}, {at[1], until}, {at[2], here}};
}

TEST(FlightplanFeeder, HoldWaypointsHoldForTheirTimeOrUntilReleased) {
    Harness h;
    // The hold without a position is held where waypoint 29 ends.
    h.feeder.replace_plan(test::synthetic(40, 41.0, three_holds({10, 20, 30}, 30.0, 10.0)), h.now);
    int steps = 0;
    while (h.reached.size() < 11 && steps++ < 100) {
        h.step();
    }
    ASSERT_EQ(h.reached.size(), 11u);
    const TimePoint hold_start = h.now;
    while (h.reached.size() < 12 && steps++ < 200) {
        h.step();
    }
    EXPECT_GE(h.now - hold_start, seconds(30));
    EXPECT_LE(h.now - hold_start, seconds(36));
    while (h.reached.size() < 21 && steps++ < 300) {
        h.step();
    }
    for (int i = 0; i < 100; ++i) {
        h.step();
    }
    EXPECT_EQ(h.reached.size(), 21u);  // held until released
    EXPECT_FALSE(h.ap.in_auto());
    EXPECT_EQ(h.feeder.progress().held, "plan.elements[0]");
    EXPECT_TRUE(h.feeder.progress().held_until_released);
    EXPECT_FALSE(h.feeder.progress().held_at_frontier) << "a hold's barrier is no frontier stop";
    h.feeder.release_hold(h.now);
    EXPECT_EQ(h.feeder.progress().held, "");
    EXPECT_FALSE(h.feeder.progress().held_until_released);
    ASSERT_LT(h.run_until_done(500), 500);
    EXPECT_EQ(h.reached, iota(0, 40));
    EXPECT_EQ(h.count(FeederEvent::Kind::HoldStarted), 3u);
    EXPECT_EQ(h.count(FeederEvent::Kind::HoldEnded), 3u);
    // Positioned items only went to the autopilot (39 of 40).
    EXPECT_EQ(h.ap.visited().size(), 39u);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
    EXPECT_EQ(h.feeder.progress().frontier_stops, 0u) << "the vehicle stood only where the plan holds";
}

// A hold is where the vehicle stops whether the daemon runs or not. A starved feeder (the vehicle drives a
// waypoint a step while it is stalled) never lets it drive past a hold's point before the hold began, nor
// past a hold until released before the release: the hold's point ends the drivable part of the mission (its
// barrier) until the vehicle is held there.
TEST(FlightplanFeeder, AStarvedFeederNeverLetsTheVehicleDrivePastAHold) {
    // Waypoints driven (positions visited) when each hold begins: through 10, 25 and 39.
    const std::vector<std::size_t> driven_at_hold{11, 26, 40};
    for (const bool legacy : {false, true}) {
        for (unsigned seed = 1; seed <= 20; ++seed) {
            const std::string run =
                std::string(legacy ? "legacy" : "current") + " seed " + std::to_string(seed);
            Impairments imp;
            imp.stall = 0.15;
            imp.stall_steps = 8;
            Harness h({}, imp, seed);
            h.ap.legacy = legacy;
            h.feeder.replace_plan(test::synthetic(60, 41.0, three_holds({10, 25, 40}, 5.0, 5.0)), h.now);
            int steps = 0;
            bool released = false;
            std::optional<int> until_started_at;
            while (h.feeder.progress().state != PlanState::Done && steps++ < 3000) {
                h.step();
                const std::size_t begun = h.count(FeederEvent::Kind::HoldStarted);
                const std::size_t limit = begun < driven_at_hold.size() ? driven_at_hold[begun] : 59;
                // A hold begun and ended is behind the vehicle; the next one bounds how far it may have gone.
                ASSERT_LE(h.ap.visited().size(), limit)
                    << run << ", step " << steps << ", holds begun " << begun;
                if (begun == 2 && !released) {
                    ASSERT_LE(h.ap.visited().size(), driven_at_hold[1]) << run << ": held until released";
                    until_started_at = until_started_at.value_or(steps);
                    if (steps - *until_started_at >= 30) {
                        h.feeder.release_hold(h.now);
                        released = true;
                    }
                }
            }
            ASSERT_EQ(h.feeder.progress().state, PlanState::Done) << run;
            EXPECT_TRUE(released) << run;
            EXPECT_EQ(h.reached, iota(0, 60)) << run;
            EXPECT_EQ(h.ap.visited().size(), 59u) << run;
            EXPECT_EQ(h.count(FeederEvent::Kind::HoldStarted), 3u) << run;
            EXPECT_EQ(h.feeder.progress().starvation_holds, 0u) << run;
            EXPECT_GT(h.stalls, 4) << run;
        }
    }
}

// A hold's point is the window's last entry until it is reached, so no later entry's report tells that the
// vehicle passed it: a lost reached report of it is made good by the board heading for its barrier.
TEST(FlightplanFeeder, ALostReachedReportOfAHoldsPointIsMadeGoodByTheBarrierAfterIt) {
    for (const bool legacy : {false, true}) {
        for (unsigned seed = 1; seed <= 20; ++seed) {
            const std::string run =
                std::string(legacy ? "legacy" : "current") + " seed " + std::to_string(seed);
            Impairments imp;
            imp.drop_reached = 0.4;
            imp.current_on_change = true;
            Harness h({}, imp, seed);
            h.ap.legacy = legacy;
            h.feeder.replace_plan(test::synthetic(60, 41.0, three_holds({10, 25, 40}, 5.0, 5.0)), h.now);
            int steps = 0;
            while (h.feeder.progress().state != PlanState::Done && steps++ < 2000) {
                h.step();
                if (h.feeder.progress().held_until_released) {
                    h.feeder.release_hold(h.now);
                }
            }
            ASSERT_EQ(h.feeder.progress().state, PlanState::Done)
                << run << ": " << h.reached.size() << " reached";
            EXPECT_EQ(h.reached, iota(0, 60)) << run;
            EXPECT_EQ(h.count(FeederEvent::Kind::HoldStarted), 3u) << run;
        }
    }
}

TEST(FlightplanFeeder, ShortPlanEndsOnStopItem) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(2), h.now);
    ASSERT_LT(h.run_until_done(50), 50);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    EXPECT_EQ(h.reached, iota(0, 2));
    EXPECT_TRUE(h.ap.parked());
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().state, PlanState::Done);
}

TEST(FlightplanFeeder, ABoardWhoseStopEndsItsMissionHoldsAtTheEndByItselfEvenWithTheFeederStopped) {
    // APM:Rover 2.x has no NAV_LOITER_UNLIM: its Stop is a DO_JUMP past the mission's end, after which it
    // holds where it is. No HOLD from the daemon is needed, so a stalled daemon loses nothing at the end.
    FeederConfig c;
    c.window = 6;
    Harness h(c);
    h.ap.legacy = true;
    h.feeder.replace_plan(test::synthetic(23), h.now);
    while (h.feeder.progress().waypoints_reached < 19) {
        h.step();
    }
    h.impairments().stall = 1.0;  // the daemon stops for good
    h.impairments().stall_steps = 1000;
    for (int i = 0; i < 30; ++i) {
        h.step();
    }
    EXPECT_FALSE(h.ap.in_auto());
    EXPECT_EQ(h.ap.stop_holds(), 1);
    EXPECT_EQ(h.ap.hold_requests(), 0);
    expect_visited(h, 41.0, 0, 23);
    EXPECT_EQ(h.ap.visited().size(), 23u) << "nothing driven after the last waypoint";
}

// The ring's invariant: a feeder that stalls for 1..8 steps at random (a starved daemon; the vehicle drives
// one waypoint a step meanwhile, so a stall of five steps or more runs through the whole window) never lets
// the vehicle drive a slot left from an earlier round. It stops at the frontier and goes on once the writes
// land.
TEST(FlightplanFeeder, AStarvedFeederStopsTheVehicleAtTheFrontierAndNeverLetsItDriveAStaleSlot) {
    for (const bool legacy : {false, true}) {
        for (unsigned seed = 1; seed <= 20; ++seed) {
            Impairments imp;
            imp.stall = 0.08;
            imp.stall_steps = 8;
            Harness h({}, imp, seed);
            h.ap.legacy = legacy;
            h.feeder.replace_plan(test::synthetic(300), h.now);
            ASSERT_LT(h.run_until_done(4000), 4000) << "legacy " << legacy << " seed " << seed;
            EXPECT_EQ(h.reached, iota(0, 300)) << "legacy " << legacy << " seed " << seed;
            expect_visited(h, 41.0, 0, 300);
            EXPECT_EQ(h.ap.visited().size(), 300u) << "legacy " << legacy << " seed " << seed;
            EXPECT_GT(h.stalls, 10);
            EXPECT_GT(h.feeder.progress().frontier_stops, 0u) << "the stalls must have emptied the window";
            EXPECT_GT(h.feeder.progress().frontier_wait, Duration::zero());
            EXPECT_FALSE(h.feeder.progress().held_at_frontier);
            EXPECT_EQ(h.count(FeederEvent::Kind::HeldAtFrontier), h.feeder.progress().frontier_stops);
            EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
            EXPECT_EQ(h.ap.hold_requests(), 0);
            EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
        }
    }
}

TEST(FlightplanFeeder, WhileTheVehicleWaitsAtTheFrontierTheProgressSaysSo) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(50), h.now);
    for (int i = 0; i < 10; ++i) {
        h.step();
    }
    h.impairments().requests_per_step = 0;  // nothing reaches the autopilot any more
    for (int i = 0; i < 8; ++i) {
        h.step();
    }
    const auto p = h.feeder.progress();
    EXPECT_TRUE(p.held_at_frontier);
    EXPECT_EQ(p.frontier_stops, 1u);
    EXPECT_EQ(p.state, PlanState::Running);
    EXPECT_NE(p.interruption.find("waiting"), std::string::npos) << p.interruption;
    EXPECT_TRUE(h.ap.parked());
    EXPECT_TRUE(h.ap.in_auto()) << "parked on the barrier, not held";
    h.impairments().requests_per_step = 2;
    ASSERT_LT(h.run_until_done(200), 200);
    EXPECT_EQ(h.reached, iota(0, 50));
    expect_visited(h, 41.0, 0, 50);
    EXPECT_FALSE(h.feeder.progress().held_at_frontier);
    EXPECT_EQ(h.count(FeederEvent::Kind::HeldAtFrontier), 1u);
}

// A skip's set-current that comes late (here: its first attempt times out) while the vehicle, done with its
// old target, already drove on into the new head: the head reached is counted, and the vehicle is not sent
// back to it.
TEST(FlightplanFeeder, ASkipWhoseSetCurrentComesLateNeverDrivesAWaypointTwice) {
    for (const bool legacy : {false, true}) {
        Impairments imp;
        imp.requests_per_step = 3;
        Harness h({}, imp);
        h.ap.legacy = legacy;
        h.feeder.replace_plan(test::synthetic(100), h.now);
        for (int i = 0; i < 10; ++i) {
            h.step();
        }
        const auto visited_before = h.ap.visited().size();
        ASSERT_TRUE(h.feeder.skip_to(60, h.now));
        h.impairments().fail_next_set_current = true;
        ASSERT_LT(h.run_until_done(500), 500);
        EXPECT_FALSE(h.impairments().fail_next_set_current) << "the scenario needs the late set-current";
        // At most the old target, then 60..99, each once.
        const auto& v = h.ap.visited();
        std::size_t at = visited_before;
        if (v.size() == visited_before + 41) {
            ++at;  // the target it was heading for when the skip came
        }
        ASSERT_EQ(v.size(), at + 40) << "legacy " << legacy;
        expect_visited(h, 41.0, 60, 100, at);
    }
}

// The wrap's three items go in one write, which the board takes item by item: the vehicle can reach the
// wrap's waypoint, holding the new entry, before the write's answer. Told the item is on board (in order with
// the reports), the feeder takes that arrival for the entry, not for the barrier the slot held: no wait at
// the frontier, and the vehicle is never pointed at the slot again.
TEST(FlightplanFeeder, AnArrivalAtTheWrapBeforeItsWriteIsAnsweredIsTheEntryOnceTheBoardHoldsIt) {
    using autopilot::MissionItem;
    WindowFeeder f(FeederConfig{});  // window 5: ring slots 2..5, the wrap 6..8
    TimePoint now{};
    f.replace_plan(test::synthetic(40), now);
    OutrunningBoard b;
    auto& board = b.items;
    auto& target = b.target;
    std::vector<FeederEvent::Kind> kinds;
    int starved = 0;
    const auto drain = [&] {
        while (auto e = f.poll_event()) {
            kinds.push_back(e->kind);
            starved += e->kind == FeederEvent::Kind::WindowStarved ? 1 : 0;
        }
    };
    bool met = false;
    for (int i = 0; i < 400 && !met; ++i) {
        const auto r = b.step(f, now, drain);
        if (!r) {
            continue;
        }
        if (const auto* w = std::get_if<autopilot::WriteMissionItems>(&r->op)) {
            const bool at_the_wrap = w->first_slot == 6 && w->items.size() == 3 && target == 6 &&
                                     board[6].kind == MissionItem::Kind::Stop;
            board[w->first_slot] = w->items[0];
            if (at_the_wrap) {
                // The board took the first item and asked for the next; the vehicle reached it meanwhile and
                // went on through the jump to slot 2, whose barrier stops it. No target report follows (a 2.x
                // board runs that Stop as a jump past its end, reports nothing of use, and holds).
                drain();
                kinds.clear();
                f.on_item_stored(6, w->items[0]);
                f.on_current(6, now);
                f.on_reached(6, now);
                target = 2;
                drain();
                met = true;
            }
            for (std::size_t k = 1; k < w->items.size(); ++k) {
                board[static_cast<std::uint16_t>(w->first_slot + k)] = w->items[k];
            }
        }
        f.on_request_result(r->id, autopilot::RequestResult::Ok, now);
        drain();
        if (!met) {
            b.drive_one(f, now);
            drain();
        }
    }
    ASSERT_TRUE(met) << "the scenario needs the wrap written while the vehicle heads for its barrier";
    // The arrival is the entry's, not a wait at the frontier.
    const auto reached = std::find(kinds.begin(), kinds.end(), FeederEvent::Kind::WaypointReached);
    ASSERT_NE(reached, kinds.end());
    EXPECT_EQ(std::find(kinds.begin(), reached, FeederEvent::Kind::HeldAtFrontier), reached);
    EXPECT_EQ(starved, 0) << "the wrap's first item on board, the rest still landing, is no stale slot";
    // What follows: the writes for slot 2 on, and the vehicle never pointed back at the wrap.
    for (int i = 0; i < 50; ++i) {
        now += milliseconds(100);
        const auto r = f.poll_request(now);
        if (!r) {
            break;
        }
        if (const auto* sc = std::get_if<autopilot::SetMissionCurrent>(&r->op)) {
            EXPECT_NE(sc->slot, 6) << "pointed back at the slot it reached";
        }
        f.on_request_result(r->id, autopilot::RequestResult::Ok, now);
    }
}

// A 2.x board runs a Stop as a jump past its mission's end and never reports reaching one. The daemon,
// stopped for seconds, gave up on the answer to the head's write (it waited in the port); the board had
// stored the entry, and the vehicle reached it and stopped at the next barrier. Its report of the head's slot
// is the entry reached, not an arrival at the barrier the slot held: no wait at the frontier is counted
// there, and the vehicle is never pointed back at the slot it reached (it drove that waypoint twice, in
// place).
TEST(FlightplanFeeder, AReportOfTheHeadsSlotWhoseWriteWasGivenUpOnIsTheEntryOnABoardWhoseStopIsAJump) {
    using autopilot::MissionItem;
    const FeederConfig config{};  // window 5: ring slots 2..5, the wrap 6..8
    WindowFeeder f(config);
    f.set_stop_ends_mission(true);
    TimePoint now{};
    f.replace_plan(test::synthetic(40), now);
    OutrunningBoard b;
    auto& board = b.items;
    auto& target = b.target;
    std::vector<FeederEvent> events;
    const auto drain = [&] {
        while (auto e = f.poll_event()) {
            events.push_back(*e);
        }
    };
    std::optional<std::uint16_t> lost_slot;
    std::size_t reached_before = 0;
    for (int i = 0; i < 400 && !lost_slot; ++i) {
        const auto r = b.step(f, now, drain);
        if (!r) {
            continue;
        }
        if (const auto* w = std::get_if<autopilot::WriteMissionItems>(&r->op)) {
            const bool over_the_target = w->first_slot == target && w->first_slot < 6 &&
                                         w->items.size() == 1 &&
                                         w->items[0].kind == MissionItem::Kind::Waypoint &&
                                         board[target].kind == MissionItem::Kind::Stop;
            board[w->first_slot] = w->items[0];
            if (over_the_target) {
                // The board stores the entry and answers; the daemon is stopped, and when it runs again it
                // gives up on the answer before reading it.
                lost_slot = w->first_slot;
                drain();
                reached_before = static_cast<std::size_t>(std::count_if(
                    events.begin(), events.end(),
                    [](const FeederEvent& e) { return e.kind == FeederEvent::Kind::WaypointReached; }));
                now += config.request_timeout + seconds(1);
                f.handle_timeout(now);
                now += seconds(1);
                f.handle_timeout(now);
                drain();
                // Then it reads what the board said meanwhile: the entry reached, and nothing of use after it
                // (the barrier beyond is a jump past the end; the board holds there).
                f.on_reached(*lost_slot, now);
                target = static_cast<std::uint16_t>(*lost_slot + 1);
                drain();
                continue;
            }
            for (std::size_t k = 1; k < w->items.size(); ++k) {
                board[static_cast<std::uint16_t>(w->first_slot + k)] = w->items[k];
            }
        }
        f.on_request_result(r->id, autopilot::RequestResult::Ok, now);
        drain();
        b.drive_one(f, now);
        drain();
    }
    ASSERT_TRUE(lost_slot)
        << "the scenario needs the head written over its barrier as the vehicle heads there";
    const std::size_t reached_after =
        static_cast<std::size_t>(std::count_if(events.begin(), events.end(), [](const FeederEvent& e) {
            return e.kind == FeederEvent::Kind::WaypointReached;
        }));
    EXPECT_EQ(reached_after, reached_before + 1) << "the entry in the lost write's slot, reached";
    // What follows (every request answered): the vehicle is never pointed back at the slot it reached.
    for (int i = 0; i < 50; ++i) {
        now += milliseconds(100);
        const auto r = f.poll_request(now);
        if (!r) {
            break;
        }
        if (const auto* sc = std::get_if<autopilot::SetMissionCurrent>(&r->op)) {
            EXPECT_NE(sc->slot, *lost_slot) << "pointed back at the slot it reached";
        }
        f.on_request_result(r->id, autopilot::RequestResult::Ok, now);
    }
}

TEST(FlightplanFeeder, ProgressReportsWindowAndResumePoint) {
    Harness h;
    EXPECT_EQ(h.feeder.progress().state, PlanState::None);
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 12; ++i) {
        h.step();
    }
    const auto p = h.feeder.progress();
    EXPECT_EQ(p.state, PlanState::Running);
    EXPECT_EQ(p.plan_name, "synthetic");
    // K-1 entries; between a reached report and the rewrite of its slot the window is one short.
    EXPECT_GE(p.window, 3u);
    EXPECT_LE(p.window, 4u);
    ASSERT_TRUE(p.next_waypoint.has_value());
    EXPECT_EQ(*p.next_waypoint, p.waypoints_reached);
    EXPECT_EQ(p.resume_index, p.next_waypoint);
    EXPECT_EQ(p.element, "plan.elements[0]");
}

TEST(FlightplanFeeder, RequestTimeoutCountsAsFailureAndIsRetried) {
    Harness h;
    h.feeder.replace_plan(test::synthetic(10), h.now);
    auto first = h.feeder.poll_request(h.now);
    ASSERT_TRUE(first.has_value());
    EXPECT_FALSE(h.feeder.poll_request(h.now).has_value());  // one outstanding at a time
    h.now += seconds(6);
    ASSERT_LE(h.feeder.poll_timeout(), h.now);
    // Found a second past its deadline, the daemon was not running: the answer gets a moment to be read.
    h.feeder.handle_timeout(h.now);
    EXPECT_FALSE(h.feeder.poll_request(h.now).has_value());
    h.now = h.feeder.poll_timeout();
    h.feeder.handle_timeout(h.now);
    auto again = h.feeder.poll_request(h.now);
    ASSERT_TRUE(again.has_value());
    EXPECT_NE(again->id, first->id);
    EXPECT_EQ(again->op.index(), first->op.index());
    h.feeder.on_request_result(first->id, autopilot::RequestResult::Ok, h.now);  // stale: ignored
    EXPECT_FALSE(h.feeder.poll_request(h.now).has_value());
    EXPECT_EQ(h.feeder.progress().retries, 1u);
}

}  // namespace
}  // namespace airseg::flightplan

#include "services/flightplan/expander.hpp"
#include "services/flightplan/plan_loader.hpp"

namespace airseg::flightplan {
namespace {

TEST(FlightplanFeeder, ExampleSurveyPlanElementsStartAndFinishInOrder) {
    const auto r = load_plan_file(::airseg::test::source_dir() + "/config/plans/rover-survey.yaml");
    ASSERT_TRUE(r.ok()) << to_string(r.errors);
    std::vector<Waypoint> expected;
    {
        Expander all(r.plan);
        while (auto w = all.next()) {
            expected.push_back(*w);
        }
    }
    test::Harness h;
    h.feeder.replace_plan({std::make_unique<Expander>(r.plan), r.plan->name}, h.now);
    std::vector<std::string> started;
    std::string open_element;
    std::size_t seen = 0;
    for (int i = 0; i < 2000 && h.feeder.progress().state != PlanState::Done; ++i) {
        h.step();
        for (; seen < h.events.size(); ++seen) {
            const auto& e = h.events[seen];
            if (e.kind == FeederEvent::Kind::ElementStarted) {
                EXPECT_EQ(open_element, "") << "started " << e.element_path << " inside " << open_element;
                open_element = e.element_path;
                started.push_back(e.element_path);
            } else if (e.kind == FeederEvent::Kind::ElementFinished) {
                EXPECT_EQ(e.element_path, open_element);
                open_element.clear();
            } else if (e.kind == FeederEvent::Kind::HoldStarted && e.element_path == "plan.elements[7]") {
                h.feeder.release_hold(h.now);  // the operator check
            }
        }
    }
    ASSERT_EQ(h.feeder.progress().state, PlanState::Done);
    const std::vector<std::string> want = {"plan.elements[0]",
                                           "plan.elements[1]",
                                           "plan.elements[3]",
                                           "plan.elements[4]",
                                           "plan.elements[5]",
                                           "plan.elements[6].repeat.elements[0]",
                                           "plan.elements[6].repeat.elements[1]",
                                           "plan.elements[6].repeat.elements[0]",
                                           "plan.elements[6].repeat.elements[1]",
                                           "plan.elements[6].repeat.elements[0]",
                                           "plan.elements[6].repeat.elements[1]",
                                           "plan.elements[7]",
                                           "plan.elements[8]"};
    EXPECT_EQ(started, want);
    std::vector<std::uint64_t> all(expected.size());
    for (std::size_t i = 0; i < all.size(); ++i) {
        all[i] = i;
    }
    EXPECT_EQ(h.reached, all);
    // Only positioned waypoints go to the autopilot, in plan order.
    std::vector<LatLon> positioned;
    for (const auto& w : expected) {
        if (w.has_position) {
            positioned.push_back(w.position);
        }
    }
    EXPECT_EQ(h.ap.visited(), positioned);
    EXPECT_EQ(h.count(FeederEvent::Kind::HoldStarted), 2u);
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
    EXPECT_EQ(h.feeder.progress().starvation_holds, 0u);
}

}  // namespace
}  // namespace airseg::flightplan

namespace airseg::flightplan {
namespace {

TEST(FlightplanFeeder, ClearPlanHoldsTheVehicleAndStopsFeeding) {
    test::Harness h;
    h.feeder.replace_plan(test::synthetic(100), h.now);
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    h.feeder.clear_plan();
    EXPECT_EQ(h.feeder.progress().state, PlanState::None);
    const int writes = h.ap.writes();
    for (int i = 0; i < 20; ++i) {
        h.step();
    }
    EXPECT_FALSE(h.ap.in_auto());
    EXPECT_EQ(h.ap.writes(), writes);
    EXPECT_LE(h.ap.visited().size(), 21u);
}

TEST(FlightplanFeeder, NewPlanAfterDoneStartsFromTheParkedVehicle) {
    test::Harness h;
    h.feeder.replace_plan(test::synthetic(12, 41.0), h.now);
    ASSERT_LT(h.run_until_done(100), 100);
    for (int i = 0; i < 3; ++i) {
        h.step();
    }
    ASSERT_TRUE(h.ap.parked());
    h.feeder.replace_plan(test::synthetic(30, 42.0), h.now);
    ASSERT_LT(h.run_until_done(200), 200);
    ASSERT_EQ(h.ap.visited().size(), 42u);
    for (std::uint64_t i = 0; i < 30; ++i) {
        EXPECT_EQ(h.ap.visited()[12 + i], test::SyntheticStream::position_of(42.0, i));
    }
    EXPECT_EQ(h.ap.end_of_mission_holds(), 0);
}

}  // namespace
}  // namespace airseg::flightplan

namespace airseg::flightplan {
namespace {

// Random operator actions and autopilot trouble on top of a lossy link, several seeds. Invariants: the
// autopilot never completes its mission (never falls into HOLD by itself), the vehicle never drives back
// into an older plan or to an earlier waypoint of the current one (so never to a stale slot), reached
// indices are strictly increasing per plan, and once the trouble stops every plan finishes.
TEST(FlightplanFeeder, ChaosKeepsTheInvariants) {
    for (unsigned seed = 1; seed <= 12; ++seed) {
        test::Impairments imp;
        imp.duplicate_reached = 0.1;
        imp.delay_reached = 0.1;
        imp.drop_reached = 0.05;
        imp.fail_request = 0.05;
        imp.requests_per_step = 2;
        imp.stall = 0.03;
        imp.stall_steps = 8;
        test::Harness h({}, imp, seed);
        h.ap.legacy = seed % 2 == 0;
        std::mt19937 rng(seed * 7919u);
        int generation = 0;
        auto base_lat = [](int g) { return 10.0 + g; };
        h.feeder.replace_plan(test::synthetic(400, base_lat(0)), h.now);
        for (int step = 0; step < 3000; ++step) {
            // Nothing reaches a stalled daemon: the operator's commands and the autopilot's reboot wait.
            const unsigned dice = h.stalled() ? 1000u : rng() % 1000;
            if (dice < 3) {
                h.feeder.replace_plan(test::synthetic(300 + rng() % 300, base_lat(++generation)), h.now);
            } else if (dice < 6) {
                // Forward skips only: a backward skip legitimately revisits waypoints.
                if (auto next = h.feeder.progress().next_waypoint) {
                    h.feeder.skip_to(*next + 1 + rng() % 50, h.now);
                }
            } else if (dice < 9) {
                h.ap.reboot();
                h.feeder.on_autopilot_rebooted(h.now);
            } else if (dice < 15) {
                h.feeder.pause();
            } else if (dice < 40) {
                h.feeder.resume();
            }
            h.step();
        }
        h.feeder.resume();
        h.impairments() = test::Impairments{};
        ASSERT_LT(h.run_until_done(3000), 3000) << "seed " << seed;
        EXPECT_EQ(h.ap.end_of_mission_holds(), 0) << "seed " << seed;
        EXPECT_GE(generation, 2) << "seed " << seed;  // the scenario did replace plans
        EXPECT_GT(h.feeder.progress().retries, 0u) << "seed " << seed;
        // A replacement whose first write lands after the vehicle reached its kept target holds it once (see
        // AReplacementWhoseFirstWriteLandsJustAfterTheTargetIsReachedHoldsTheVehicle); nothing else does.
        EXPECT_LE(h.feeder.progress().starvation_holds, static_cast<std::uint64_t>(generation))
            << "seed " << seed;
        // Visited positions: generation = round(lat) - 10, index from the latitude offset.
        int last_gen = -1;
        long last_index = -1;
        for (const auto& p : h.ap.visited()) {
            const int g = static_cast<int>(std::floor(p.lat)) - 10;
            const long index = std::lround((p.lat - std::floor(p.lat)) / 1e-4);
            ASSERT_EQ(p, test::SyntheticStream::position_of(base_lat(g), static_cast<std::uint64_t>(index)));
            ASSERT_GE(g, last_gen) << "seed " << seed << ": drove back into an older plan";
            if (g == last_gen) {
                ASSERT_GT(index, last_index) << "seed " << seed << ": drove back to an earlier waypoint";
            }
            last_gen = g;
            last_index = index;
        }
        std::map<std::uint32_t, std::uint64_t> last_reached;
        for (const auto& e : h.events) {
            if (e.kind != FeederEvent::Kind::WaypointReached) {
                continue;
            }
            auto it = last_reached.find(e.generation);
            if (it != last_reached.end()) {
                ASSERT_GT(e.plan_index, it->second) << "seed " << seed;
            }
            last_reached[e.generation] = e.plan_index;
        }
    }
}

}  // namespace
}  // namespace airseg::flightplan

// ModeControl in simulated time: every request ends exactly once (Ok, Refused, Timeout or Cancelled).
#include "services/autopilot/ardupilot/mode_control.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/ardupilot/rover_modes.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

const TimePoint kAsked = TimePoint{} + std::chrono::hours(1);
constexpr auto kHold = static_cast<std::uint32_t>(RoverMode::Hold);
constexpr auto kAuto = static_cast<std::uint32_t>(RoverMode::Auto);
constexpr auto kManual = static_cast<std::uint32_t>(RoverMode::Manual);

TEST(ModeControl, RetriedThenTimedOut) {
    ModeControl m(milliseconds(1500), 3);
    EXPECT_FALSE(m.start(7, VehicleState::Parking, kHold, kAsked));
    EXPECT_TRUE(m.pending());
    EXPECT_EQ(m.poll_send(), kHold);
    EXPECT_FALSE(m.poll_send());

    EXPECT_FALSE(m.handle_timeout(kAsked + milliseconds(1499)));
    EXPECT_FALSE(m.poll_send());

    std::vector<TimePoint> sends;
    std::optional<ModeOutcome> outcome;
    while (!outcome) {
        const TimePoint now = m.poll_timeout();
        ASSERT_NE(now, kNever);
        outcome = m.handle_timeout(now);
        if (m.poll_send()) {
            sends.push_back(now);
        }
    }
    ASSERT_EQ(sends.size(), 3u);
    for (std::size_t i = 0; i < sends.size(); ++i) {
        EXPECT_EQ(sends[i], kAsked + milliseconds(1500) * (i + 1));
    }
    EXPECT_EQ(outcome->id, 7u);
    EXPECT_EQ(outcome->target, VehicleState::Parking);
    EXPECT_EQ(outcome->result, RequestResult::Timeout);
    EXPECT_EQ(outcome->detail, "no heartbeat in HOLD after 4 attempts");
    EXPECT_FALSE(m.pending());
    EXPECT_EQ(m.poll_timeout(), kNever);
    EXPECT_FALSE(m.handle_timeout(kAsked + seconds(60)));
}

TEST(ModeControl, NoRetriesMeansOneAttempt) {
    ModeControl m(seconds(1), 0);
    EXPECT_FALSE(m.start(1, VehicleState::Parking, kHold, kAsked));
    EXPECT_EQ(m.poll_send(), kHold);
    const auto o = m.handle_timeout(kAsked + seconds(1));
    ASSERT_TRUE(o);
    EXPECT_EQ(o->result, RequestResult::Timeout);
    EXPECT_FALSE(m.poll_send());
}

TEST(ModeControl, ConfirmedByTheHeartbeatsMode) {
    ModeControl m(milliseconds(1500), 3);
    EXPECT_FALSE(m.start(3, VehicleState::WaypointNavigation, kAuto, kAsked));
    (void)m.poll_send();
    EXPECT_FALSE(m.on_heartbeat(kHold));  // not yet there
    EXPECT_TRUE(m.pending());
    EXPECT_FALSE(m.handle_timeout(kAsked + milliseconds(1500)));  // a retry
    EXPECT_EQ(m.poll_send(), kAuto);
    const auto o = m.on_heartbeat(kAuto);
    ASSERT_TRUE(o);
    EXPECT_EQ(o->id, 3u);
    EXPECT_EQ(o->target, VehicleState::WaypointNavigation);
    EXPECT_EQ(o->mode, kAuto);
    EXPECT_EQ(o->result, RequestResult::Ok);
    // Exactly one outcome.
    EXPECT_FALSE(m.pending());
    EXPECT_FALSE(m.on_heartbeat(kAuto));
    EXPECT_FALSE(m.on_ack(4));
    EXPECT_FALSE(m.cancel("late"));
    EXPECT_FALSE(m.handle_timeout(kAsked + seconds(60)));
}

TEST(ModeControl, RefusedByTheAck) {
    ModeControl m(milliseconds(1500), 3);
    EXPECT_FALSE(m.start(4, VehicleState::WaypointNavigation, kAuto, kAsked));
    EXPECT_FALSE(m.on_ack(0));  // ACCEPTED: the heartbeat confirms
    EXPECT_FALSE(m.on_ack(5));  // IN_PROGRESS
    EXPECT_TRUE(m.pending());
    const auto o = m.on_ack(4);
    ASSERT_TRUE(o);
    EXPECT_EQ(o->id, 4u);
    EXPECT_EQ(o->result, RequestResult::Refused);
    EXPECT_EQ(o->detail, "autopilot answered MAV_RESULT_FAILED to mode AUTO");
    EXPECT_FALSE(m.pending());
    EXPECT_FALSE(m.poll_send());  // nothing left to send for it
}

TEST(ModeControl, ASecondRequestEndsTheFirstCancelled) {
    // The Driver cancels the running request before it starts the next.
    ModeControl m(milliseconds(1500), 3);
    EXPECT_FALSE(m.start(1, VehicleState::WaypointNavigation, kAuto, kAsked));
    (void)m.poll_send();
    const auto first = m.cancel("superseded by a request for MANUAL");
    ASSERT_TRUE(first);
    EXPECT_EQ(first->id, 1u);
    EXPECT_EQ(first->result, RequestResult::Cancelled);
    EXPECT_EQ(first->detail, "superseded by a request for MANUAL");
    EXPECT_FALSE(m.cancel("again"));

    EXPECT_FALSE(m.start(2, VehicleState::Manual, kManual, kAsked + milliseconds(200)));
    EXPECT_EQ(m.poll_send(), kManual);
    EXPECT_EQ(m.poll_timeout(), kAsked + milliseconds(1700));
    EXPECT_FALSE(m.on_heartbeat(kAuto));  // the first request's mode confirms nothing now
    const auto second = m.on_heartbeat(kManual);
    ASSERT_TRUE(second);
    EXPECT_EQ(second->id, 2u);
    EXPECT_EQ(second->result, RequestResult::Ok);
}

TEST(ModeControl, StartWhileOneIsRunningEndsItCancelled) {
    ModeControl m(milliseconds(1500), 3);
    EXPECT_FALSE(m.start(1, VehicleState::WaypointNavigation, kAuto, kAsked));
    (void)m.poll_send();
    const auto first = m.start(2, VehicleState::Manual, kManual, kAsked + milliseconds(200));
    ASSERT_TRUE(first);
    EXPECT_EQ(first->id, 1u);
    EXPECT_EQ(first->target, VehicleState::WaypointNavigation);
    EXPECT_EQ(first->mode, kAuto);
    EXPECT_EQ(first->result, RequestResult::Cancelled);
    EXPECT_EQ(first->detail, "superseded by request 2");

    EXPECT_EQ(m.poll_send(), kManual);
    EXPECT_EQ(m.poll_timeout(), kAsked + milliseconds(1700));
    EXPECT_FALSE(m.on_heartbeat(kAuto));
    const auto second = m.on_heartbeat(kManual);
    ASSERT_TRUE(second);
    EXPECT_EQ(second->id, 2u);
    EXPECT_EQ(second->result, RequestResult::Ok);
    EXPECT_FALSE(m.cancel("again"));  // the first ended once, at start()
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

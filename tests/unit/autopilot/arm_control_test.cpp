// ArmControl in simulated time: the arm command, its retries, the heartbeat's confirmation, and a refusal
// explained by the texts ArduPilot sends around its COMMAND_ACK.
#include "services/autopilot/ardupilot/arm_control.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {
namespace {

const TimePoint kT0 = TimePoint{} + std::chrono::hours(1);

TEST(ArmControl, AcceptedThenConfirmedByTheHeartbeat) {
    ArmControl a(milliseconds(1500), 3);
    EXPECT_FALSE(a.start(7, kT0));
    EXPECT_TRUE(a.poll_send());
    EXPECT_FALSE(a.poll_send()) << "once per attempt";
    EXPECT_FALSE(a.on_heartbeat(false)) << "a heartbeat from before the command";
    a.on_ack(mavlink::kResultAccepted, kT0 + milliseconds(20));
    const auto o = a.on_heartbeat(true);
    ASSERT_TRUE(o);
    EXPECT_EQ(o->id, 7u);
    EXPECT_EQ(o->result, RequestResult::Ok);
    EXPECT_FALSE(a.pending());
}

TEST(ArmControl, AcceptedButNeverShownArmedTimesOut) {
    ArmControl a(milliseconds(1500), 3);
    (void)a.start(1, kT0);
    a.on_ack(mavlink::kResultAccepted, kT0);
    EXPECT_FALSE(a.handle_timeout(kT0 + milliseconds(1499)));
    const auto o = a.handle_timeout(kT0 + milliseconds(1500));
    ASSERT_TRUE(o);
    EXPECT_EQ(o->result, RequestResult::Timeout);
}

TEST(ArmControl, UnansweredCommandsAreSentAgainThenTimeOut) {
    ArmControl a(seconds(1), 2);
    (void)a.start(1, kT0);
    EXPECT_TRUE(a.poll_send());
    EXPECT_FALSE(a.handle_timeout(kT0 + seconds(1)));
    EXPECT_TRUE(a.poll_send());
    EXPECT_EQ(a.attempt(), 1u);
    EXPECT_FALSE(a.handle_timeout(kT0 + seconds(2)));
    EXPECT_TRUE(a.poll_send());
    const auto o = a.handle_timeout(kT0 + seconds(3));
    ASSERT_TRUE(o);
    EXPECT_EQ(o->result, RequestResult::Timeout);
    EXPECT_NE(o->detail.find("3 attempts"), std::string::npos) << o->detail;
}

// ArduPilot queues its texts and sends the COMMAND_ACK at once: the reasons may come after it.
TEST(ArmControl, ARefusalWaitsForItsReasonsAfterTheAcknowledgement) {
    ArmControl a(milliseconds(1500), 3, milliseconds(500));
    a.on_text("Arm: Mode not armable", kT0 - seconds(1));  // an earlier attempt's: not this one's reason
    (void)a.start(3, kT0);
    a.on_ack(mavlink::kResultFailed, kT0 + milliseconds(10));
    EXPECT_FALSE(a.on_heartbeat(false));
    a.on_text("Arm: Need Position Estimate", kT0 + milliseconds(30));
    a.on_text("Throttle disarmed", kT0 + milliseconds(31));
    a.on_text("Arm: Compass not calibrated", kT0 + milliseconds(40));
    EXPECT_FALSE(a.handle_timeout(kT0 + milliseconds(400)));
    const auto o = a.handle_timeout(kT0 + milliseconds(510));
    ASSERT_TRUE(o);
    EXPECT_EQ(o->id, 3u);
    EXPECT_EQ(o->result, RequestResult::Refused);
    EXPECT_EQ(
        o->detail,
        "the autopilot refused to arm (MAV_RESULT_FAILED): Arm: Need Position Estimate; Arm: Compass not "
        "calibrated");
    EXPECT_EQ(a.refusals(), 1u);
}

TEST(ArmControl, WithoutAnArmTextTheLastPreArmTextSaysWhy) {
    ArmControl a(milliseconds(1500), 3, milliseconds(500));
    a.on_text("PreArm: Hardware safety switch", kT0);
    a.on_text("PreArm: \x01\xff odd", kT0 + seconds(1));  // printable ASCII only reaches status
    (void)a.start(1, kT0 + seconds(10));
    a.on_ack(mavlink::kResultDenied, kT0 + seconds(10));
    const auto o = a.handle_timeout(kT0 + seconds(11));
    ASSERT_TRUE(o);
    EXPECT_EQ(o->result, RequestResult::Refused);
    EXPECT_EQ(a.last_refusal(), "PreArm: ?? odd");
    EXPECT_NE(o->detail.find("MAV_RESULT_DENIED"), std::string::npos);

    ArmControl late(milliseconds(1500), 3, milliseconds(500));
    late.on_text("PreArm: Hardware safety switch", kT0);
    (void)late.start(1, kT0 + seconds(90));  // a PreArm text a minute and a half old says nothing now
    late.on_ack(mavlink::kResultFailed, kT0 + seconds(90));
    ASSERT_TRUE(late.handle_timeout(kT0 + seconds(91)));
    EXPECT_EQ(late.last_refusal(), "it gave no reason");
}

TEST(ArmControl, ANewStartOrACancelEndsTheRunningOneCancelled) {
    ArmControl a(milliseconds(1500), 3);
    (void)a.start(1, kT0);
    const auto superseded = a.start(2, kT0);
    ASSERT_TRUE(superseded);
    EXPECT_EQ(superseded->id, 1u);
    EXPECT_EQ(superseded->result, RequestResult::Cancelled);
    const auto cancelled = a.cancel("link lost");
    ASSERT_TRUE(cancelled);
    EXPECT_EQ(cancelled->id, 2u);
    EXPECT_EQ(cancelled->detail, "link lost");
    EXPECT_FALSE(a.cancel("again"));
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

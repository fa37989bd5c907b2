#include "services/autopilot/gcs_gate.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/autopilot/gcs_gate_rig.hpp"

namespace airseg::autopilot {
namespace {

namespace mav = airseg::mavlink;

using gate_test::parse;
using gate_test::Rig;

TEST(GcsGate, AMissionUploadIsAnsweredDeniedWithTheReasonAndNeverWritten) {
    Rig rig;
    mav::MissionCount count;
    count.target_system = 1;
    count.target_component = 1;
    count.count = 5;
    const auto out = rig.gate.from_ground(rig.gcs.encode(count));
    EXPECT_TRUE(out.to_autopilot.empty());
    ASSERT_EQ(out.to_ground.size(), 1 + mission_refusal_texts().size());
    // The acknowledgement comes from the autopilot's identity, to the ground station that asked.
    EXPECT_EQ(out.to_ground[0].id, mav::MissionAck::kId);
    EXPECT_EQ(out.to_ground[0].delivery, ForwardedFrame::Delivery::Reliable);
    const auto frames = parse(out.to_ground[0].bytes);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].sysid, 1);
    EXPECT_EQ(frames[0].compid, 1);
    const auto ack = mav::decode_payload<mav::MissionAck>(frames[0].payload_view());
    EXPECT_EQ(ack.target_system, 254);
    EXPECT_EQ(ack.target_component, 190);
    EXPECT_EQ(ack.type, mav::kMissionDenied);
    EXPECT_EQ(ack.mission_type, mav::kMissionTypeMission);
    std::string said;
    for (std::size_t i = 1; i < out.to_ground.size(); ++i) {
        const auto text = parse(out.to_ground[i].bytes);
        ASSERT_EQ(text.size(), 1u);
        ASSERT_EQ(text[0].msgid, mav::Statustext::kId);
        said += std::string(mav::text_of(mav::decode_payload<mav::Statustext>(text[0].payload_view()).text));
        said += '\n';
    }
    EXPECT_NE(said.find("refused"), std::string::npos) << said;
    EXPECT_NE(said.find("airsegctl plan load"), std::string::npos) << said;
    EXPECT_EQ(rig.gate.stats().missions_refused, 1u);
    EXPECT_EQ(rig.gate.stats().passed, 0u);
}

TEST(GcsGate, EveryMissionWriteIsRefused) {
    Rig rig;
    mav::MissionItemInt item;
    item.target_system = 1;
    mav::MissionItem legacy;
    legacy.target_system = 1;
    mav::MissionClearAll clear;
    clear.target_system = 0;  // broadcast: the autopilot would take it
    mav::MissionSetCurrent current;
    current.target_system = 1;
    mav::MissionWritePartialList partial;
    partial.target_system = 1;
    std::vector<std::uint8_t> all;
    for (const auto& f : {rig.gcs.encode(item), rig.gcs.encode(legacy), rig.gcs.encode(clear),
                          rig.gcs.encode(current), rig.gcs.encode(partial)}) {
        all.insert(all.end(), f.begin(), f.end());
    }
    const auto out = rig.gate.from_ground(all);
    EXPECT_TRUE(out.to_autopilot.empty());
    EXPECT_EQ(rig.gate.stats().missions_refused, 5u);
}

TEST(GcsGate, TheSetCurrentCommandIsRefusedOtherCommandsPass) {
    Rig rig;
    mav::CommandLong set_current;
    set_current.target_system = 1;
    set_current.command = mav::kCmdDoSetMissionCurrent;
    set_current.param1 = 3;
    const auto out = rig.gate.from_ground(rig.gcs.encode(set_current));
    EXPECT_TRUE(out.to_autopilot.empty());
    ASSERT_FALSE(out.to_ground.empty());
    const auto frames = parse(out.to_ground[0].bytes);
    ASSERT_EQ(frames.size(), 1u);
    ASSERT_EQ(frames[0].msgid, mav::CommandAck::kId);
    const auto ack = mav::decode_payload<mav::CommandAck>(frames[0].payload_view());
    EXPECT_EQ(ack.command, mav::kCmdDoSetMissionCurrent);
    EXPECT_EQ(ack.result, mav::kResultDenied);
    EXPECT_EQ(ack.target_system, 254);

    mav::CommandLong arm;
    arm.target_system = 1;
    arm.command = 400;  // MAV_CMD_COMPONENT_ARM_DISARM
    EXPECT_EQ(rig.gate.from_ground(rig.gcs.encode(arm)).to_autopilot.size(), 1u);
    EXPECT_EQ(rig.gate.stats().missions_refused, 1u);
}

TEST(GcsGate, ReadsCommandsFencesAndOtherSystemsPassUnchanged) {
    Rig rig;
    mav::MissionRequestList list;  // a mission download
    list.target_system = 1;
    mav::ParamRequestList params;
    params.target_system = 1;
    mav::MissionCount fence;  // fences are not the flight plan's
    fence.target_system = 1;
    fence.mission_type = 1;
    mav::MissionCount other;  // another vehicle's mission
    other.target_system = 2;
    std::vector<std::vector<std::uint8_t>> sent{rig.gcs.encode(list), rig.gcs.encode(params),
                                                rig.gcs.encode(fence), rig.gcs.encode(other)};
    std::vector<std::uint8_t> all;
    for (const auto& f : sent) {
        all.insert(all.end(), f.begin(), f.end());
    }
    const auto out = rig.gate.from_ground(all);
    EXPECT_TRUE(out.to_ground.empty());
    EXPECT_EQ(out.to_autopilot, sent);
    EXPECT_EQ(rig.gate.stats().passed, 4u);
}

TEST(GcsGate, OnlyValidFramesOfKnownMessagesPass) {
    Rig rig;
    mav::Heartbeat hb;
    auto frame = rig.gcs.encode(hb);
    auto damaged = frame;
    damaged[damaged.size() - 1] ^= 0x55;
    const auto out = rig.gate.from_ground(damaged);
    EXPECT_TRUE(out.to_autopilot.empty());
    EXPECT_GE(rig.gate.stats().invalid, 1u);
    const std::vector<std::uint8_t> noise{1, 2, 3, 4};
    EXPECT_TRUE(rig.gate.from_ground(noise).to_autopilot.empty());
    EXPECT_EQ(rig.gate.from_ground(frame).to_autopilot.size(), 1u);
}

TEST(GcsFrames, AnswersTravelReliablyTelemetryFreshest) {
    using D = ForwardedFrame::Delivery;
    EXPECT_EQ(delivery_of(mav::ParamValue::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::CommandAck::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::Statustext::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::MissionItemInt::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::MissionCount::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::MissionAck::kId), D::Reliable);
    EXPECT_EQ(delivery_of(mav::Attitude::kId), D::Freshest);
    EXPECT_EQ(delivery_of(mav::Heartbeat::kId), D::Freshest);
    EXPECT_EQ(delivery_of(mav::MissionCurrent::kId), D::Freshest);

    mav::Encoder v1(1, 1, mav::Version::V1), v2(1, 1);
    mav::Attitude att;
    EXPECT_EQ(forwarded(v1.encode(att)).id, mav::Attitude::kId);
    mav::Statustext text;
    const auto f = forwarded(v2.encode(text));
    EXPECT_EQ(f.id, mav::Statustext::kId);
    EXPECT_EQ(f.delivery, D::Reliable);
}

TEST(GcsGate, WithAReceiverAnUploadIsReceivedAndOtherMissionWritesStayRefused) {
    Rig rig;
    MissionReceiver uploads{1, 1};
    rig.gate.receive_uploads(uploads);
    mav::MissionCount count;
    count.target_system = 1;
    count.count = 2;
    auto out = rig.gate.from_ground(rig.gcs.encode(count), TimePoint{} + seconds(5));
    EXPECT_TRUE(out.to_autopilot.empty());
    EXPECT_TRUE(out.to_ground.empty());  // the receiver answers
    const auto asked = uploads.take_output();
    ASSERT_EQ(asked.size(), 1u);
    EXPECT_EQ(asked[0].id, mav::MissionRequestInt::kId);
    EXPECT_EQ(rig.gate.stats().upload_frames, 1u);
    EXPECT_EQ(rig.gate.stats().missions_refused, 0u);
    mav::MissionClearAll clear;
    clear.target_system = 1;
    out = rig.gate.from_ground(rig.gcs.encode(clear));
    EXPECT_TRUE(out.to_autopilot.empty());
    EXPECT_EQ(out.to_ground[0].id, mav::MissionAck::kId);
    EXPECT_EQ(rig.gate.stats().missions_refused, 1u);
}

}  // namespace
}  // namespace airseg::autopilot

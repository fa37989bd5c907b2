#include "ground/mavlink_router.hpp"

#include <gtest/gtest.h>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/autopilot/mavlink/target.hpp"

namespace airseg::ground {
namespace {

namespace mav = airseg::mavlink;

/// The frame as a receiver's parser delivers it (MAVLink 2 payload zero-extended).
template <class M>
mav::Frame parsed(const M& m, std::uint8_t sysid = 1, std::uint8_t compid = 1) {
    mav::Encoder encoder(sysid, compid);
    mav::Parser parser;
    mav::Frame out;
    parser.push(encoder.encode(m), [&](const mav::Frame& f) { out = f; });
    return out;
}

TEST(MavlinkTarget, ReadsTheTargetFieldsAtTheirOffsets) {
    mav::CommandAck ack;
    ack.target_system = 255;
    ack.target_component = 190;
    const auto t = frame_target(parsed(ack));
    ASSERT_TRUE(t);
    EXPECT_EQ(t->system, 255);
    EXPECT_EQ(t->component, 190);

    mav::MissionCount count;
    count.count = 3;
    count.target_system = 200;
    count.target_component = 1;
    const auto c = frame_target(parsed(count));
    ASSERT_TRUE(c);
    EXPECT_EQ(c->system, 200);
    EXPECT_EQ(c->component, 1);
}

TEST(MavlinkTarget, ATruncatedTargetByteIsZeroAndAMessageWithoutOneIsABroadcast) {
    // MISSION_REQUEST_INT: seq (u16), target_system, target_component, mission_type; with the targets and
    // the type 0 the encoder cuts the payload after seq, so the targets were never on the wire.
    mav::MissionRequestInt request;
    request.seq = 7;
    const auto frame = parsed(request);
    EXPECT_LT(frame.wire_length, 3);
    const auto t = frame_target(frame);
    ASSERT_TRUE(t);
    EXPECT_EQ(t->system, 0);
    EXPECT_EQ(t->component, 0);

    mav::ParamValue value;
    value.param_count = 1;
    EXPECT_FALSE(frame_target(parsed(value)));
    EXPECT_FALSE(target_offsets(0xFFFFFF).system);  // unknown message: broadcast
}

// The vehicle reads a frame's addressee from its bytes as they came from the autopilot (to keep what is
// addressed to airsegd off the radio): the same answer as from the parsed frame.
TEST(MavlinkTarget, AWholeFramesBytesGiveTheAddresseeOfItsParsedForm) {
    mav::Encoder encoder(1, 1);
    mav::CommandAck ack;
    ack.target_system = 255;
    ack.target_component = 191;
    const auto a = mav::frame_target(std::span<const std::uint8_t>(encoder.encode(ack)));
    ASSERT_TRUE(a);
    EXPECT_EQ(a->system, 255);
    EXPECT_EQ(a->component, 191);

    mav::MissionRequestInt request;  // the targets 0: cut from the wire, read as 0
    request.seq = 7;
    const auto r = mav::frame_target(std::span<const std::uint8_t>(encoder.encode(request)));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->system, 0);
    EXPECT_EQ(r->component, 0);

    // MAVLink 1 MISSION_REQUEST (40): seq u16, target_system, target_component (the checksum is not read).
    const std::vector<std::uint8_t> v1{0xFE, 4, 0, 1, 1, 40, 7, 0, 9, 8, 0, 0};
    const auto one = mav::frame_target(std::span<const std::uint8_t>(v1));
    ASSERT_TRUE(one);
    EXPECT_EQ(one->system, 9);
    EXPECT_EQ(one->component, 8);

    mav::ParamValue value;
    EXPECT_FALSE(mav::frame_target(std::span<const std::uint8_t>(encoder.encode(value))));
    const std::vector<std::uint8_t> header_cut_short{0xFD, 9, 0};  // three bytes of a 10-byte header
    EXPECT_FALSE(mav::frame_target(std::span<const std::uint8_t>(header_cut_short)));
}

// A message airseg does not type (LOG_REQUEST_LIST: start, end as uint16_t, then the targets) is still
// addressed: the offsets come from the whole dialect.
TEST(MavlinkTarget, AMessageOfTheDialectThatIsNotTypedHasItsAddressee) {
    ASSERT_EQ(mav::find_message(117), nullptr) << "LOG_REQUEST_LIST became typed: pick another message";
    const auto offsets = target_offsets(117);
    ASSERT_TRUE(offsets.system);
    ASSERT_TRUE(offsets.component);
    EXPECT_EQ(*offsets.system, 4);
    EXPECT_EQ(*offsets.component, 5);
}

TEST(MavlinkRouter, AFrameGoesOnlyWhereItsAddresseeWasHeard) {
    MavlinkRouter router;
    const std::vector<StationId> stations{1, 2, 3};
    router.heard(1, 255, 190);  // QGroundControl
    router.heard(2, 255, 200);  // a second station, another component
    // Station 3 has sent nothing yet.

    EXPECT_EQ(router.destinations(FrameTarget{255, 190}, stations), (std::vector<StationId>{1}));
    EXPECT_EQ(router.destinations(FrameTarget{255, 200}, stations), (std::vector<StationId>{2}));
    EXPECT_EQ(router.destinations(FrameTarget{255, 0}, stations), (std::vector<StationId>{1, 2}));
    EXPECT_EQ(router.destinations(FrameTarget{0, 0}, stations), stations);
    EXPECT_EQ(router.destinations(std::nullopt, stations), stations);
    EXPECT_TRUE(router.destinations(FrameTarget{42, 1}, stations).empty());
    EXPECT_EQ(router.stats().routed, 3u);
    EXPECT_EQ(router.stats().broadcast, 2u);
    EXPECT_EQ(router.stats().unrouted, 1u);
}

TEST(MavlinkRouter, FramesAddressedToAirsegdReachNoStation) {
    MavlinkRouter router;
    const std::vector<StationId> stations{1};
    router.heard(1, 255, 191);  // even one that sends as airsegd's own address
    EXPECT_TRUE(router.destinations(FrameTarget{255, 191}, stations).empty());
    EXPECT_EQ(router.stats().to_airsegd, 1u);
    EXPECT_FALSE(router.delivers(1, FrameTarget{255, 191}));
}

TEST(MavlinkRouter, AForgottenStationGetsOnlyBroadcastsAndSendersAreBounded) {
    MavlinkRouter router;
    router.heard(1, 255, 190);
    router.forget(1);
    EXPECT_FALSE(router.delivers(1, FrameTarget{255, 190}));
    EXPECT_TRUE(router.delivers(1, std::nullopt));
    for (int c = 0; c < 40; ++c) {
        router.heard(2, 10, static_cast<std::uint8_t>(c));
    }
    EXPECT_EQ(router.stats().senders_refused, 40u - MavlinkRouter::kMaxSendersPerStation);
    EXPECT_TRUE(router.delivers(2, FrameTarget{10, 3}));
    EXPECT_FALSE(router.delivers(2, FrameTarget{10, 39}));
}

}  // namespace
}  // namespace airseg::ground

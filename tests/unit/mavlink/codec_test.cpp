// Typed messages to frames and back, checked byte for byte against frames of an independent implementation.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/mavlink/golden_frames.hpp"

namespace airseg::mavlink {
namespace {

using test::from_hex;

std::vector<Frame> parse_all(const std::vector<std::uint8_t>& bytes, Parser& parser) {
    std::vector<Frame> frames;
    parser.push(bytes, [&](const Frame& f) { frames.push_back(f); });
    parser.finish([&](const Frame& f) { frames.push_back(f); });
    return frames;
}

std::vector<Frame> parse_all(const std::vector<std::uint8_t>& bytes) {
    Parser parser;
    return parse_all(bytes, parser);
}

Heartbeat golden_heartbeat() {
    Heartbeat hb;
    hb.type = 10;
    hb.autopilot = 3;
    hb.base_mode = 0x59;
    hb.custom_mode = 4;
    hb.system_status = 4;
    return hb;
}

Encoder encoder_at(std::uint8_t sysid, std::uint8_t compid, Version v, std::uint8_t seq) {
    Encoder e(sysid, compid, v);
    // The sequence counter only moves forward by encoding; skip to the golden frame's number.
    std::array<std::uint8_t, kMaxFrameLength> scratch{};
    while (e.next_seq() != seq) {
        e.encode(Heartbeat{}, scratch);
    }
    return e;
}

TEST(MavlinkCodec, HeartbeatMatchesIndependentEncoderInBothVersions) {
    EXPECT_EQ(encoder_at(1, 1, Version::V1, 7).encode(golden_heartbeat()), from_hex(test::kHeartbeatV1));
    EXPECT_EQ(encoder_at(1, 1, Version::V2, 7).encode(golden_heartbeat()), from_hex(test::kHeartbeatV2));
}

TEST(MavlinkCodec, DecodesIndependentHeartbeats) {
    for (auto hex : {test::kHeartbeatV1, test::kHeartbeatV2}) {
        const auto frames = parse_all(from_hex(hex));
        ASSERT_EQ(frames.size(), 1u);
        EXPECT_EQ(frames[0].seq, 7);
        EXPECT_EQ(frames[0].sysid, 1);
        EXPECT_EQ(frames[0].compid, 1);
        EXPECT_TRUE(frames[0].checksum_verified);
        const auto hb = decode<Heartbeat>(frames[0]);
        ASSERT_TRUE(hb.has_value());
        EXPECT_EQ(*hb, golden_heartbeat());
    }
    EXPECT_EQ(parse_all(from_hex(test::kHeartbeatV1))[0].version, Version::V1);
    EXPECT_EQ(parse_all(from_hex(test::kHeartbeatV2))[0].version, Version::V2);
}

TEST(MavlinkCodec, GpsRawIntTruncatesTrailingZeroExtensionsAndZeroExtendsOnReceipt) {
    GpsRawInt gps;
    gps.time_usec = 123456789012ULL;
    gps.fix_type = 3;
    gps.lat = 473977418;
    gps.lon = 85455939;
    gps.alt = 488000;
    gps.eph = 121;
    gps.epv = 65535;
    gps.vel = 15;
    gps.cog = 27000;
    gps.satellites_visible = 10;
    const auto golden = from_hex(test::kGpsRawIntV2);
    EXPECT_EQ(encoder_at(1, 1, Version::V2, 200).encode(gps), golden);

    const auto frames = parse_all(golden);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].wire_length, 30);
    EXPECT_EQ(frames[0].payload_length, 52);  // zero-extended to the full message
    EXPECT_EQ(decode<GpsRawInt>(frames[0]), gps);
}

TEST(MavlinkCodec, StatustextCharArrayRoundTrips) {
    Statustext st;
    st.severity = 6;
    set_text(st.text, "Mission: 1 WP");
    EXPECT_EQ(encoder_at(1, 1, Version::V2, 0).encode(st), from_hex(test::kStatustextV2));
    const auto decoded = decode<Statustext>(parse_all(from_hex(test::kStatustextV2)).at(0));
    ASSERT_TRUE(decoded.has_value());
    EXPECT_EQ(text_of(decoded->text), "Mission: 1 WP");
}

TEST(MavlinkCodec, CommandLongFloatsAreLittleEndianIeee) {
    CommandLong cmd;
    cmd.target_system = 1;
    cmd.target_component = 1;
    cmd.command = 400;
    cmd.param1 = 1.0f;
    cmd.param2 = 21196.0f;
    cmd.param7 = -0.5f;
    EXPECT_EQ(encoder_at(255, 190, Version::V2, 9).encode(cmd), from_hex(test::kCommandLongV2));
    EXPECT_EQ(decode<CommandLong>(parse_all(from_hex(test::kCommandLongV2)).at(0)), cmd);
}

TEST(MavlinkCodec, ParamValueV1CarriesTheBasePayload) {
    ParamValue pv;
    set_text(pv.param_id, "SYSID_THISMAV");
    pv.param_value = 1.5f;
    pv.param_type = 9;
    pv.param_count = 900;
    pv.param_index = 17;
    EXPECT_EQ(encoder_at(1, 1, Version::V1, 3).encode(pv), from_hex(test::kParamValueV1));
    EXPECT_EQ(decode<ParamValue>(parse_all(from_hex(test::kParamValueV1)).at(0)), pv);
}

TEST(MavlinkCodec, Version1DropsExtensionFields) {
    MissionCount mc;
    mc.target_system = 1;
    mc.target_component = 1;
    mc.count = 5;
    mc.mission_type = 2;  // an extension: MAVLink 1 cannot carry it
    Encoder v1(255, 190, Version::V1);
    const auto bytes = v1.encode(mc);
    EXPECT_EQ(bytes.size(), kHeaderLengthV1 + 4 + kChecksumLength);
    const auto decoded = decode<MissionCount>(parse_all(bytes).at(0));
    ASSERT_TRUE(decoded.has_value());
    EXPECT_EQ(decoded->count, 5);
    EXPECT_EQ(decoded->mission_type, 0);

    Encoder v2(255, 190, Version::V2);
    EXPECT_EQ(decode<MissionCount>(parse_all(v2.encode(mc)).at(0))->mission_type, 2);
}

TEST(MavlinkCodec, AllZeroPayloadKeepsOneByte) {
    Encoder e(1, 1);
    const auto bytes = e.encode(MissionItemReached{});
    EXPECT_EQ(bytes[1], 1);  // payload length
    EXPECT_EQ(bytes.size(), kHeaderLengthV2 + 1 + kChecksumLength);
    EXPECT_EQ(decode<MissionItemReached>(parse_all(bytes).at(0))->seq, 0);
}

TEST(MavlinkCodec, SequenceNumbersAdvancePerEncoderAndWrap) {
    Encoder e(1, 1);
    std::array<std::uint8_t, kMaxFrameLength> out{};
    for (int i = 0; i < 256; ++i) {
        ASSERT_GT(e.encode(Heartbeat{}, out), 0u);
        ASSERT_EQ(out[4], static_cast<std::uint8_t>(i));
    }
    EXPECT_EQ(e.next_seq(), 0);
}

TEST(MavlinkCodec, EveryFieldOfAWideMessageRoundTrips) {
    AutopilotVersion av;
    av.capabilities = 0x0123456789ABCDEFULL;
    av.flight_sw_version = 0x04050600;
    av.middleware_sw_version = 1;
    av.os_sw_version = 2;
    av.board_version = 0xDEADBEEF;
    av.flight_custom_version = {1, 2, 3, 4, 5, 6, 7, 8};
    av.os_custom_version = {0xFF, 0, 0xFF, 0, 0xFF, 0, 0xFF, 0};
    av.vendor_id = 0x1209;
    av.product_id = 0x5741;
    av.uid = 0xFEDCBA9876543210ULL;
    av.uid2[17] = 0x42;
    for (Version v : {Version::V2}) {
        Encoder e(1, 1, v);
        EXPECT_EQ(decode<AutopilotVersion>(parse_all(e.encode(av)).at(0)), av);
    }
    BatteryStatus bs;
    bs.voltages = {4200, 4190, 4180, 65535, 65535, 65535, 65535, 65535, 65535, 65535};
    bs.current_battery = -1;
    bs.battery_remaining = -1;
    bs.temperature = -1234;
    bs.voltages_ext = {1, 2, 3, 4};
    bs.fault_bitmask = 0x80000001u;
    Encoder e(1, 1);
    EXPECT_EQ(decode<BatteryStatus>(parse_all(e.encode(bs)).at(0)), bs);
}

TEST(MavlinkCodec, ExplicitLittleEndianLayoutOfATypedPayload) {
    SetMode sm;
    sm.target_system = 1;
    sm.base_mode = 0x81;
    sm.custom_mode = 0x0A0B0C0D;
    std::array<std::uint8_t, kMaxPayload> payload{};
    ASSERT_EQ(encode_payload(sm, payload), 6u);
    const std::array<std::uint8_t, 6> expected{0x0D, 0x0C, 0x0B, 0x0A, 0x01, 0x81};
    EXPECT_TRUE(std::equal(expected.begin(), expected.end(), payload.begin()));
}

TEST(MavlinkCodec, DecodeOfAnotherMessageIsEmpty) {
    const auto frames = parse_all(from_hex(test::kHeartbeatV2));
    EXPECT_FALSE(decode<SysStatus>(frames.at(0)).has_value());
}

TEST(MavlinkCodec, LongerPayloadThanKnownIsAccepted) {
    // A sender with a newer definition may append fields; the known ones still decode.
    Encoder e(1, 1);
    MissionItemReached m;
    m.seq = 0x1234;
    std::array<std::uint8_t, 4> payload{0x34, 0x12, 0x99, 0x98};
    std::array<std::uint8_t, kMaxFrameLength> out{};
    const auto* info = find_message(MissionItemReached::kId);
    const std::size_t n = encode_frame(FrameHeader{Version::V2, 0, 1, 1, MissionItemReached::kId, 0},
                                       info->crc_extra, payload, out);
    const auto frames =
        parse_all(std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].payload_length, 4);
    EXPECT_EQ(decode<MissionItemReached>(frames[0]), m);
}

TEST(MavlinkCodec, EncodeFrameRefusesWhatCannotBeFramed) {
    std::array<std::uint8_t, kMaxFrameLength> out{};
    std::array<std::uint8_t, 1> payload{0};
    EXPECT_EQ(encode_frame(FrameHeader{Version::V1, 0, 1, 1, 300, 0}, 0, payload, out), 0u);
    EXPECT_EQ(encode_frame(FrameHeader{Version::V2, 0, 1, 1, 0x1000000, 0}, 0, payload, out), 0u);
    EXPECT_GT(encode_frame(FrameHeader{Version::V2, 0, 1, 1, 300, 0}, 0, payload, out), 0u);
}

}  // namespace
}  // namespace airseg::mavlink

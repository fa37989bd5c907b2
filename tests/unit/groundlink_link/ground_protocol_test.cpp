#include "services/groundlink/protocol/ground_protocol.hpp"

#include "services/groundlink/protocol/deflate_codec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace airseg::groundlink::protocol {
namespace {

Telemetry sample() {
    Telemetry t;
    t.lat_deg = 41.2756789;
    t.lon_deg = 1.9871234;
    t.alt_m = 12.3;
    t.ground_speed_mps = 2.54;
    t.heading_deg = 271.25;
    t.roll_deg = -5;
    t.pitch_deg = 3;
    t.battery_v = 12.345;
    t.battery_pct = 87;
    t.gps_fix = 3;
    t.satellites = 11;
    t.vehicle_state = 4;
    t.mode = 10;
    t.plan_state = 1;
    t.plan_element = 7;
    t.next_waypoint = 123456;
    return t;
}

TEST(GroundProtocol, TelemetryIsTwentyNineBytesAndRoundTrips) {
    const auto bytes = encode(sample());
    EXPECT_EQ(bytes.size(), 29u);
    EXPECT_EQ(bytes[0], kVersion);
    EXPECT_EQ(bytes[1], 0x01);
    // Explicit little-endian: latitude 412756789 = 0x189A2D35.
    EXPECT_EQ(bytes[2], 0x35);
    EXPECT_EQ(bytes[5], 0x18);
    auto decoded = decode(bytes);
    ASSERT_TRUE(decoded.message) << decoded.error;
    const auto& t = std::get<Telemetry>(*decoded.message);
    EXPECT_NEAR(t.lat_deg, 41.2756789, 1e-7);
    EXPECT_NEAR(t.lon_deg, 1.9871234, 1e-7);
    EXPECT_NEAR(t.alt_m, 12.3, 0.05);
    EXPECT_NEAR(t.ground_speed_mps, 2.54, 0.005);
    EXPECT_NEAR(t.heading_deg, 271.25, 0.005);
    EXPECT_EQ(t.roll_deg, -5);
    EXPECT_EQ(t.pitch_deg, 3);
    EXPECT_NEAR(t.battery_v, 12.345, 0.0005);
    EXPECT_EQ(t.battery_pct, 87);
    EXPECT_EQ(t.gps_fix, 3);
    EXPECT_EQ(t.satellites, 11);
    EXPECT_EQ(t.vehicle_state, 4);
    EXPECT_EQ(t.mode, 10);
    EXPECT_EQ(t.plan_state, 1);
    EXPECT_EQ(t.plan_element, 7);
    EXPECT_EQ(t.next_waypoint, 123456u);
}

TEST(GroundProtocol, EveryPlanStateRoundTripsBesideTheVehicleState) {
    for (std::uint8_t state = 0; state <= 5; ++state) {
        auto t = sample();
        t.plan_state = state;
        t.vehicle_state = 15;
        const auto decoded = decode(encode(t));
        ASSERT_TRUE(decoded.message) << decoded.error;
        EXPECT_EQ(std::get<Telemetry>(*decoded.message).plan_state, state);
        EXPECT_EQ(std::get<Telemetry>(*decoded.message).vehicle_state, 15);
    }
}

TEST(GroundProtocol, TheNoPositionBitRoundTripsBesideBothStates) {
    for (const bool none : {false, true}) {
        auto t = sample();
        t.plan_state = 5;
        t.vehicle_state = 15;
        t.no_position = none;
        const auto decoded = decode(encode(t));
        ASSERT_TRUE(decoded.message) << decoded.error;
        const auto& got = std::get<Telemetry>(*decoded.message);
        EXPECT_EQ(got.no_position, none);
        EXPECT_EQ(got.plan_state, 5);
        EXPECT_EQ(got.vehicle_state, 15);
    }
}

TEST(GroundProtocol, TelemetryClampsOutOfRangeValues) {
    Telemetry t;
    t.lat_deg = -33.9;
    t.lon_deg = -151.2;
    t.alt_m = 99999;
    t.heading_deg = -90;
    t.roll_deg = 400;
    t.satellites = 40;
    t.battery_pct.reset();
    t.next_waypoint = 50'000'000;
    auto d = decode(encode(t));
    ASSERT_TRUE(d.message);
    const auto& back = std::get<Telemetry>(*d.message);
    EXPECT_NEAR(back.lat_deg, -33.9, 1e-7);
    EXPECT_NEAR(back.lon_deg, -151.2, 1e-7);
    EXPECT_NEAR(back.alt_m, 3276.7, 0.01);
    EXPECT_NEAR(back.heading_deg, 270.0, 0.01);
    EXPECT_EQ(back.roll_deg, 127);
    EXPECT_EQ(back.satellites, 15);
    EXPECT_FALSE(back.battery_pct.has_value());
    EXPECT_EQ(back.next_waypoint, 0xffffffu);
}

TEST(GroundProtocol, OtherMessagesRoundTrip) {
    std::vector<Message> messages{
        LinkStatsReport{180, 52, 4800, 17, 2},
        Event{Event::Severity::Warning, "autopilot rebooted"},
        Command{42, {{"cmd", "param.set"}, {"name", "WP_RADIUS"}, {"value", 2.5}}},
        Result{42, {{"ok", true}, {"result", {{"value", 2.5}}}}},
    };
    for (const auto& m : messages) {
        auto d = decode(encode(m));
        ASSERT_TRUE(d.message) << d.error;
        EXPECT_EQ(*d.message, m);
    }
}

// A status answer as airsegd sends it: the CBOR is about 1.5 KB, the message on the radio a fraction.
TEST(GroundProtocol, AStatusAnswerIsCompressedToAFewHundredBytesAndRoundTrips) {
    nlohmann::json status = {
        {"autopilot",
         {{"link", "up"},
          {"mode", "AUTO"},
          {"state", "DIRECTED"},
          {"ready", true},
          {"reboots", 0},
          {"position", {{"lat", 41.27612}, {"lon", 1.98711}, {"alt", 3.2}}}}},
        {"groundlink",
         {{"link", "up"},
          {"frames_sent", 18234},
          {"frames_received", 9932},
          {"crc_errors", 311},
          {"framing_errors", 2817},
          {"rtt_ms", 412.5},
          {"loss", 0.04},
          {"mode", "single"}}},
        {"plan", {{"state", "running"}, {"name", "rover-survey"}, {"window", 5}, {"waypoints_reached", 12}}},
        {"services",
         {{"autopilot", {{"health", "up"}, {"error", ""}, {"since", "2026-11-25T14:10:02.982Z"}}}}},
        {"uptime_s", 5123.4},
        {"version", "0.1.0"}};
    for (int i = 0; i < 40; ++i) {
        status["groundlink"]["per_kind"]["counter_" + std::to_string(i)] = i * 7;  // bulk of a real document
    }
    const Result answer{9, {{"ok", true}, {"result", status}}};
    const auto cbor = nlohmann::json::to_cbor(answer.answer);
    const auto wire = encode(answer);
    EXPECT_EQ(wire[1], static_cast<std::uint8_t>(MessageType::ResultDeflated));
    EXPECT_LT(wire.size(), cbor.size() / 2) << "cbor " << cbor.size() << " bytes";
    const auto back = decode(wire);
    ASSERT_TRUE(back.message) << back.error;
    EXPECT_EQ(*back.message, Message(answer));

    // A short command stays plain CBOR: compressing it would not pay.
    const auto status_cmd = encode(Command{1, {{"cmd", "status"}}});
    EXPECT_EQ(status_cmd[1], static_cast<std::uint8_t>(MessageType::Command));
}

TEST(GroundProtocol, ADamagedCompressedPayloadIsNamedNotDecoded) {
    nlohmann::json big;
    for (int i = 0; i < 50; ++i) {
        big["key_" + std::to_string(i)] = "value " + std::to_string(i);
    }
    auto wire = encode(Command{3, {{"cmd", "plan.load"}, {"plan", big}}});
    ASSERT_EQ(wire[1], static_cast<std::uint8_t>(MessageType::CommandDeflated));
    auto truncated = wire;
    truncated.resize(truncated.size() / 2);
    const auto d = decode(truncated);
    EXPECT_FALSE(d.message);
    EXPECT_NE(d.error.find("does not inflate"), std::string::npos) << d.error;
    // A stream that would inflate beyond the limit is refused, not allocated.
    const std::vector<std::uint8_t> zeros(kMaxInflated + 1024, 0);
    auto bomb = std::vector<std::uint8_t>{
        kVersion, static_cast<std::uint8_t>(MessageType::ResultDeflated), 1, 0, 0, 0};
    const auto packed = deflate_payload(zeros);
    bomb.insert(bomb.end(), packed.begin(), packed.end());
    EXPECT_LT(packed.size(), 2048U);
    const auto refused = decode(bomb);
    EXPECT_FALSE(refused.message);
    EXPECT_NE(refused.error.find("larger than"), std::string::npos) << refused.error;
}

TEST(GroundProtocol, UnknownTypesAreSkippedNotErrors) {
    std::vector<std::uint8_t> bytes{kVersion, 0x7e, 1, 2, 3};
    auto d = decode(bytes);
    ASSERT_TRUE(d.message);
    EXPECT_EQ(std::get<Unknown>(*d.message).type, 0x7e);
}

TEST(GroundProtocol, BadInputIsNamed) {
    EXPECT_NE(decode(std::vector<std::uint8_t>{1}).error.find("shorter"), std::string::npos);
    EXPECT_NE(decode(std::vector<std::uint8_t>{9, 1}).error.find("version 9"), std::string::npos);
    auto telemetry = encode(sample());
    telemetry.pop_back();
    EXPECT_FALSE(decode(telemetry).message);
    std::vector<std::uint8_t> bad_cbor{kVersion, 0x10, 1, 0, 0, 0, 0xff};
    EXPECT_FALSE(decode(bad_cbor).message);
}

TEST(GroundProtocol, DeeplyNestedPayloadIsRefusedWithoutRecursion) {
    std::vector<std::uint8_t> bytes{kVersion, 0x10, 1, 0, 0, 0};
    bytes.insert(bytes.end(), 100000, 0x81);  // arrays of one element, nested 100000 deep
    bytes.push_back(0x00);
    auto d = decode(bytes);
    EXPECT_FALSE(d.message);
    EXPECT_NE(d.error.find("nested"), std::string::npos);

    // 20 levels is fine.
    std::vector<std::uint8_t> ok{kVersion, 0x10, 1, 0, 0, 0};
    ok.insert(ok.end(), 20, 0x81);
    ok.push_back(0x00);
    EXPECT_TRUE(decode(ok).message) << decode(ok).error;
}

TEST(GroundProtocol, RandomBytesNeverCrash) {
    std::mt19937 rng(7);
    for (int i = 0; i < 20000; ++i) {
        std::vector<std::uint8_t> bytes(rng() % 64);
        for (auto& b : bytes) {
            b = static_cast<std::uint8_t>(rng());
        }
        if (!bytes.empty()) {
            bytes[0] = kVersion;
        }
        auto d = decode(bytes);
        EXPECT_TRUE(d.message.has_value() != !d.error.empty());
    }
}

TEST(GroundProtocol, JoystickRoundTripsAndClamps) {
    const auto bytes = encode(Joystick{-0.5, 0.25});
    ASSERT_EQ(bytes.size(), 6u);
    EXPECT_EQ(bytes[1], 0x12);
    // steering -5000 = 0xEC78, little-endian.
    EXPECT_EQ(bytes[2], 0x78);
    EXPECT_EQ(bytes[3], 0xEC);
    auto d = decode(bytes);
    ASSERT_TRUE(d.message) << d.error;
    EXPECT_EQ(std::get<Joystick>(*d.message), (Joystick{-0.5, 0.25}));

    auto clamped = decode(encode(Joystick{3.0, -7.0}));
    EXPECT_EQ(std::get<Joystick>(*clamped.message), (Joystick{1.0, -1.0}));
    // A hostile peer's out-of-range axes are clamped on decoding too.
    std::vector<std::uint8_t> wild{kVersion, 0x12, 0xff, 0x7f, 0x00, 0x80};
    EXPECT_EQ(std::get<Joystick>(*decode(wild).message), (Joystick{1.0, -1.0}));
    std::vector<std::uint8_t> short_body{kVersion, 0x12, 0x00};
    EXPECT_FALSE(decode(short_body).message);
}

TEST(GroundProtocol, ReceptionReportRoundTrips) {
    const auto bytes = encode(ReceptionReport{0x01020304});
    ASSERT_EQ(bytes.size(), 6u);
    EXPECT_EQ(bytes[1], 0x13);
    EXPECT_EQ(bytes[2], 0x04);
    EXPECT_EQ(bytes[5], 0x01);
    EXPECT_EQ(std::get<ReceptionReport>(*decode(bytes).message), ReceptionReport{0x01020304});
    EXPECT_FALSE(decode(std::vector<std::uint8_t>{kVersion, 0x13, 1, 2}).message);
}

TEST(GroundProtocol, MavlinkFramesCarryTheirBytesUnchanged) {
    // Two frames back to back (a v2 HEARTBEAT and the start of another): the protocol does not look inside.
    const std::vector<std::uint8_t> frames{0xfd, 0x09, 0x00, 0x00, 0x00, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00,
                                           0x00, 0x00, 0x00, 0x0a, 0x03, 0x81, 0x04, 0x03, 0xc7, 0xc7, 0xfe};
    const auto bytes = encode(MavlinkFrames{frames});
    ASSERT_EQ(bytes.size(), 2 + frames.size());
    EXPECT_EQ(bytes[1], 0x16);
    EXPECT_TRUE(std::equal(frames.begin(), frames.end(), bytes.begin() + 2));
    const auto d = decode(bytes);
    ASSERT_TRUE(d.message) << d.error;
    EXPECT_EQ(std::get<MavlinkFrames>(*d.message).bytes, frames);
    // An empty one carries nothing and is refused.
    EXPECT_FALSE(decode(std::vector<std::uint8_t>{kVersion, 0x16}).message);
}

TEST(GroundProtocol, MavlinkTopicsArePerMessageIdAndApartFromAirsegTopics) {
    EXPECT_EQ(mavlink_topic(0), 0x8000);
    EXPECT_EQ(mavlink_topic(30), 0x801e);
    EXPECT_NE(mavlink_topic(30), mavlink_topic(33));
    for (const auto own : {kTopicTelemetry, kTopicLinkStats, kTopicJoystick, kTopicReception}) {
        EXPECT_LT(own, kTopicMavlinkBase);
    }
}

TEST(GroundProtocol, StateNames) {
    EXPECT_STREQ(vehicle_state_name(4), "MANUAL_NAVIGATION");
    EXPECT_STREQ(vehicle_state_name(15), "?");
}

}  // namespace
}  // namespace airseg::groundlink::protocol

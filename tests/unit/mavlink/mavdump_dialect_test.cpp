// airseg-mavdump over ArduPilot's whole dialect: messages the daemon has no struct for are decoded and
// encoded field by field, and the dialect listing (--messages) has the documented shape.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tools/mavdump/frame_json.hpp"

namespace airseg::mavdump {
// Named: a unity build compiles the test files of this binary in one translation unit.
namespace dialect_json_test {
namespace {

std::vector<mavlink::Frame> parse_frames(const std::vector<std::uint8_t>& bytes) {
    mavlink::Parser p;
    std::vector<mavlink::Frame> frames;
    p.push(bytes, [&](const mavlink::Frame& f) { frames.push_back(f); });
    p.finish([&](const mavlink::Frame& f) { frames.push_back(f); });
    return frames;
}

TEST(MavdumpDialect, ListingHasTheDocumentedShape) {
    const mavlink::MessageInfo* m = mavlink::find_dialect_message("MISSION_COUNT");
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(
        message_to_json(*m),
        R"({"name":"MISSION_COUNT","msgid":44,"crc_extra":221,"min_length":4,"length":9,"typed":true,)"
        R"("fields":[{"name":"target_system","type":"uint8_t"},{"name":"target_component","type":"uint8_t"},)"
        R"({"name":"count","type":"uint16_t"},{"name":"mission_type","type":"uint8_t","extension":true},)"
        R"({"name":"opaque_id","type":"uint32_t","extension":true}]})");
    const mavlink::MessageInfo* named = mavlink::find_dialect_message("NAMED_VALUE_FLOAT");
    ASSERT_NE(named, nullptr);
    EXPECT_NE(message_to_json(*named).find(R"({"name":"name","type":"char","length":10})"),
              std::string::npos);
    EXPECT_NE(message_to_json(*named).find(R"("typed":false)"), std::string::npos);
}

TEST(MavdumpDialect, UntypedMessageIsDecodedByFieldName) {
    JsonFrameEncoder encoder;
    const auto r = encoder.encode_line(
        R"({"name":"AHRS","sysid":1,"compid":1,"fields":{"omegaIx":1.5,"error_yaw":-0.25,"renorm_val":3}})");
    ASSERT_EQ(r.error, "");
    const auto frames = parse_frames(r.frame);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_TRUE(frames[0].checksum_verified);
    EXPECT_FALSE(frames[0].typed);
    EXPECT_EQ(frame_to_json(frames[0]),
              R"({"name":"AHRS","msgid":163,"sysid":1,"compid":1,"seq":0,"v":2,"fields":{"omegaIx":1.5,)"
              R"("omegaIy":0,"omegaIz":0,"accel_weight":0,"renorm_val":3,"error_rp":0,"error_yaw":-0.25}})");
    EXPECT_EQ(encoder.encode_line(R"({"name":"AHRS","fields":{"no_such":1}})").error,
              R"(AHRS has no field "no_such")");
}

// Each message with every byte of its payload set: the JSON line encodes back to the same frame.
TEST(MavdumpDialect, EveryDialectMessageRoundTripsThroughJson) {
    for (const mavlink::MessageInfo& m : mavlink::dialect_messages()) {
        std::vector<std::uint8_t> payload(m.length, 0x41);  // 'A': printable in strings, non-zero elsewhere
        std::array<std::uint8_t, mavlink::kMaxFrameLength> out{};
        const std::size_t n = mavlink::encode_message(
            mavlink::FrameHeader{mavlink::Version::V2, 3, 9, 8, m.id, 0}, m, payload, out);
        const std::vector<std::uint8_t> bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
        const auto frames = parse_frames(bytes);
        ASSERT_EQ(frames.size(), 1u) << m.name;
        const std::string json = frame_to_json(frames[0]);
        EXPECT_EQ(json.find("UNKNOWN"), std::string::npos) << json;
        JsonFrameEncoder encoder;
        const auto back = encoder.encode_line(json);
        EXPECT_EQ(back.error, "") << m.name;
        EXPECT_EQ(back.frame, bytes) << m.name << ": " << json;
    }
}

}  // namespace
}  // namespace dialect_json_test
}  // namespace airseg::mavdump

// The JSON side of airseg-mavdump: frame -> JSON line -> frame, errors, and the JSON reader itself.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/mavlink/golden_frames.hpp"
#include "tools/mavdump/frame_json.hpp"
#include "tools/mavdump/json.hpp"
#include "tools/mavdump/tlog_reader.hpp"

namespace airseg::mavdump {
namespace {

using mavlink::test::from_hex;

std::vector<mavlink::Frame> parse(const std::vector<std::uint8_t>& bytes) {
    mavlink::Parser p;
    std::vector<mavlink::Frame> frames;
    p.push(bytes, [&](const mavlink::Frame& f) { frames.push_back(f); });
    p.finish([&](const mavlink::Frame& f) { frames.push_back(f); });
    return frames;
}

TEST(MavdumpJson, HeartbeatLineHasTheDocumentedShape) {
    const auto frames = parse(from_hex(mavlink::test::kHeartbeatV2));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frame_to_json(frames[0]),
              R"({"name":"HEARTBEAT","msgid":0,"sysid":1,"compid":1,"seq":7,"v":2,"fields":{"type":10,)"
              R"("autopilot":3,"base_mode":89,"custom_mode":4,"system_status":4,"mavlink_version":3}})");
}

TEST(MavdumpJson, GoldenFramesRoundTripByteForByte) {
    JsonFrameEncoder encoder;
    for (auto hex :
         {mavlink::test::kHeartbeatV1, mavlink::test::kHeartbeatV2, mavlink::test::kGpsRawIntV2,
          mavlink::test::kStatustextV2, mavlink::test::kCommandLongV2, mavlink::test::kParamValueV1}) {
        const auto bytes = from_hex(hex);
        const auto frames = parse(bytes);
        ASSERT_EQ(frames.size(), 1u) << hex;
        const auto result = encoder.encode_line(frame_to_json(frames[0]));
        ASSERT_EQ(result.error, "") << hex;
        EXPECT_EQ(result.frame, bytes) << frame_to_json(frames[0]);
    }
}

TEST(MavdumpJson, FloatsSpecialValuesAndArraysRoundTrip) {
    JsonFrameEncoder encoder;
    const std::string line =
        R"({"name":"HOME_POSITION","sysid":1,"compid":1,"seq":4,"v":2,"fields":{"latitude":-353632621,)"
        R"("longitude":1491652374,"altitude":584070,"x":0.1,"y":"nan","z":"-inf","q":[1,0,0,1e-07],)"
        R"("approach_x":3.4028235e+38,"time_usec":18446744073709551615}})";
    const auto result = encoder.encode_line(line);
    ASSERT_EQ(result.error, "");
    const auto frames = parse(result.frame);
    ASSERT_EQ(frames.size(), 1u);
    const auto home = mavlink::decode<mavlink::HomePosition>(frames[0]);
    ASSERT_TRUE(home.has_value());
    EXPECT_EQ(home->latitude, -353632621);
    EXPECT_EQ(home->x, 0.1f);
    EXPECT_TRUE(std::isnan(home->y));
    EXPECT_TRUE(std::isinf(home->z) && home->z < 0);
    EXPECT_EQ(home->q[3], 1e-07f);
    EXPECT_EQ(home->time_usec, 18446744073709551615ull);
    const std::string back = frame_to_json(frames[0]);
    EXPECT_NE(back.find(R"("x":0.1,"y":"nan","z":"-inf","q":[1,0,0,1e-07])"), std::string::npos) << back;
    EXPECT_NE(back.find(R"("approach_x":3.4028235e+38)"), std::string::npos) << back;
}

TEST(MavdumpJson, NonAsciiTextSurvivesAsEscapedBytes) {
    JsonFrameEncoder encoder;
    const auto result = encoder.encode_line(
        R"({"name":"STATUSTEXT","fields":{"severity":2,"text":"quote \" back \\ \u00e9\u0001"}})");
    ASSERT_EQ(result.error, "");
    const auto frames = parse(result.frame);
    const auto st = mavlink::decode<mavlink::Statustext>(frames.at(0));
    EXPECT_EQ(mavlink::text_of(st->text), std::string("quote \" back \\ \xe9\x01"));
    EXPECT_NE(frame_to_json(frames[0]).find(R"("text":"quote \" back \\ \u00e9\u0001")"), std::string::npos);
}

TEST(MavdumpJson, DefaultsAndSequenceCounting) {
    JsonFrameEncoder encoder;
    const auto a = encoder.encode_line(R"({"name":"HEARTBEAT"})");
    const auto b = encoder.encode_line(R"({"msgid":0})");
    const auto c = encoder.encode_line(R"({"name":"HEARTBEAT","sysid":1,"compid":1,"v":1})");
    ASSERT_EQ(a.error + b.error + c.error, "");
    const auto fa = parse(a.frame).at(0);
    const auto fb = parse(b.frame).at(0);
    const auto fc = parse(c.frame).at(0);
    EXPECT_EQ(fa.sysid, 255);
    EXPECT_EQ(fa.compid, 190);
    EXPECT_EQ(fa.version, mavlink::Version::V2);
    EXPECT_EQ(fa.seq, 0);
    EXPECT_EQ(fb.seq, 1);
    EXPECT_EQ(fc.seq, 0);  // another sender, its own counter
    EXPECT_EQ(fc.version, mavlink::Version::V1);
}

TEST(MavdumpJson, UnknownIdsPrintRawAndEncodeWithTheirCrcExtra) {
    JsonFrameEncoder encoder;
    const auto r =
        encoder.encode_line(R"({"msgid":12345,"sysid":1,"compid":1,"payload":"0102ff","crc_extra":7})");
    ASSERT_EQ(r.error, "");
    const auto f = parse(r.frame).at(0);
    EXPECT_FALSE(f.checksum_verified);
    EXPECT_EQ(frame_to_json(f), R"({"name":"UNKNOWN_12345","msgid":12345,"sysid":1,"compid":1,"seq":0,"v":2,)"
                                R"("payload":"0102ff"})");
}

TEST(MavdumpJson, ErrorsNameWhatIsWrong) {
    JsonFrameEncoder encoder;
    auto error_of = [&](const char* line) { return encoder.encode_line(line).error; };
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"typo":1}})"), "HEARTBEAT has no field \"typo\"");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"type":256}})"),
              "HEARTBEAT.type: value out of range for uint8_t");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"type":1.5}})"),
              "HEARTBEAT.type: expects an integer, got 1.5");
    EXPECT_EQ(
        error_of(
            R"({"name":"STATUSTEXT","fields":{"text":"012345678901234567890123456789012345678901234567890"}})"),
        "STATUSTEXT.text: string longer than 50 bytes");
    EXPECT_EQ(error_of(R"({"name":"NOPE"})"),
              "unknown message name \"NOPE\" (give \"msgid\" to send it raw)");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","msgid":1})"), "\"name\" HEARTBEAT has msgid 0, not 1");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","v":3})"), "\"v\" must be 1 or 2");
    EXPECT_EQ(error_of(R"({"msgid":70000})"),
              "message id 70000 is not known: give its raw \"payload\" (hex) and its \"crc_extra\"");
    EXPECT_EQ(error_of(R"({"msgid":300,"payload":"00","crc_extra":1,"v":1})"),
              "message id 300 cannot be sent as MAVLink 1 (ids above 255 need v2)");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT",)"), "invalid JSON: expected a string key at byte 20");
    EXPECT_EQ(error_of("[1,2]"), "expected a JSON object");
}

TEST(MavdumpJson, ReaderRejectsMalformedDocuments) {
    for (const char* bad : {"", "{", "{\"a\":}", "[1,]", "\"unterminated", "01x", "{\"a\":1} trailing", "-",
                            "1.", "\"\\ud800\"", "\"\\q\""}) {
        EXPECT_FALSE(parse_json(bad).value.has_value()) << bad;
    }
    std::string deep(100, '[');
    EXPECT_FALSE(parse_json(deep).value.has_value());
    const auto ok = parse_json(R"( {"a":[true,false,null,-1.5e3,"x\u20ac\ud83d\ude00"]} )");
    ASSERT_TRUE(ok.value.has_value());
    const auto* arr = ok.value->member("a")->as_array();
    ASSERT_NE(arr, nullptr);
    EXPECT_EQ(*(*arr)[4].as_string(), "x\xe2\x82\xac\xf0\x9f\x98\x80");
}

TEST(MavdumpTlog, SplitsRecordsAndResynchronises) {
    std::vector<std::uint8_t> log;
    auto add = [&](std::uint64_t t, const std::vector<std::uint8_t>& frame) {
        for (int i = 7; i >= 0; --i) {
            log.push_back(static_cast<std::uint8_t>(t >> (8 * i)));
        }
        log.insert(log.end(), frame.begin(), frame.end());
    };
    add(1700000000000001ull, from_hex(mavlink::test::kHeartbeatV2));
    log.push_back(0x00);  // a stray byte between records
    add(1700000000000002ull, from_hex(mavlink::test::kParamValueV1));
    add(1700000000000003ull, from_hex(mavlink::test::kGpsRawIntV2));
    TlogReader reader;
    std::vector<std::uint64_t> times;
    for (std::size_t i = 0; i < log.size(); i += 5) {  // awkward chunking
        reader.push(std::span(log).subspan(i, std::min<std::size_t>(5, log.size() - i)),
                    [&](std::uint64_t t, std::span<const std::uint8_t> frame) {
                        times.push_back(t);
                        EXPECT_EQ(parse(std::vector<std::uint8_t>(frame.begin(), frame.end())).size(), 1u);
                    });
    }
    reader.finish();
    EXPECT_EQ(times,
              (std::vector<std::uint64_t>{1700000000000001ull, 1700000000000002ull, 1700000000000003ull}));
    EXPECT_EQ(reader.skipped_bytes(), 1u);
}

}  // namespace
}  // namespace airseg::mavdump

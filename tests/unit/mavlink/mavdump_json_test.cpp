// The JSON side of airseg-mavdump: frame -> JSON line -> frame, errors, and how malformed lines are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/mavlink/golden_frames.hpp"
#include "tools/mavdump/frame_json.hpp"
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
    EXPECT_EQ(
        error_of(R"({"name":"HEARTBEAT",)"),
        "invalid JSON: syntax error while parsing object key - unexpected end of input; expected string "
        "literal at byte 20");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"type":-1}})"),
              "HEARTBEAT.type: value out of range for uint8_t");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"type":"1"}})"),
              "HEARTBEAT.type: expects an integer");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","fields":{"type":1e2}})"),
              "HEARTBEAT.type: expects an integer, got 100.0");
    EXPECT_EQ(error_of(R"({"name":"HOME_POSITION","fields":{"time_usec":18446744073709551616}})"),
              "HOME_POSITION.time_usec: integer out of range");
    EXPECT_EQ(error_of(R"({"name":"HOME_POSITION","fields":{"latitude":-9223372036854775809}})"),
              "HOME_POSITION.latitude: integer out of range");
    EXPECT_EQ(error_of(R"({"name":"HOME_POSITION","fields":{"time_usec":-1}})"),
              "HOME_POSITION.time_usec: value out of range for uint64_t");
    EXPECT_EQ(error_of(R"({"name":"HOME_POSITION","fields":{"x":1e400}})"),
              "invalid JSON: number out of range");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","sysid":256})"), "\"sysid\" must be an integer from 0 to 255");
    EXPECT_EQ(error_of(R"({"name":"HEARTBEAT","seq":1.0})"), "\"seq\" must be an integer from 0 to 255");
    EXPECT_EQ(error_of("[1,2]"), "expected a JSON object");
}

TEST(MavdumpJson, MalformedLinesAreRefusedWithTheirByteOffset) {
    JsonFrameEncoder encoder;
    for (const char* bad : {"", "{", "{\"a\":}", "[1,]", "\"unterminated", "01x", "{\"a\":1} trailing", "-",
                            "1.", "\"\\ud800\"", "\"\\q\"", "{\"text\":\"\xff\"}"}) {
        const auto r = encoder.encode_line(bad);
        EXPECT_EQ(r.error.rfind("invalid JSON: ", 0), 0u) << bad;
        EXPECT_NE(r.error.find(" at byte "), std::string::npos) << r.error;
        EXPECT_TRUE(r.frame.empty());
    }
    EXPECT_EQ(encoder.encode_line(R"({"name":"HEARTBEAT","fields":{"type":1,}})").error,
              "invalid JSON: syntax error while parsing object key - unexpected '}'; expected string literal "
              "at byte 39");
    // The error names the place, not the input: a long or binary token is not echoed.
    const std::string long_token = R"({"name":")" + std::string(10000, 'x') + "\x01\"}";
    const std::string error = encoder.encode_line(long_token).error;
    EXPECT_LT(error.size(), 200u) << error;
    EXPECT_NE(error.find("at byte 10009"), std::string::npos) << error;
    EXPECT_EQ(error.find('\x01'), std::string::npos);
}

TEST(MavdumpJson, NestingIsBounded) {
    JsonFrameEncoder encoder;
    auto nested = [](int levels) {  // the frame object itself is the first level
        return R"({"name":"HEARTBEAT","ignored":)" + std::string(levels - 1, '[') +
               std::string(levels - 1, ']') + "}";
    };
    EXPECT_EQ(encoder.encode_line(nested(32)).error, "");
    EXPECT_EQ(encoder.encode_line(nested(33)).error, "invalid JSON: nested deeper than 32 levels");
    // Refused as soon as the limit is crossed, whatever follows.
    EXPECT_EQ(encoder.encode_line(std::string(1000000, '[')).error,
              "invalid JSON: nested deeper than 32 levels");
}

TEST(MavdumpJson, TextFieldsTakeUnicodeEscapesAndUtf8) {
    JsonFrameEncoder encoder;
    // A copy: text_of is a view into the decoded message, which ends with the lambda.
    auto text_of_line = [&](const std::string& line) -> std::string {
        const auto r = encoder.encode_line(line);
        EXPECT_EQ(r.error, "") << line;
        const auto st = mavlink::decode<mavlink::Statustext>(parse(r.frame).at(0));
        return std::string(mavlink::text_of(st->text));
    };
    // Above U+00FF a code point keeps its UTF-8 bytes, whether escaped or written as is.
    EXPECT_EQ(text_of_line(R"({"name":"STATUSTEXT","fields":{"text":"x\u20ac\ud83d\ude00"}})"),
              "x\xe2\x82\xac\xf0\x9f\x98\x80");
    EXPECT_EQ(text_of_line("{\"name\":\"STATUSTEXT\",\"fields\":{\"text\":\"x\xe2\x82\xac\"}}"),
              "x\xe2\x82\xac");
    // Up to U+00FF a code point is one byte (the printer's \u00NN), written as is or escaped.
    EXPECT_EQ(text_of_line("{\"name\":\"STATUSTEXT\",\"fields\":{\"text\":\"\xc3\xa9\\u00ff\"}}"),
              "\xe9\xff");
    // The length limit counts bytes of the field, so 50 such code points fit.
    std::string fifty;
    for (int i = 0; i < 50; ++i) {
        fifty += "\\u00e9";
    }
    EXPECT_EQ(text_of_line(R"({"name":"STATUSTEXT","fields":{"text":")" + fifty + "\"}}"),
              std::string(50, '\xe9'));
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

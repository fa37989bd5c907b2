// The radio profile: the --radio text, its checks (each naming the key) and what it makes of the transport.
#include "services/groundlink/transport/radio_profile.hpp"

#include <gtest/gtest.h>

#include <string>

namespace airseg::groundlink {
namespace {

using std::chrono::milliseconds;

bool same(const RadioProfile& a, const RadioProfile& b) {
    return a.air_speed_kbps == b.air_speed_kbps && a.ecc == b.ecc && a.packet_bytes == b.packet_bytes &&
           a.packet_overhead == b.packet_overhead && a.turnaround == b.turnaround &&
           a.half_duplex == b.half_duplex && a.buffer_bytes == b.buffer_bytes && a.adapt == b.adapt;
}

TEST(GroundlinkRadioProfile, DefaultsAreValid) {
    const RadioProfile p;
    EXPECT_EQ(p.validate("groundlink.radio"), "");
    EXPECT_EQ(p.air_speed_kbps, 0u);
    EXPECT_FALSE(p.ecc);
    EXPECT_EQ(p.packet_bytes, 252u);
    EXPECT_EQ(p.packet_overhead, 0u);
    EXPECT_EQ(p.turnaround, milliseconds(1));
    EXPECT_TRUE(p.half_duplex);
    EXPECT_EQ(p.buffer_bytes, 0u);
    EXPECT_FALSE(p.adapt);
}

TEST(GroundlinkRadioProfile, AdaptIsASwitchThatReachesTheTransport) {
    RadioProfile p;
    ASSERT_EQ(parse_radio_profile("adapt=on,buffer=2048", p), "");
    EXPECT_TRUE(p.adapt);
    TransportConfig c;
    p.apply(c, 5760.0);
    EXPECT_TRUE(c.air_adapt);
    ASSERT_EQ(parse_radio_profile("adapt=off", p), "");
    p.apply(c, 5760.0);
    EXPECT_FALSE(c.air_adapt);
    const std::string error = parse_radio_profile("adapt=sometimes", p);
    EXPECT_NE(error.find("adapt=sometimes"), std::string::npos) << error;
    EXPECT_NE(error.find("on or off"), std::string::npos) << error;
    EXPECT_NE(parse_radio_profile("colour=blue", p).find("adapt"), std::string::npos);  // listed as known
}

TEST(GroundlinkRadioProfile, ParsesEveryKey) {
    RadioProfile p;
    ASSERT_EQ(
        parse_radio_profile(
            "air_speed=64,ecc=on,packet=128,packet_overhead=8,turnaround=10ms,duplex=full,buffer=2048", p),
        "");
    EXPECT_EQ(p.air_speed_kbps, 64u);
    EXPECT_TRUE(p.ecc);
    EXPECT_EQ(p.packet_bytes, 128u);
    EXPECT_EQ(p.packet_overhead, 8u);
    EXPECT_EQ(p.turnaround, milliseconds(10));
    EXPECT_FALSE(p.half_duplex);
    EXPECT_EQ(p.buffer_bytes, 2048u);
}

TEST(GroundlinkRadioProfile, KeysComeInAnyOrderAndOnlyThoseGivenChange) {
    RadioProfile a;
    RadioProfile b;
    ASSERT_EQ(parse_radio_profile("buffer=4096,duplex=half,ecc=true,air_speed=128", a), "");
    ASSERT_EQ(parse_radio_profile("air_speed=128,ecc=true,duplex=half,buffer=4096", b), "");
    EXPECT_TRUE(same(a, b));
    EXPECT_EQ(a.packet_bytes, 252u);  // not given: as before
    EXPECT_EQ(a.turnaround, milliseconds(1));

    // Over an earlier profile, as a second --radio goes over the first.
    ASSERT_EQ(parse_radio_profile("ecc=off,turnaround=0.5ms", a), "");
    EXPECT_FALSE(a.ecc);
    EXPECT_EQ(a.air_speed_kbps, 128u);
    EXPECT_EQ(a.turnaround, std::chrono::microseconds(500));
    ASSERT_EQ(parse_radio_profile("turnaround=3", a), "");  // a bare number is milliseconds
    EXPECT_EQ(a.turnaround, milliseconds(3));
    ASSERT_EQ(parse_radio_profile("", a), "");
    EXPECT_EQ(a.turnaround, milliseconds(3));
}

TEST(GroundlinkRadioProfile, EachErrorNamesTheKeyAndLeavesTheProfileAlone) {
    struct Case {
        const char* text;
        const char* names;  // what the message must contain
    };
    const Case cases[] = {
        {"air_speed=64,colour=blue", "colour"},
        {"packet", "packet"},
        {"air_speed=64,packet", "expected KEY=VALUE"},
        {"air_speed=fast", "air_speed=fast"},
        {"air_speed=-1", "air_speed"},
        {"air_speed=99999999999", "air_speed"},
        {"air_speed=200000", "air_speed"},
        {"buffer=2k", "buffer=2k"},
        {"ecc=maybe", "ecc=maybe"},
        {"duplex=simplex", "duplex=simplex"},
        {"turnaround=soon", "turnaround=soon"},
        {"turnaround=200ms", "turnaround"},
        {"packet=0,packet_overhead=8", "packet_overhead"},
        {"packet=4", "packet"},
        {"packet_overhead=300", "packet_overhead"},
        {"buffer=10", "buffer"},
        {"adapt=maybe", "adapt=maybe"},
    };
    for (const auto& c : cases) {
        RadioProfile p;
        ASSERT_EQ(parse_radio_profile("air_speed=32,ecc=on,buffer=1024", p), "");
        const RadioProfile before = p;
        const std::string error = parse_radio_profile(c.text, p);
        EXPECT_TRUE(error.starts_with("--radio ")) << c.text << ": " << error;
        EXPECT_NE(error.find(c.names), std::string::npos) << c.text << ": " << error;
        EXPECT_TRUE(same(p, before)) << c.text;
    }
    RadioProfile p;
    EXPECT_NE(parse_radio_profile("ecc=maybe", p).find("on or off"), std::string::npos);
    EXPECT_NE(parse_radio_profile("duplex=simplex", p).find("half or full"), std::string::npos);
    EXPECT_NE(parse_radio_profile("turnaround=200ms", p).find("0..100 ms"), std::string::npos);
}

TEST(GroundlinkRadioProfile, ValidateNamesTheYamlKey) {
    RadioProfile p;
    p.packet_bytes = 0;
    p.packet_overhead = 8;
    EXPECT_TRUE(p.validate("groundlink.radio").starts_with("groundlink.radio.packet_overhead "))
        << p.validate("groundlink.radio");
    p = RadioProfile{};
    p.buffer_bytes = 10;
    EXPECT_TRUE(p.validate("groundlink.radio").starts_with("groundlink.radio.buffer "));
    p = RadioProfile{};
    p.turnaround = milliseconds(101);
    EXPECT_TRUE(p.validate("groundlink.radio").starts_with("groundlink.radio.turnaround "));
    p = RadioProfile{};
    p.packet_bytes = 4096;
    p.packet_overhead = 256;
    p.buffer_bytes = std::size_t{1} << 24;
    p.air_speed_kbps = 100'000;
    p.turnaround = milliseconds(100);
    EXPECT_EQ(p.validate("groundlink.radio"), "");  // the bounds themselves are allowed
}

TEST(GroundlinkRadioProfile, AirRateInBytesPerSecond) {
    RadioProfile p;
    EXPECT_DOUBLE_EQ(p.air_bytes_per_s(5760.0), 5760.0);  // 0: what the serial port carries
    p.air_speed_kbps = 64;
    EXPECT_DOUBLE_EQ(p.air_bytes_per_s(5760.0), 8000.0);
    p.ecc = true;
    EXPECT_DOUBLE_EQ(p.air_bytes_per_s(5760.0), 4000.0);
    p.air_speed_kbps = 0;
    EXPECT_DOUBLE_EQ(p.air_bytes_per_s(5760.0), 2880.0);
}

TEST(GroundlinkRadioProfile, ApplySetsTheTransportsAirParameters) {
    RadioProfile p;
    ASSERT_EQ(
        parse_radio_profile(
            "air_speed=64,ecc=on,packet=252,packet_overhead=8,turnaround=10ms,duplex=full,buffer=2048", p),
        "");
    TransportConfig t;
    t.link_rate_bytes_per_s = 5760.0;
    p.apply(t, 5760.0);
    EXPECT_DOUBLE_EQ(t.air_rate_bytes_per_s, 4000.0);
    EXPECT_EQ(t.air_packet_payload, 252u);
    EXPECT_EQ(t.air_packet_overhead, 8u);
    EXPECT_EQ(t.air_turnaround, milliseconds(10));
    EXPECT_FALSE(t.half_duplex);
    EXPECT_EQ(t.radio_buffer_bytes, 2048u);
    EXPECT_DOUBLE_EQ(t.link_rate_bytes_per_s, 5760.0);  // the serial port's rate stays
    EXPECT_TRUE(t.validate().empty());
}

TEST(GroundlinkRadioProfile, AnAirRateEqualToTheSerialRateIsNotSet) {
    TransportConfig t;
    RadioProfile{}.apply(t, 5760.0);
    EXPECT_EQ(t.air_rate_bytes_per_s, 0.0);
    EXPECT_EQ(t.air_packet_payload, 252u);
    EXPECT_EQ(t.air_packet_overhead, 0u);
    EXPECT_EQ(t.air_turnaround, milliseconds(1));
    EXPECT_TRUE(t.half_duplex);
    EXPECT_EQ(t.radio_buffer_bytes, 0u);

    RadioProfile p;
    p.air_speed_kbps = 64;  // 8000 B/s
    TransportConfig u;
    p.apply(u, 8000.0);
    EXPECT_EQ(u.air_rate_bytes_per_s, 0.0);
    p.apply(u, 5760.0);
    EXPECT_DOUBLE_EQ(u.air_rate_bytes_per_s, 8000.0);
}

}  // namespace
}  // namespace airseg::groundlink

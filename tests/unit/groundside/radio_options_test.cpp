// The radio options of airsegctl and airseg-ground: --radio reaches the ground end's profile, and a bad
// value is one line naming the option and the key.
#include "groundside/radio_options.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace airseg::groundside {
namespace {

using std::chrono::milliseconds;

RadioOptions parsed(const std::vector<std::string>& args) {
    RadioOptions radio;
    cli::OptionTable table;
    add_radio_options(table, radio, [] {});
    cli::parse(args, table);
    return radio;
}

std::string error_of(const std::vector<std::string>& args) {
    try {
        parsed(args);
    } catch (const cli::UsageError& e) {
        return e.what();
    }
    return "";
}

TEST(RadioOptions, RadioFillsTheProfile) {
    const auto o = parsed({"--link", "/dev/ttyUSB0", "--radio",
                           "air_speed=64,ecc=on,packet=252,packet_overhead=8,turnaround=10ms,duplex=full,"
                           "buffer=2048"});
    EXPECT_EQ(o.profile.air_speed_kbps, 64u);
    EXPECT_TRUE(o.profile.ecc);
    EXPECT_EQ(o.profile.packet_bytes, 252u);
    EXPECT_EQ(o.profile.packet_overhead, 8u);
    EXPECT_EQ(o.profile.turnaround, milliseconds(10));
    EXPECT_FALSE(o.profile.half_duplex);
    EXPECT_EQ(o.profile.buffer_bytes, 2048u);
    EXPECT_EQ(validate(o), "");
}

TEST(RadioOptions, WithoutRadioTheProfileIsTheDefault) {
    const auto o = parsed({"--link", "/dev/ttyUSB0", "--baud", "115200"});
    EXPECT_EQ(o.profile.air_speed_kbps, 0u);
    EXPECT_FALSE(o.profile.ecc);
    EXPECT_EQ(o.profile.packet_bytes, 252u);
    EXPECT_TRUE(o.profile.half_duplex);
}

TEST(RadioOptions, RepeatedRadioAddsKeysAndTheLastWins) {
    const auto o = parsed({"--radio", "air_speed=64,ecc=on", "--radio=ecc=off,buffer=4096"});
    EXPECT_EQ(o.profile.air_speed_kbps, 64u);
    EXPECT_FALSE(o.profile.ecc);
    EXPECT_EQ(o.profile.buffer_bytes, 4096u);
}

TEST(RadioOptions, BadRadioValuesNameTheOptionAndTheKey) {
    const std::pair<const char*, const char*> cases[] = {
        {"colour=blue", "colour"},
        {"air_speed", "expected KEY=VALUE"},
        {"packet=big", "packet=big"},
        {"ecc=maybe", "ecc=maybe"},
        {"duplex=simplex", "duplex"},
        {"turnaround=200ms", "turnaround"},
        {"packet=0,packet_overhead=8", "packet_overhead"},
        {"buffer=10", "buffer"},
    };
    for (const auto& [text, names] : cases) {
        const auto error = error_of({"--radio", text});
        EXPECT_TRUE(error.starts_with("--radio ")) << text << ": " << error;
        EXPECT_NE(error.find(names), std::string::npos) << text << ": " << error;
    }
}

// A UDP link has no radio to describe: --radio with it is a mistake said at once, not ignored.
TEST(RadioOptions, RadioWithUdpIsRefused) {
    EXPECT_EQ(validate(parsed({"--udp", "127.0.0.1:14660"})), "");
    EXPECT_EQ(validate(parsed({"--udp", "127.0.0.1:14660", "--radio", "air_speed=64"})),
              "--radio describes serial radios; it does not apply to --udp");
    EXPECT_EQ(validate(parsed({"--link", "/dev/ttyUSB0", "--radio", "air_speed=64"})), "");
}

TEST(RadioOptions, HelpListsRadio) {
    RadioOptions radio;
    cli::OptionTable table;
    add_radio_options(table, radio, [] {});
    const auto help = cli::describe(table);
    EXPECT_NE(help.find("--radio KEY=VALUE[,...]"), std::string::npos) << help;
    EXPECT_NE(help.find("groundlink.radio"), std::string::npos) << help;
}

}  // namespace
}  // namespace airseg::groundside

#include <gtest/gtest.h>

#include "cli/values.hpp"
#include "tools/linksim/control.hpp"
#include "tools/linksim/options.hpp"

namespace airseg::linksim {
namespace {

using cli::UsageError;

LinkSimOptions parse(std::vector<std::string> extra) {
    std::vector<std::string> args{"--a", "/tmp/x/a", "--b", "/tmp/x/b"};
    args.insert(args.end(), extra.begin(), extra.end());
    auto o = parse_options(args);
    if (!o) {
        throw std::logic_error("help");
    }
    return *o;
}

std::string error_of(std::vector<std::string> extra) {
    try {
        parse(std::move(extra));
    } catch (const UsageError& e) {
        return e.what();
    }
    return "";
}

TEST(LinkSimOptions, DefaultsMatchASikPairAt57600) {
    const auto o = parse({});
    EXPECT_EQ(o.radio.baud, 57600u);
    EXPECT_EQ(o.radio.duplex, Duplex::Half);
    EXPECT_EQ(o.radio.max_air_packet, 252u);
    EXPECT_EQ(o.radio.impairment[0].byte_loss, 0.0);
}

TEST(LinkSimOptions, DirectionalVariantsApplyToOneDirection) {
    const auto o = parse({"--loss", "0.1", "--loss-ba", "0.3", "--frame-loss-ab", "0.2", "--outage", "5:2.5",
                          "--outage-ab", "60:30", "--latency", "40", "--full-duplex", "--seed", "9"});
    EXPECT_EQ(o.radio.impairment[index(Side::A)].byte_loss, 0.1);
    EXPECT_EQ(o.radio.impairment[index(Side::B)].byte_loss, 0.3);
    EXPECT_EQ(o.radio.impairment[index(Side::A)].frame_loss, 0.2);
    EXPECT_EQ(o.radio.impairment[index(Side::B)].frame_loss, 0.0);
    ASSERT_EQ(o.radio.impairment[index(Side::A)].outages.size(), 2u);
    ASSERT_EQ(o.radio.impairment[index(Side::B)].outages.size(), 1u);
    EXPECT_EQ(o.radio.impairment[index(Side::A)].outages[1].start, seconds(60));
    EXPECT_EQ(o.radio.impairment[index(Side::B)].outages[0].length, milliseconds(2500));
    EXPECT_EQ(o.radio.impairment[index(Side::B)].latency, milliseconds(40));
    EXPECT_EQ(o.radio.duplex, Duplex::Full);
    EXPECT_EQ(o.radio.seed, 9u);
}

TEST(LinkSimOptions, UsbLatencySetsBothAdaptersOrOne) {
    auto o = parse({"--usb-latency", "16"});
    EXPECT_EQ(o.radio.usb_latency[index(Side::A)], milliseconds(16));
    EXPECT_EQ(o.radio.usb_latency[index(Side::B)], milliseconds(16));
    o = parse({"--usb-latency-a", "4", "--usb-packet", "30"});
    EXPECT_EQ(o.radio.usb_latency[index(Side::A)], milliseconds(4));
    EXPECT_EQ(o.radio.usb_latency[index(Side::B)], Duration::zero());
    EXPECT_EQ(o.radio.usb_packet, 30u);
    EXPECT_EQ(parse({}).radio.usb_latency[index(Side::A)], Duration::zero()) << "no adapter unless asked";
    EXPECT_NE(error_of({"--usb-latency", "300"}).find("usb_latency"), std::string::npos);
}

TEST(LinkSimOptions, BadInputNamesTheOption) {
    EXPECT_NE(error_of({"--loss", "1.5"}).find("--loss"), std::string::npos);
    EXPECT_NE(error_of({"--ber-ab", "x"}).find("--ber-ab"), std::string::npos);
    EXPECT_NE(error_of({"--baud", "12"}).find("--baud"), std::string::npos);
    EXPECT_NE(error_of({"--outage", "10"}).find("START:DURATION"), std::string::npos);
    EXPECT_NE(error_of({"--outage", "10:0"}).find("positive"), std::string::npos);
    EXPECT_NE(error_of({"--wobble"}).find("--wobble"), std::string::npos);
    EXPECT_NE(error_of({"--latency"}).find("missing value"), std::string::npos);
    EXPECT_THROW(parse_options({"--a", "/tmp/same", "--b", "/tmp/same"}), UsageError);
    EXPECT_THROW(parse_options({"--a", "/tmp/only"}), UsageError);
    EXPECT_FALSE(parse_options({"--help"}));
}

TEST(LinkSimControl, CommandsChangeTheModelAndBadOnesChangeNothing) {
    RadioModel model(RadioConfig{}, TimePoint{});
    EXPECT_EQ(apply_control(model, "loss 0.25 ab", TimePoint{}), "ok loss 0.25 ab");
    EXPECT_EQ(model.impairment(Side::A).byte_loss, 0.25);
    EXPECT_EQ(model.impairment(Side::B).byte_loss, 0.0);
    EXPECT_EQ(apply_control(model, "frame-loss 0.5", TimePoint{}).rfind("ok", 0), 0u);
    EXPECT_EQ(model.impairment(Side::B).frame_loss, 0.5);
    EXPECT_EQ(apply_control(model, "latency 12 ba", TimePoint{}).rfind("ok", 0), 0u);
    EXPECT_EQ(model.impairment(Side::B).latency, milliseconds(12));

    EXPECT_EQ(apply_control(model, "loss 7", TimePoint{}).rfind("error", 0), 0u);
    EXPECT_EQ(model.impairment(Side::A).byte_loss, 0.25);
    EXPECT_EQ(apply_control(model, "loss 0.1 sideways", TimePoint{}).rfind("error", 0), 0u);
    EXPECT_EQ(apply_control(model, "down c", TimePoint{}).rfind("error", 0), 0u);
    EXPECT_EQ(apply_control(model, "", TimePoint{}).rfind("error", 0), 0u);

    EXPECT_EQ(apply_control(model, "down a", TimePoint{}), "ok radio a down");
    EXPECT_TRUE(model.radio_down(Side::A));
    EXPECT_EQ(apply_control(model, "up a", TimePoint{}), "ok radio a up");
    EXPECT_FALSE(model.radio_down(Side::A));
}

TEST(LinkSimControl, OutageStartsNowAndEnds) {
    RadioConfig c;
    c.duplex = Duplex::Full;
    RadioModel model(c, TimePoint{});
    const TimePoint t1 = TimePoint{} + seconds(1);
    EXPECT_EQ(apply_control(model, "outage 2 ab", t1).rfind("ok", 0), 0u);
    const std::vector<std::uint8_t> bytes(10, 0x55);
    model.push(Side::A, bytes, t1);
    EXPECT_TRUE(model.poll_output(Side::B, t1 + seconds(1)).empty());
    model.push(Side::A, bytes, t1 + seconds(2) + milliseconds(1));
    EXPECT_EQ(model.poll_output(Side::B, t1 + seconds(3)).size(), 10u);
}

}  // namespace
}  // namespace airseg::linksim

// RoverSim's banner (tools/apmsim/banner.hpp): what current ArduPilot sends on every parameter list request,
// before the parameters, and on MAV_CMD_DO_SEND_BANNER.
#include <gtest/gtest.h>

#include "services/autopilot/mavlink/enums.hpp"
#include "tests/integration/apmsim/sim_harness.hpp"
#include "tools/apmsim/banner.hpp"

namespace airseg::apmsim::test {
namespace {

/// The texts received from `from` on, up to the first PARAM_VALUE.
std::vector<std::string> texts_before_parameters(const SimHarness& h, std::size_t from) {
    std::vector<std::string> texts;
    for (std::size_t i = from; i < h.received.size(); ++i) {
        if (mv::decode<mv::ParamValue>(h.received[i].frame)) {
            break;
        }
        if (const auto t = mv::decode<mv::Statustext>(h.received[i].frame)) {
            EXPECT_EQ(t->severity, mavlink::kSeverityInfo);
            texts.emplace_back(mv::text_of(t->text));
        }
    }
    return texts;
}

std::vector<std::string> banner() {
    std::vector<std::string> lines;
    for (const auto l : firmware_banner()) {
        lines.emplace_back(l);
    }
    return lines;
}

TEST(ApmsimBanner, EveryParameterListStartsWithTheBanner) {
    SimHarness h;
    h.boot();
    ASSERT_EQ(banner().size(), 4u);
    EXPECT_TRUE(banner().front().starts_with("ArduRover V4."));
    for (int request = 0; request < 3; ++request) {
        const std::size_t from = h.received.size();
        h.send(mv::ParamRequestList{});
        h.run_for(seconds(1));
        EXPECT_EQ(texts_before_parameters(h, from), banner()) << "request " << request;
        EXPECT_GE(h.all<mv::ParamValue>(from).size(), 200u);
    }
    // A parameter read brings no banner.
    const std::size_t from = h.received.size();
    mv::ParamRequestRead read;
    read.param_index = -1;
    mv::set_text(read.param_id, "WP_RADIUS");
    h.send(read);
    h.run_for(seconds(1));
    EXPECT_TRUE(h.all<mv::Statustext>(from).empty());
}

TEST(ApmsimBanner, SendBannerCommandSendsItAndIsAccepted) {
    SimHarness h;
    h.boot();
    const std::size_t from = h.received.size();
    mv::CommandLong c;
    c.command = kCmdDoSendBanner;
    h.send(c);
    const auto ack = h.wait_for<mv::CommandAck>(seconds(1), from);
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->command, kCmdDoSendBanner);
    EXPECT_EQ(ack->result, mavlink::kResultAccepted);
    EXPECT_EQ(texts_before_parameters(h, from), banner());
}

TEST(ApmsimBanner, Rover2SendsNone) {
    SimHarness h(RoverSimConfig::for_firmware(Firmware::Rover2));
    h.gcs.set_version(mv::Version::V1);  // the 2.x board reads MAVLink 1 only
    h.boot();
    const std::size_t from = h.received.size();
    h.send(mv::ParamRequestList{});
    h.run_for(seconds(1));
    EXPECT_TRUE(texts_before_parameters(h, from).empty());
    EXPECT_FALSE(h.all<mv::ParamValue>(from).empty());
}

}  // namespace
}  // namespace airseg::apmsim::test

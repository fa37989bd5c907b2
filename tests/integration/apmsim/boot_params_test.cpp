// RoverSim in simulated time: boot sequence, heartbeats, parameters, streams, reboots.
#include <gtest/gtest.h>

#include "tests/integration/apmsim/sim_harness.hpp"

namespace airseg::apmsim::test {
namespace {

TEST(ApmsimBoot, SilentThenCalibratingThenReady) {
    RoverSimConfig c;
    c.boot_delay = seconds(2);
    c.calib_time = seconds(3);
    SimHarness h(c);
    h.run_for(milliseconds(1900));
    EXPECT_TRUE(h.received.empty()) << "the board says nothing while it boots";

    auto hb = h.wait_for<mv::Heartbeat>(seconds(1));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->type, 10);
    EXPECT_EQ(hb->autopilot, 3);
    EXPECT_EQ(hb->system_status, 2) << "initialising: MAV_STATE_CALIBRATING (Rover sends no BOOT)";
    EXPECT_EQ(hb->custom_mode, 16u) << "INITIALISING";
    EXPECT_EQ(h.received.front().frame.sysid, 1);
    EXPECT_EQ(h.received.front().frame.compid, 1);
    EXPECT_EQ(h.received.front().frame.version, mv::Version::V2);
    ASSERT_TRUE(h.last<mv::Statustext>());
    EXPECT_EQ(mv::text_of(h.all<mv::Statustext>().front().text), "Initialising APM...");

    hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->system_status, 2) << "still MAV_STATE_CALIBRATING";
    EXPECT_FALSE(hb->base_mode & 128) << "never armed while initialising";

    ASSERT_TRUE(h.wait_text("Ready to drive.", seconds(3)));
    EXPECT_GE(h.now - kStart, seconds(5));
    hb = h.wait_for<mv::Heartbeat>(seconds(2));
    ASSERT_TRUE(hb);
    EXPECT_EQ(hb->custom_mode, 0u) << "INITIAL_MODE is MANUAL";
    EXPECT_EQ(hb->system_status, 4) << "MANUAL: ACTIVE, armed or not";
    EXPECT_TRUE(hb->base_mode & 1) << "custom mode enabled";
    EXPECT_FALSE(hb->base_mode & 128) << "ARMING_REQUIRE 1: disarmed until armed";
    EXPECT_FALSE(h.sim.state().armed);
}

TEST(ApmsimBoot, HeartbeatsAtOneHertz) {
    SimHarness h;
    h.boot();
    const std::size_t from = h.received.size();
    h.run_for(seconds(10));
    const auto n = h.all<mv::Heartbeat>(from).size();
    EXPECT_GE(n, 9u);
    EXPECT_LE(n, 11u);
}

TEST(ApmsimBoot, PortOpenRebootsUnlessDisabled) {
    SimHarness h;
    h.boot();
    h.sim.port_opened(h.now);
    EXPECT_EQ(h.sim.state().phase, BootPhase::Silent);
    EXPECT_EQ(h.sim.state().boots, 2u);

    RoverSimConfig c;
    c.reset_on_open = false;
    SimHarness p(c);
    p.boot();
    p.sim.port_opened(p.now);
    EXPECT_EQ(p.sim.state().phase, BootPhase::Ready);
}

TEST(ApmsimBoot, MavlinkOneWhenAsked) {
    RoverSimConfig c;
    c.version = mv::Version::V1;
    SimHarness h(c);
    ASSERT_TRUE(h.wait_for<mv::Heartbeat>(seconds(5)));
    EXPECT_EQ(h.received.back().frame.version, mv::Version::V1);
}

TEST(ApmsimParams, ListHasOverTwoHundredRealNames) {
    SimHarness h;
    h.boot();
    const std::size_t from = h.received.size();
    h.send(mv::ParamRequestList{});
    h.run_for(seconds(1));
    const auto values = h.all<mv::ParamValue>(from);
    ASSERT_GE(values.size(), 200u);
    EXPECT_EQ(values.size(), values.front().param_count);
    std::set<std::string> names;
    for (const auto& v : values) {
        names.insert(std::string(mv::text_of(v.param_id)));
    }
    EXPECT_EQ(names.size(), values.size()) << "names are unique";
    for (const char* n :
         {"WP_RADIUS", "CRUISE_SPEED", "SYSID_THISMAV", "SR0_POSITION", "RC3_TRIM", "MODE1"}) {
        EXPECT_TRUE(names.count(n)) << n;
    }
}

TEST(ApmsimParams, ReadSetEchoAndKeptAcrossReboot) {
    SimHarness h;
    h.boot();
    mv::ParamSet s;
    mv::set_text(s.param_id, "CRUISE_SPEED");
    s.param_value = 3.5F;
    s.param_type = 9;
    std::size_t from = h.received.size();
    h.send(s);
    auto echo = h.last<mv::ParamValue>(from);
    ASSERT_TRUE(echo);
    EXPECT_EQ(mv::text_of(echo->param_id), "CRUISE_SPEED");
    EXPECT_FLOAT_EQ(echo->param_value, 3.5F);

    mv::ParamSet unknown;
    mv::set_text(unknown.param_id, "NO_SUCH_PARAM");
    from = h.received.size();
    h.send(unknown);
    h.run_for(milliseconds(100));
    EXPECT_TRUE(h.all<mv::ParamValue>(from).empty()) << "an unknown name gets no answer";

    mv::ParamSet integer;
    mv::set_text(integer.param_id, "WP_RADIUS");
    integer.param_value = 4.0F;
    h.send(integer);

    h.sim.reboot(h.now);
    h.boot();
    mv::ParamRequestRead r;
    mv::set_text(r.param_id, "CRUISE_SPEED");
    r.param_index = -1;
    from = h.received.size();
    h.send(r);
    auto v = h.last<mv::ParamValue>(from);
    ASSERT_TRUE(v);
    EXPECT_FLOAT_EQ(v->param_value, 3.5F);

    mv::ParamRequestRead by_index;
    by_index.param_index = static_cast<std::int16_t>(v->param_index);
    from = h.received.size();
    h.send(by_index);
    v = h.last<mv::ParamValue>(from);
    ASSERT_TRUE(v);
    EXPECT_EQ(mv::text_of(v->param_id), "CRUISE_SPEED");
}

TEST(ApmsimStreams, RequestDataStreamAndMessageInterval) {
    SimHarness h;
    h.boot();
    std::size_t from = h.received.size();
    h.run_for(seconds(2));
    EXPECT_TRUE(h.all<mv::GlobalPositionInt>(from).empty()) << "no streams until asked";

    mv::RequestDataStream r;
    r.req_stream_id = 6;  // POSITION
    r.req_message_rate = 5;
    r.start_stop = 1;
    h.send(r);
    from = h.received.size();
    h.run_for(seconds(2));
    const auto n = h.all<mv::GlobalPositionInt>(from).size();
    EXPECT_GE(n, 9u);
    EXPECT_LE(n, 11u);

    mv::CommandLong c;
    c.command = 511;
    c.param1 = static_cast<float>(mv::VfrHud::kId);
    c.param2 = 100000;  // 10 Hz
    h.send(c);
    auto ack = h.last<mv::CommandAck>();
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->command, 511);
    EXPECT_EQ(ack->result, 0);
    from = h.received.size();
    h.run_for(seconds(1));
    EXPECT_GE(h.all<mv::VfrHud>(from).size(), 9u);

    // The group rate is stored in SR0_POSITION, so it comes back after a reboot.
    h.sim.reboot(h.now);
    h.boot();
    from = h.received.size();
    h.run_for(seconds(1));
    EXPECT_GE(h.all<mv::GlobalPositionInt>(from).size(), 4u);
}

TEST(ApmsimStreams, SystemTimeRestartsAtReboot) {
    SimHarness h;
    h.boot();
    mv::RequestDataStream r;
    r.req_stream_id = 12;  // EXTRA3
    r.req_message_rate = 2;
    r.start_stop = 1;
    h.send(r);
    h.run_for(seconds(20));
    auto t = h.last<mv::SystemTime>();
    ASSERT_TRUE(t);
    EXPECT_GT(t->time_boot_ms, 20000u);
    h.sim.reboot(h.now);
    const std::size_t from = h.received.size();
    h.boot();
    h.run_for(seconds(1));
    t = h.last<mv::SystemTime>(from);
    ASSERT_TRUE(t);
    EXPECT_LT(t->time_boot_ms, 8000u);
    auto b = h.last<mv::BatteryStatus>(from);
    ASSERT_TRUE(b);
    EXPECT_GT(b->current_consumed, 0);
}

TEST(ApmsimModes, SetModeCommandAndHistory) {
    SimHarness h;
    ASSERT_TRUE(h.run_until([&] { return h.sim.state().phase == BootPhase::Calibrating; }, seconds(5)));
    h.set_mode(RoverMode::Hold);
    auto ack = h.last<mv::CommandAck>();
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->result, 1) << "TEMPORARILY_REJECTED while calibrating";
    h.boot();
    h.set_mode(RoverMode::Hold);
    ack = h.last<mv::CommandAck>();
    ASSERT_TRUE(ack);
    EXPECT_EQ(ack->command, 176);
    EXPECT_EQ(ack->result, 0);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Hold);

    h.set_mode(RoverMode::Auto);
    EXPECT_EQ(h.last<mv::CommandAck>()->result, 4) << "AUTO without a mission fails";

    mv::SetMode sm;
    sm.base_mode = 1;
    sm.custom_mode = 3;  // STEERING
    h.send(sm);
    EXPECT_EQ(h.sim.state().mode, RoverMode::Steering);
    ASSERT_TRUE(h.sim.rc_pilot(RoverMode::Manual, h.now));

    const auto& hist = h.sim.mode_history();
    ASSERT_EQ(hist.size(), 4u);
    EXPECT_EQ(hist[0].cause, "power on");
    EXPECT_EQ(hist[0].to, RoverMode::Manual);
    EXPECT_EQ(hist[1].cause, "command");
    EXPECT_EQ(hist[1].to, RoverMode::Hold);
    EXPECT_EQ(hist[2].to, RoverMode::Steering);
    EXPECT_EQ(hist[3].cause, "rc pilot");
    h.sim.reboot(h.now);
    EXPECT_EQ(h.sim.mode_history().back().cause, "reboot");
}

TEST(ApmsimModes, RcOverrideDrivesInManual) {
    SimHarness h;
    h.boot_armed();
    const GeoPoint start = h.sim.state().position;
    mv::RcChannelsOverride o;
    o.chan1_raw = 1500;
    o.chan3_raw = 1700;  // half forward
    for (int i = 0; i < 10; ++i) {
        h.send(o);
        h.run_for(milliseconds(500));
    }
    const auto s = h.sim.state();
    EXPECT_GT(s.speed, 1.0);
    EXPECT_GT(distance_m(start, s.position), 5.0);
    // Released: sticks back to trim, the car stops.
    o.chan1_raw = 0;
    o.chan3_raw = 0;
    h.send(o);
    h.run_for(seconds(5));
    EXPECT_NEAR(h.sim.state().speed, 0.0, 1e-9);
}

}  // namespace
}  // namespace airseg::apmsim::test

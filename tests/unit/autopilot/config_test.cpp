// Configuration validation, the Rover mode table, the mission item codec and the RC override core.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "services/autopilot/ardupilot/mission_codec.hpp"
#include "services/autopilot/ardupilot/rc_override.hpp"
#include "services/autopilot/ardupilot/rover_modes.hpp"
#include "services/autopilot/autopilot_config.hpp"

namespace airseg::autopilot {
namespace {

bool mentions(const std::vector<std::string>& problems, const std::string& key) {
    return std::any_of(problems.begin(), problems.end(),
                       [&](const std::string& p) { return p.find(key) != std::string::npos; });
}

TEST(AutopilotConfig, BoardDefaultsAreValid) {
    EXPECT_TRUE(AutopilotConfig::validate(AutopilotConfig{}).empty());
    const auto apm = AutopilotConfig::defaults_for(Board::Apm2);
    EXPECT_TRUE(AutopilotConfig::validate(apm).empty());
    EXPECT_TRUE(apm.reset_on_open);
    EXPECT_EQ(apm.mavlink_version, 1);
    EXPECT_FALSE(apm.use_message_interval);
    const auto px = AutopilotConfig::defaults_for(Board::Pixhawk);
    EXPECT_TRUE(AutopilotConfig::validate(px).empty());
    EXPECT_FALSE(px.reset_on_open);
    EXPECT_TRUE(px.use_message_interval);
}

TEST(AutopilotConfig, EveryProblemNamesItsKey) {
    AutopilotConfig c;
    c.bauds = {12345};
    c.heartbeat_timeout = milliseconds(10);
    c.mavlink_version = 3;
    c.target_sysid = 0;
    c.params = {{"WAY_TOO_LONG_PARAMETER_NAME", 1}, {"A", 1}, {"A", 2}};
    c.mission.min_timeout = seconds(2);
    c.mission.max_timeout = seconds(1);
    c.rc_override.steering_channel = 3;
    c.rc_override.pwm_min = 1600;
    const auto p = AutopilotConfig::validate(c);
    for (const char* key : {"autopilot.bauds", "autopilot.heartbeat_timeout", "autopilot.mavlink_version",
                            "autopilot.target_sysid", "autopilot.params", "autopilot.mission.max_timeout",
                            "autopilot.rc_override"}) {
        EXPECT_TRUE(mentions(p, key)) << key;
    }
    EXPECT_TRUE(mentions(p, "given twice"));
    EXPECT_TRUE(mentions(p, "same channel"));
}

using ardupilot::RoverMode;
using ardupilot::state_for;

TEST(RoverModes, StatesFromHeartbeats) {
    auto m = [](RoverMode r) { return static_cast<std::uint32_t>(r); };
    EXPECT_EQ(state_for(m(RoverMode::Hold), false, false, false), VehicleState::Parking);
    EXPECT_EQ(state_for(m(RoverMode::Manual), false, false, false), VehicleState::Directed);
    EXPECT_EQ(state_for(m(RoverMode::Manual), false, true, false), VehicleState::ManualNavigation);
    EXPECT_EQ(state_for(m(RoverMode::Auto), false, false, false), VehicleState::WaypointNavigation);
    EXPECT_EQ(state_for(m(RoverMode::Auto), true, false, false), VehicleState::ConfigureCheck);
    EXPECT_EQ(state_for(m(RoverMode::Initialising), false, false, false), VehicleState::ConfigureCheck);
    EXPECT_EQ(state_for(m(RoverMode::Hold), false, false, true), VehicleState::Manual);
    EXPECT_EQ(state_for(m(RoverMode::Rtl), false, false, false), VehicleState::Unknown);
    EXPECT_EQ(ardupilot::rover_mode_name(10), "AUTO");
    EXPECT_EQ(ardupilot::rover_mode_name(99), "MODE(99)");
    EXPECT_STREQ(ardupilot::rover_mode_known_name(4), "HOLD");
    EXPECT_EQ(ardupilot::rover_mode_known_name(99), nullptr);
}

TEST(RoverModes, TransitionTable) {
    using ardupilot::transition_refusal;
    EXPECT_FALSE(transition_refusal(VehicleState::Parking, VehicleState::WaypointNavigation));
    EXPECT_FALSE(transition_refusal(VehicleState::WaypointNavigation, VehicleState::ManualNavigation));
    EXPECT_FALSE(transition_refusal(VehicleState::ConfigureCheck, VehicleState::Manual));
    EXPECT_FALSE(transition_refusal(VehicleState::Manual, VehicleState::Manual));
    EXPECT_TRUE(transition_refusal(VehicleState::Manual, VehicleState::Parking));
    EXPECT_TRUE(transition_refusal(VehicleState::ConfigureCheck, VehicleState::Parking));
    EXPECT_TRUE(transition_refusal(VehicleState::Parking, VehicleState::ConfigureCheck));
    EXPECT_TRUE(transition_refusal(VehicleState::Parking, VehicleState::Unknown));
    for (auto s : {VehicleState::Parking, VehicleState::Manual, VehicleState::WaypointNavigation}) {
        EXPECT_EQ(vehicle_state_from_string(to_string(s)), s);
    }
}

TEST(MissionCodec, RoundTripsEveryKind) {
    MissionItem wp;
    wp.lat = 41.2756789;
    wp.lon = -1.9866123;
    wp.alt = 3.5;
    wp.radius = 2.0;
    wp.hold_s = 5.0;
    MissionItem stop = wp;
    stop.kind = MissionItem::Kind::Stop;
    stop.radius.reset();
    stop.hold_s.reset();
    MissionItem jump;
    jump.kind = MissionItem::Kind::JumpTo;
    jump.jump_slot = 7;
    for (const auto& item : {wp, stop, jump}) {
        const auto wire = ardupilot::encode_item(item);
        const auto back = ardupilot::decode_item(wire);
        EXPECT_EQ(back.kind, item.kind);
        EXPECT_NEAR(back.lat, item.lat, 1e-7);
        EXPECT_NEAR(back.lon, item.lon, 1e-7);
        EXPECT_EQ(back.radius, item.radius);
        EXPECT_EQ(back.hold_s, item.hold_s);
        EXPECT_EQ(back.jump_slot, item.jump_slot);
    }
    EXPECT_EQ(ardupilot::encode_item(jump).param2, -1.0f);  // forever
    EXPECT_EQ(ardupilot::encode_item(stop).command, 17);
    // A board without NAV_LOITER_UNLIM: a jump past the end, read back as a Stop.
    const auto as_jump = ardupilot::encode_item(stop, true);
    EXPECT_EQ(as_jump.command, 177);
    EXPECT_EQ(as_jump.param1, 255.0f);
    EXPECT_EQ(ardupilot::decode_item(as_jump).kind, MissionItem::Kind::Stop);
}

TEST(RcOverride, ScalesAndClampsAndNeverSendsWithoutInput) {
    RcOverrideConfig c;
    ardupilot::RcOverride rc(c, 1, 1);
    const TimePoint t0 = TimePoint{} + seconds(100);
    rc.set_enabled(true, t0);
    EXPECT_FALSE(rc.poll(t0));  // enabled but no joystick yet: nothing
    rc.set_input(-2.0, std::nan(""), t0);
    auto m = rc.poll(t0);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->chan1_raw, c.pwm_min);            // clamped to -1
    EXPECT_EQ(m->chan3_raw, c.pwm_trim);           // NaN reads as centre
    EXPECT_EQ(m->chan2_raw, 0);                    // untouched channels stay with the RC receiver
    EXPECT_FALSE(rc.poll(t0 + milliseconds(50)));  // not before the next period
    // Disabled while driving: released at once, release_repeats times.
    rc.set_enabled(false, t0 + milliseconds(60));
    int releases = 0;
    for (TimePoint t = t0 + milliseconds(60); t < t0 + seconds(2); t += milliseconds(10)) {
        if (auto r = rc.poll(t)) {
            EXPECT_EQ(r->chan1_raw, 0);
            ++releases;
        }
    }
    EXPECT_EQ(releases, static_cast<int>(c.release_repeats));
    EXPECT_EQ(rc.poll_timeout(), kNever);
}

}  // namespace
}  // namespace airseg::autopilot

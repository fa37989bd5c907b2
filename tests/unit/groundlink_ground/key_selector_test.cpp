#include "services/groundlink/key_selector.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "services/groundlink/telemetry_sample.hpp"

namespace airseg::groundlink {
namespace {

TEST(KeySelector, WithoutAMonitorKeyEveryoneIsControlAndNothingSwitches) {
    KeySelector k(false);
    EXPECT_EQ(k.role(), Role::Control);
    EXPECT_FALSE(k.update(false, 10, 0));
    EXPECT_EQ(k.role(), Role::Control);
}

TEST(KeySelector, SwitchesKeysWhileFramesOnlyFailTheirMac) {
    KeySelector k(true);
    EXPECT_EQ(k.role(), Role::Control);
    EXPECT_FALSE(k.update(false, 0, 0)) << "silence is no evidence";
    EXPECT_FALSE(k.update(false, 2, 0)) << "one tick may be a session the vehicle just restarted";
    EXPECT_FALSE(k.update(false, 0, 1)) << "a valid frame clears the suspicion";
    EXPECT_FALSE(k.update(false, 2, 0));
    EXPECT_TRUE(k.update(false, 2, 0));
    EXPECT_EQ(k.role(), Role::Monitor);
    EXPECT_FALSE(k.update(false, 0, 3)) << "frames pass with the monitor key: stay";
    EXPECT_FALSE(k.update(true, 5, 10)) << "a link that is up is never dropped for stray frames";
    EXPECT_EQ(k.role(), Role::Monitor);
    EXPECT_FALSE(k.update(false, 3, 0));
    EXPECT_TRUE(k.update(false, 3, 0)) << "the control station came back";
    EXPECT_EQ(k.role(), Role::Control);
    EXPECT_EQ(k.switches(), 2u);
}

TEST(TelemetrySample, CarriesTheVehicleStateInWireUnits) {
    autopilot::Telemetry t;
    t.position = autopilot::Position{41.2756, 1.9866, 15.5};
    t.roll = 10 * std::numbers::pi / 180;
    t.pitch = -3 * std::numbers::pi / 180;
    t.ground_speed = 1.25;
    t.heading = 90.5;
    t.gps_fix = autopilot::GpsFix::Fix3D;
    t.satellites = 22;
    t.battery_voltage = 12.6;
    t.battery_remaining = 80;
    t.mode = "MANUAL";
    t.state = autopilot::VehicleState::ManualNavigation;
    const auto s = make_sample(t);
    EXPECT_DOUBLE_EQ(s.lat_deg, 41.2756);
    EXPECT_EQ(s.roll_deg, 10);
    EXPECT_EQ(s.pitch_deg, -3);
    EXPECT_EQ(s.gps_fix, 3);
    EXPECT_EQ(s.satellites, 15) << "capped to the nibble";
    EXPECT_EQ(s.mode, 0);
    EXPECT_STREQ(protocol::vehicle_state_name(s.vehicle_state), "MANUAL_NAVIGATION");
    EXPECT_EQ(s.battery_pct, 80);

    autopilot::Telemetry none;
    none.mode = "MODE(42)";
    EXPECT_EQ(make_sample(none).mode, 42);
    EXPECT_EQ(make_sample(none).lat_deg, 0.0);
    none.mode = "";
    EXPECT_EQ(make_sample(none).mode, protocol::kModeUnknown);
}

}  // namespace
}  // namespace airseg::groundlink

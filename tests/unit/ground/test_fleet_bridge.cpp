// The vehicle id becomes a topic level: nothing that MQTT treats specially (/, +, #) or that a broker's ACL
// patterns would read differently may pass.
#include <gtest/gtest.h>

#include "ground/fleet_bridge.hpp"

namespace airseg::ground {
namespace {

TEST(FleetVehicleId, LettersDigitsUnderscoreAndDashUpTo64) {
    EXPECT_TRUE(valid_vehicle_id("rover1"));
    EXPECT_TRUE(valid_vehicle_id("Boat_7-b"));
    EXPECT_TRUE(valid_vehicle_id(std::string(64, 'a')));
    EXPECT_FALSE(valid_vehicle_id(""));
    EXPECT_FALSE(valid_vehicle_id(std::string(65, 'a')));
    for (const char* bad : {"a/b", "+", "#", "rover 1", "rövér", "a.b", "%u"}) {
        EXPECT_FALSE(valid_vehicle_id(bad)) << bad;
    }
}

}  // namespace
}  // namespace airseg::ground

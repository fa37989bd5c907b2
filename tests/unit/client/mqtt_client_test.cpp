// airsegctl --mqtt reads back the fleet bridge's JSON: a telemetry sample survives the round trip, and the
// broker address and vehicle id are checked before anything connects.
#include <gtest/gtest.h>

#include "client/mqtt_client.hpp"
#include "groundside/mqtt_options.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::client {
namespace {

using groundside::check_vehicle_id;
using groundside::MqttOptions;
using groundside::parse_broker;
using groundside::telemetry_json;
using groundside::vehicle_topic;

TEST(MqttClient, TelemetryJsonRoundTrips) {
    groundlink::protocol::Telemetry t;
    t.lat_deg = 41.2756123;
    t.lon_deg = 1.9866456;
    t.alt_m = 12.5;
    t.ground_speed_mps = 1.25;
    t.heading_deg = 271.5;
    t.roll_deg = -3;
    t.pitch_deg = 2;
    t.battery_v = 12.345;
    t.battery_pct = 87;
    t.gps_fix = 3;
    t.satellites = 11;
    t.vehicle_state = 3;
    t.mode = 10;  // AUTO
    t.plan_state = 2;
    t.plan_element = 7;
    t.next_waypoint = 42;
    const auto back = telemetry_from_json(telemetry_json(t));
    ASSERT_TRUE(back);
    EXPECT_EQ(*back, t);

    t.battery_pct.reset();
    t.plan_state = 0;
    t.plan_element = 0;
    t.next_waypoint = 0;
    t.mode = groundlink::protocol::kModeUnknown;
    EXPECT_EQ(telemetry_from_json(telemetry_json(t)), t);
}

TEST(MqttClient, ASampleWithoutAFixIsPublishedWithoutAPlace) {
    groundlink::protocol::Telemetry t;
    t.no_position = true;  // the daemon sends 0,0 with it
    t.gps_fix = 1;
    t.battery_v = 12.1;
    const auto j = telemetry_json(t);
    EXPECT_TRUE(j["lat"].is_null()) << j.dump();
    EXPECT_TRUE(j["lon"].is_null()) << j.dump();
    EXPECT_EQ(j["position_valid"], false);
    EXPECT_EQ(telemetry_from_json(j), t);
    // A null place is a sample only when it says it has none.
    auto unsaid = j;
    unsaid.erase("position_valid");
    EXPECT_FALSE(telemetry_from_json(unsaid));
}

TEST(MqttClient, WhatIsNotASampleIsNone) {
    EXPECT_FALSE(telemetry_from_json(nlohmann::json::object()));
    EXPECT_FALSE(telemetry_from_json(nlohmann::json{{"lat", "north"}}));
    EXPECT_FALSE(telemetry_from_json(nlohmann::json::array()));
}

TEST(MqttOptions, BrokerAddresses) {
    MqttOptions o;
    EXPECT_EQ(parse_broker("broker.example", o), "");
    EXPECT_EQ(o.host, "broker.example");
    EXPECT_EQ(o.port, 1883);
    EXPECT_EQ(parse_broker("10.0.0.2:8883", o), "");
    EXPECT_EQ(o.host, "10.0.0.2");
    EXPECT_EQ(o.port, 8883);
    EXPECT_NE(parse_broker("host:0", o), "");
    EXPECT_NE(parse_broker("host:70000", o), "");
    EXPECT_NE(parse_broker(":1883", o), "");
    EXPECT_NE(parse_broker("", o), "");
}

TEST(MqttOptions, VehicleIdsFitOneTopicLevel) {
    EXPECT_EQ(check_vehicle_id("rover-1_B"), "");
    EXPECT_NE(check_vehicle_id(""), "");
    EXPECT_NE(check_vehicle_id("a/b"), "") << "a slash would open another topic level";
    EXPECT_NE(check_vehicle_id("+"), "");
    EXPECT_NE(check_vehicle_id(std::string(65, 'a')), "");
    EXPECT_EQ(vehicle_topic("rover1", "cmd/result"), "airseg/rover1/cmd/result");
}

}  // namespace
}  // namespace airseg::client

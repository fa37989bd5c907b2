#include <gtest/gtest.h>

#include <bit>

#include "client/stick_input.hpp"
#include "client/vehicle_commands.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::client {
namespace {

namespace proto = groundlink::protocol;
using groundside::WatchState;

std::vector<std::uint8_t> js_event(std::int16_t value, std::uint8_t type, std::uint8_t number) {
    const auto v = static_cast<std::uint16_t>(value);
    const std::uint8_t lo = v & 0xff, hi = v >> 8;
    const bool little = std::endian::native == std::endian::little;
    return {0, 0, 0, 0, little ? lo : hi, little ? hi : lo, type, number};
}

TEST(JsEventDecoder, AxesBecomeSteeringAndThrottle) {
    JsEventDecoder d;
    auto a = js_event(16384, 0x82, 0);   // initial state of axis 0
    auto b = js_event(-32767, 0x02, 1);  // stick pushed fully forward
    auto button = js_event(1, 0x01, 0);
    std::vector<std::uint8_t> all;
    for (auto* e : {&a, &b, &button}) {
        all.insert(all.end(), e->begin(), e->end());
    }
    // Fed in awkward pieces: records may be split across reads.
    d.feed(std::span(all).first(5));
    d.feed(std::span(all).subspan(5, 7));
    d.feed(std::span(all).subspan(12));
    EXPECT_NEAR(d.stick().steering, 0.5, 0.001);
    EXPECT_NEAR(d.stick().throttle, 1.0, 0.001);
    const auto extreme = js_event(-32768, 0x02, 0);
    d.feed(extreme);
    EXPECT_DOUBLE_EQ(d.stick().steering, -1.0);
}

TEST(KeyboardDecoder, KeysAndArrowsNudgeAndSpaceCentres) {
    KeyboardDecoder k(0.1);
    const std::string keys = "www\x1b[C\x1b[Cd";
    k.feed(std::span(reinterpret_cast<const std::uint8_t*>(keys.data()), keys.size()));
    EXPECT_NEAR(k.stick().throttle, 0.3, 1e-9);
    EXPECT_NEAR(k.stick().steering, 0.3, 1e-9);
    const std::string more = std::string(20, 's') + " q";
    k.feed(std::span(reinterpret_cast<const std::uint8_t*>(more.data()), more.size()));
    EXPECT_DOUBLE_EQ(k.stick().throttle, 0.0);
    EXPECT_TRUE(k.stick().quit);
}

TEST(WatchState, ShowsTheLatestSampleTheLinkAndRecentEvents) {
    WatchState w;
    const auto t0 = WatchState::Clock::now();
    proto::Telemetry t;
    t.lat_deg = 41.2756;
    t.lon_deg = 1.9866;
    t.gps_fix = 3;
    t.vehicle_state = 4;
    t.mode = 0;
    t.ground_speed_mps = 1.5;
    t.battery_pct = 77;
    t.plan_state = 1;
    t.plan_element = 3;
    for (int i = 0; i < 10; ++i) {
        w.take(t, t0 + std::chrono::milliseconds(500 * i));
    }
    for (int i = 0; i < 12; ++i) {
        w.take(proto::Event{proto::Event::Severity::Warning, "event " + std::to_string(i)}, t0);
    }
    w.take(proto::LinkStatsReport{120, 200, 300, 4, 0}, t0);
    w.set_ground_link({{"link", "up"}, {"rtt_ms", 90.0}, {"loss", 0.316}});
    const auto now = t0 + std::chrono::milliseconds(4600);
    EXPECT_NEAR(w.sample_rate(now), 2.0, 0.01);
    const auto screen = w.render(now);
    EXPECT_NE(screen.find("MANUAL_NAVIGATION"), std::string::npos) << screen;
    EXPECT_NE(screen.find("41.2756000"), std::string::npos) << screen;
    EXPECT_NE(screen.find("77 %"), std::string::npos) << screen;
    EXPECT_NE(screen.find("plan        running  element 3"), std::string::npos) << screen;
    EXPECT_NE(screen.find("loss 20.0 %"), std::string::npos) << screen;
    EXPECT_NE(screen.find("ground: up rtt 90 ms, loss 31.6 %"), std::string::npos) << "as the map says it";
    EXPECT_EQ(screen.find("event 3\n"), std::string::npos) << "only the last 8 events";
    EXPECT_NE(screen.find("warning: event 11"), std::string::npos);
    const auto j = w.to_json(now);
    EXPECT_EQ(j["vehicle"]["state"], "MANUAL_NAVIGATION");
    EXPECT_EQ(j["vehicle"]["mode"], "MANUAL");
    for (const std::uint8_t unnamed : {std::uint8_t{9}, proto::kModeUnknown}) {
        t.mode = unnamed;
        w.take(t, now);
        EXPECT_EQ(w.to_json(now)["vehicle"]["mode"], "?");
        EXPECT_NE(w.render(now).find("mode ?\n"), std::string::npos) << w.render(now);
    }
    EXPECT_EQ(j["events"].size(), 8u);
}

TEST(VehicleCommands, BuildRequestsAndRefuseBadArguments) {
    auto s = build_vehicle_command({"state", "manual_navigation"});
    ASSERT_TRUE(s.usage_error.empty());
    EXPECT_EQ(s.request, (nlohmann::json{{"cmd", "state"}, {"state", "MANUAL_NAVIGATION"}}));
    EXPECT_FALSE(build_vehicle_command({"state"}).usage_error.empty());

    auto set = build_vehicle_command({"param", "set", "cruise_speed", "2.5"});
    EXPECT_EQ(set.request, (nlohmann::json{{"cmd", "param.set"}, {"name", "CRUISE_SPEED"}, {"value", 2.5}}));
    EXPECT_FALSE(build_vehicle_command({"param", "set", "X", "fast"}).usage_error.empty());
    EXPECT_EQ(build_vehicle_command({"param", "list"}).request["cmd"], "param.list");
    EXPECT_FALSE(build_vehicle_command({"param", "get"}).usage_error.empty());

    auto rates = build_vehicle_command({"rates", "vehicle=5", "link_stats=0.5"});
    EXPECT_EQ(rates.request,
              (nlohmann::json{{"cmd", "rates.set"}, {"rates", {{"vehicle", 5.0}, {"link_stats", 0.5}}}}));
    EXPECT_EQ(build_vehicle_command({"rates"}).request["cmd"], "rates");
    EXPECT_FALSE(build_vehicle_command({"rates", "vehicle"}).usage_error.empty());
    const auto text = rates.render({{"requested_hz", {{"vehicle", 5}}},
                                    {"effective_hz", {{"vehicle", 2.5}}},
                                    {"factor", 0.5},
                                    {"weak_link", true},
                                    {"budget_bytes_per_s", 1440}});
    EXPECT_NE(text.find("effective    2.5 Hz"), std::string::npos) << text;
    EXPECT_NE(text.find("(link weak)"), std::string::npos) << text;
}

}  // namespace
}  // namespace airseg::client

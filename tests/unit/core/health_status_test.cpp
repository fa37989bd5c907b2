#include <gtest/gtest.h>

#include "services/common/health.hpp"
#include "services/status/status_document.hpp"

namespace airseg {
namespace {

TEST(HealthRegistry, StalledNamesServicesWithoutRecentProgress) {
    HealthRegistry reg;
    const TimePoint t0 = TimePoint{} + std::chrono::hours(1);
    reg.add("autopilot", t0);
    reg.add("groundlink", t0);
    reg.progress("autopilot", t0 + std::chrono::seconds(5));
    auto stalled = reg.stalled(t0 + std::chrono::seconds(6), std::chrono::seconds(3));
    ASSERT_EQ(stalled.size(), 1u);
    EXPECT_EQ(stalled[0], "groundlink");
    EXPECT_TRUE(reg.stalled(t0 + std::chrono::seconds(2), std::chrono::seconds(3)).empty());
}

TEST(HealthRegistry, SetReportsOnlyRealChanges) {
    HealthRegistry reg;
    reg.add("autopilot", TimePoint{});
    EXPECT_TRUE(reg.set("autopilot", Health::Down, "no /dev/ttyACM0"));
    EXPECT_FALSE(reg.set("autopilot", Health::Down, "no /dev/ttyACM0"));
    EXPECT_TRUE(reg.set("autopilot", Health::Up));
    EXPECT_FALSE(reg.set("nonexistent", Health::Up));
}

TEST(StatusDocument, HasStableServiceKeysAndSections) {
    HealthRegistry reg;
    reg.add("autopilot", TimePoint{});
    reg.set("autopilot", Health::Down, "no /dev/ttyACM0");
    reg.add("status", TimePoint{});
    reg.set("status", Health::Up);
    std::map<std::string, nlohmann::json> sections{{"plan", {{"state", "none"}}}};
    auto doc = status::build_document(reg.snapshot(), sections, 12.34);
    EXPECT_EQ(doc["services"]["autopilot"]["health"], "down");
    EXPECT_EQ(doc["services"]["autopilot"]["error"], "no /dev/ttyACM0");
    EXPECT_TRUE(doc["services"]["autopilot"]["since"].get<std::string>().ends_with("Z"));
    EXPECT_EQ(doc["services"]["status"]["health"], "up");
    EXPECT_EQ(doc["plan"]["state"], "none");
    EXPECT_DOUBLE_EQ(doc["uptime_s"].get<double>(), 12.3);

    const auto line = status::summary_line(reg.snapshot(), sections);
    EXPECT_EQ(line, "autopilot: DOWN (no /dev/ttyACM0) · plan: none");
}

TEST(StatusDocument, Iso8601IsUtcWithMilliseconds) {
    const auto t = std::chrono::system_clock::time_point{} + std::chrono::milliseconds(1'700'000'000'123);
    EXPECT_EQ(status::iso8601(t), "2023-11-14T22:13:20.123Z");
}

}  // namespace
}  // namespace airseg

// The link benchmark's harness, exercised with the seed's protocol in short simulated runs.
#include <gtest/gtest.h>

#include <sstream>

#include "bench/linkbench/report.hpp"
#include "bench/linkbench/scenario.hpp"

namespace airseg::linkbench {
namespace {

Scenario short_scenario(LinkMode mode) {
    Scenario s;
    s.mode = mode;
    s.duration = std::chrono::seconds(10);
    return s;
}

TEST(LinkbenchScenario, SeedOnItsOwnPairRunsNearLineRate) {
    const auto r = run_scenario(short_scenario(LinkMode::Dual), make_seed_endpoint);
    ASSERT_TRUE(r.ran);
    // One-way pair: only framing (9 bytes per 300, DLE/ETX, DLE doubling) stands between it and line rate.
    EXPECT_GT(r.goodput_pct, 85.0);
    EXPECT_LE(r.goodput_pct, 100.0);
    EXPECT_LT(r.max_stall_s, 1.0);
    EXPECT_EQ(r.damaged_deliveries, 0u);
    EXPECT_EQ(r.radio_overflow, 0u);
}

TEST(LinkbenchScenario, SeedOverrunsAHalfDuplexRadioSharedWithItsAcks) {
    const auto r = run_scenario(short_scenario(LinkMode::Single), make_seed_endpoint);
    ASSERT_TRUE(r.ran);
    // Unpaced writes at the serial rate into a radio whose air also carries the ACKs: the FIFO overflows.
    EXPECT_GT(r.radio_overflow, 1000u);
    EXPECT_LT(r.goodput_pct, 50.0);
    EXPECT_GT(r.wire_ab_pct, 95.0);
}

TEST(LinkbenchScenario, SameScenarioSameFigures) {
    Scenario s = short_scenario(LinkMode::Dual);
    s.byte_corruption = 1e-3;
    const auto a = run_scenario(s, make_seed_endpoint);
    const auto b = run_scenario(s, make_seed_endpoint);
    EXPECT_EQ(a.goodput_pct, b.goodput_pct);
    EXPECT_EQ(a.safe_messages, b.safe_messages);
    EXPECT_LT(a.goodput_pct, run_scenario(short_scenario(LinkMode::Dual), make_seed_endpoint).goodput_pct);
}

TEST(LinkbenchReport, TargetsWithoutOursAreNotEvaluated) {
    Row row{short_scenario(LinkMode::Single), ScenarioResult{}, ScenarioResult{}};
    row.seed.ran = true;
    row.seed.goodput_pct = 96.0;
    const auto checks = check_targets({row});
    ASSERT_FALSE(checks.empty());
    EXPECT_FALSE(checks.front().evaluated);
    EXPECT_TRUE(checks.front().seed_pass);
    std::ostringstream os;
    print_json(os, {row});
    EXPECT_NE(os.str().find("\"seed_goodput_pct\":96.0"), std::string::npos) << os.str();
    EXPECT_NE(os.str().find("\"goodput_pct\":null"), std::string::npos) << os.str();
}

}  // namespace
}  // namespace airseg::linkbench

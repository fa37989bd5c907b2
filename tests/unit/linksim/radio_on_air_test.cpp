// The ground-link transport on radios whose air is not their serial port, over the radio simulator in
// simulated time (the link benchmark's scenarios, shortened): told the radio (groundlink.radio), it paces to
// what the air carries and never overflows the radio's buffer; two ends loaded both ways share the air.
#include <gtest/gtest.h>

#include "bench/linkbench/scenario.hpp"

namespace airseg::linkbench {
namespace {

Scenario scenario(const char* label) {
    Scenario s;
    s.baud = 57600;
    s.mode = LinkMode::Single;
    s.impairment = label;
    s.duration = std::chrono::seconds(20);
    return s;
}

TEST(RadioOnAir, SmallAirPacketsWithOverheadAreCarriedOnceTheTransportIsToldOfThem) {
    Scenario s = scenario("pkt32+8");
    s.air_packet = 32;
    s.air_packet_overhead = 8;
    const auto blind = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(blind.ran);
    // Paced to the serial rate, a fifth of what it writes does not fit the air: the radio drops bytes.
    EXPECT_GT(blind.radio_overflow, 1000u);
    s.radio_configured = true;
    const auto told = run_scenario(s, make_transport_endpoint);
    EXPECT_EQ(told.radio_overflow, 0u);
    EXPECT_GE(told.goodput_pct, 60.0) << "32 of every 40 air bytes are payload: 80 % at most";
    EXPECT_GT(told.goodput_pct, 2 * blind.goodput_pct);
    EXPECT_EQ(told.damaged_deliveries, 0u);
    std::cout << "[ figures ] 32-byte air packets with 8 bytes of overhead: goodput " << blind.goodput_pct
              << " % (" << blind.radio_overflow << " bytes overflowed) -> " << told.goodput_pct
              << " % configured\n";
}

TEST(RadioOnAir, ASlowTurnaroundIsPacedForOnceTheTransportIsToldOfIt) {
    Scenario s = scenario("turn10ms");
    s.turnaround = std::chrono::milliseconds(10);
    const auto blind = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(blind.ran);
    EXPECT_GT(blind.radio_overflow, 0u);
    s.radio_configured = true;
    const auto told = run_scenario(s, make_transport_endpoint);
    EXPECT_EQ(told.radio_overflow, 0u);
    EXPECT_GE(told.goodput_pct, 75.0);
    std::cout << "[ figures ] 10 ms turnaround: goodput " << blind.goodput_pct << " % ("
              << blind.radio_overflow << " bytes overflowed) -> " << told.goodput_pct << " % configured\n";
}

TEST(RadioOnAir, BulkAndFastTrafficBothWaysLeaveEachDirectionAThirdOfTheAir) {
    const auto alone = run_scenario(scenario("clean"), make_transport_endpoint);
    ASSERT_TRUE(alone.ran);
    Scenario s = scenario("bidir+fast");
    s.bidirectional = true;
    s.fast_both_ways = true;
    const auto both = run_scenario(s, make_transport_endpoint);
    // Each end's Fast traffic keeps it urgent all the time; neither end may wait for the other's urgency
    // to end, or one direction falls silent for the whole run.
    EXPECT_GE(both.fast_run_goodput_ab_pct, alone.goodput_pct / 3);
    EXPECT_GE(both.fast_run_goodput_ba_pct, alone.goodput_pct / 3);
    EXPECT_LE(both.fast_run_stall_ab_s, 5.0);
    EXPECT_LE(both.fast_run_stall_ba_s, 5.0);
    EXPECT_GE(both.fast_delivery_pct, 95.0);
    std::cout << "[ figures ] bulk and Fast both ways: A->B " << both.fast_run_goodput_ab_pct << " %, B->A "
              << both.fast_run_goodput_ba_pct << " % (one direction alone " << alone.goodput_pct
              << " %); longest waits " << both.fast_run_stall_ab_s << " s / " << both.fast_run_stall_ba_s
              << " s\n";
}

TEST(RadioOnAir, TheVehiclesTelemetryTrickleCostsBulkLittle) {
    Scenario s = scenario("telemetry");
    s.telemetry_from_b = true;
    const auto r = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(r.ran);
    EXPECT_GE(r.goodput_pct, 88.0);
    EXPECT_EQ(r.damaged_deliveries, 0u);
    std::cout << "[ figures ] bulk beside 2 Hz telemetry and 1 Hz link statistics: goodput " << r.goodput_pct
              << " %\n";
}

}  // namespace
}  // namespace airseg::linkbench

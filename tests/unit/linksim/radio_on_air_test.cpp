// The ground-link transport on radios whose air is not their serial port, over the radio simulator in
// simulated time (the link benchmark's scenarios, shortened): told the radio (groundlink.radio), it paces to
// what the air carries and never overflows the radio's buffer; two ends loaded both ways share the air.
#include <gtest/gtest.h>

#include <memory>

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

TEST(RadioOnAir, ToldOnlyTheBufferTheTransportMeasuresASlowAirAndOverflowsItFarLess) {
    Scenario s = scenario("turn10ms");
    s.turnaround = std::chrono::milliseconds(10);
    const auto blind = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(blind.ran);
    s.radio_adapt = true;  // the buffer, adapt on; the turnaround left at its 1 ms default
    const auto measured = run_scenario(s, make_transport_endpoint);
    EXPECT_GE(measured.goodput_pct, 1.5 * blind.goodput_pct);
    EXPECT_LE(3 * measured.radio_overflow, blind.radio_overflow);
    EXPECT_LT(measured.air_carried_pct, 100.0);  // it judged the air slower than configured
    EXPECT_GE(measured.air_carried_pct, 25.0);
    EXPECT_EQ(measured.damaged_deliveries, 0u);
    std::cout << "[ figures ] 10 ms turnaround, measured: goodput " << blind.goodput_pct << " % ("
              << blind.radio_overflow << " bytes overflowed) -> " << measured.goodput_pct << " % ("
              << measured.radio_overflow << "), pace " << measured.air_carried_pct << " % of the line\n";
}

TEST(RadioOnAir, MeasuringANoisyAirDoesNotSlowItDown) {
    Scenario s = scenario("corrupt=1e-4");
    s.byte_corruption = 1e-4;
    s.duration = std::chrono::seconds(40);  // a trial costs a few seconds; 20 would make it a tenth
    const auto configured = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(configured.ran);
    s.radio_adapt = true;
    const auto measured = run_scenario(s, make_transport_endpoint);
    // Corruption loses frames whatever the pace: a trial may look, but the pace goes back.
    EXPECT_GE(measured.goodput_pct, 0.9 * configured.goodput_pct);
    std::cout << "[ figures ] corruption 1e-4: goodput " << configured.goodput_pct << " % configured, "
              << measured.goodput_pct << " % measured\n";
}

TEST(RadioOnAir, TheBufferRuleLeavesBothDirectionsTheirShare) {
    // With the radio's buffer known, the lighter end was held for as long as the heavier one talked.
    Scenario s = scenario("bidir");
    s.bidirectional = true;
    s.radio_configured = true;
    const auto both = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(both.ran);
    EXPECT_GE(both.goodput_pct, 75.0);
    EXPECT_LE(both.max_stall_s, 5.0);
    // Each end counts only its own radio's queue, which a busy peer delays more than the estimate says:
    // a few hundred bytes overflow in a run (the shared budget overflowed none, and starved one end).
    EXPECT_LE(both.radio_overflow, 2000u);
    std::cout << "[ figures ] bulk both ways, radio told: goodput " << both.goodput_pct
              << " %, longest stall " << both.max_stall_s << " s\n";
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

// The transport's end, as an application that names no command with a request id would use it.
class WithoutRequestIds final : public BenchEndpoint {
  public:
    explicit WithoutRequestIds(std::unique_ptr<BenchEndpoint> inner) : inner_(std::move(inner)) {}
    bool send_safe(std::span<const std::uint8_t> m, TimePoint now) override {
        return inner_->send_safe(m, now);
    }
    bool send_urgent(std::span<const std::uint8_t> m, TimePoint now) override {
        return inner_->send_urgent(m, now);
    }
    void send_fast(std::uint16_t stream, std::span<const std::uint8_t> m, TimePoint now) override {
        inner_->send_fast(stream, m, now);
    }
    void handle_bytes(std::size_t path, std::span<const std::uint8_t> b, TimePoint now) override {
        inner_->handle_bytes(path, b, now);
    }
    void handle_timeout(TimePoint now) override { inner_->handle_timeout(now); }
    std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now) override {
        return inner_->poll_transmit(path, now);
    }
    std::optional<BenchMessage> poll_message() override { return inner_->poll_message(); }
    TimePoint poll_timeout() const override { return inner_->poll_timeout(); }
    std::size_t safe_backlog() const override { return inner_->safe_backlog(); }
    bool request_ids() const override { return false; }

  private:
    std::unique_ptr<BenchEndpoint> inner_;
};

TEST(RadioOnAir, ACommandWhoseAnswerWasLostRunsOnceWhenANewClientSendsItAgain) {
    Scenario s = scenario("lost answer");
    s.lost_answers = true;
    s.duration = std::chrono::seconds(40);
    const auto r = run_scenario(s, make_transport_endpoint);
    ASSERT_TRUE(r.ran);
    EXPECT_GE(r.cmd_retried, 2u);
    EXPECT_GE(r.cmd_retried_answered + 1, r.cmd_retried);  // the last may still be on its way
    EXPECT_EQ(r.cmd_applied_twice, 0u);
    // The same radio and clients without the vehicle's record: the retried commands run twice.
    const auto unrecorded = run_scenario(s, [](const EndpointSetup& e) -> std::unique_ptr<BenchEndpoint> {
        return std::make_unique<WithoutRequestIds>(make_transport_endpoint(e));
    });
    EXPECT_GE(unrecorded.cmd_applied_twice, 1u);
    std::cout << "[ figures ] lost answers: " << r.cmd_retried << " commands sent again by a new client, "
              << r.cmd_applied_twice << " run twice (" << unrecorded.cmd_applied_twice
              << " without the record); command p90 " << r.cmd_p90_s << " s\n";
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

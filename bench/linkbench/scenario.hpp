#pragma once
// One benchmark scenario: two protocol ends joined by one or two simulated radio pairs, driven in simulated
// time by a fixed workload, with the figures the benchmark reports.
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "bench/linkbench/endpoint.hpp"
#include "tools/linksim/radio_config.hpp"

namespace airseg::linkbench {

struct Scenario {
    std::uint32_t baud = 57600;
    LinkMode mode = LinkMode::Single;
    std::string impairment = "clean";       ///< label printed in the table
    double byte_corruption = 0.0;           ///< both directions, every pair
    double byte_loss = 0.0;                 ///< independent byte loss, both directions, every pair
    double bit_error_rate = 0.0;            ///< independent bit flips, both directions, every pair
    double frame_loss = 0.0;                ///< air packet loss, both directions, every pair
    std::optional<linksim::Outage> outage;  ///< both directions, every pair
    bool bidirectional = false;             ///< bulk Safe traffic both ways (otherwise A→B only)
    bool fast_both_ways = false;            ///< the Fast run sends Fast B→A too (with bidirectional)
    bool telemetry_from_b = false;  ///< B sends airsegd's telemetry (48 B at 2 Hz, 37 B at 1 Hz) as Fast
    Duration duration = std::chrono::seconds(60);
    Duration turnaround = std::chrono::milliseconds(1);  ///< radio dead air when the sending side changes
    std::size_t air_packet = 252;                        ///< payload bytes per air packet
    std::size_t air_packet_overhead = 0;                 ///< air bytes each packet adds
    /// The transport is told the radio as it is (air packets, overhead, turnaround, buffer), as
    /// groundlink.radio tells it; otherwise it assumes the defaults (1 ms turnaround, no packet overhead).
    bool radio_configured = false;
    /// Commands carry a request id and B runs them through the vehicle's record of recent commands
    /// (services/common/command_record.hpp; the seed had none). The answer to every fourth is lost: B's
    /// radio goes silent for 6 s as the command arrives; the client gives up after 3 s, starts again (a new
    /// session) and sends the same command again.
    bool lost_answers = false;
    /// The transport's pacing follows the air as it measures it (groundlink.radio.adapt); told the radio's
    /// buffer, and the rest only with radio_configured.
    bool radio_adapt = false;
    double pacing_factor =
        1.0;                    ///< the transport's link_rate as a fraction of baud/10 (the seed never paces)
    std::uint64_t seed = 1000;  ///< of the radios' impairments: the same seed gives the same figures
};

struct ScenarioResult {
    bool ran = false;          ///< false when the protocol is not available in this build
    double goodput_pct = 0.0;  ///< intact, unique Safe payload per second (both ways if bidirectional)
                               ///< as % of one line's payload rate (baud/10 bytes/s)
    double fast_p50_ms = 0.0;  ///< Fast A→B latency (second run); NaN when nothing arrived
    double fast_p99_ms = 0.0;
    double fast_delivery_pct = 0.0;  ///< Fast messages sent (until 2 s before the end) that arrived
    double max_stall_s = 0.0;        ///< longest time without a Safe delivery A→B
    /// Per direction, from the run with Fast traffic (bulk and Fast both ways when fast_both_ways): goodput
    /// as % of one line's rate, and the longest time without a Safe delivery.
    double fast_run_goodput_ab_pct = 0.0;
    double fast_run_goodput_ba_pct = 0.0;
    double fast_run_stall_ab_s = 0.0;
    double fast_run_stall_ba_s = 0.0;
    /// Command round trips (third run): a status-sized exchange on the urgent channel while telemetry flows,
    /// one command at a time; unanswered commands count as infinitely slow.
    double cmd_p50_s = 0.0;
    double cmd_p90_s = 0.0;
    std::uint64_t cmd_sent = 0;
    std::uint64_t cmd_answered = 0;
    std::uint64_t cmd_retried = 0;           ///< lost_answers: commands sent again by a client started again
    std::uint64_t cmd_retried_answered = 0;  ///< ... and answered after that
    std::uint64_t cmd_applied_twice = 0;     ///< lost_answers: commands the vehicle ran more than once
    double cmd_twice = 0.0;                  ///< cmd_applied_twice, as a figure for the table
    std::uint64_t safe_messages = 0;
    std::uint64_t damaged_deliveries = 0;  ///< messages whose content differs from what was sent
    // Where the bytes went (diagnostics printed by --verbose):
    double wire_ab_pct = 0.0;          ///< bytes A wrote, all pairs, % of one line's rate
    double wire_ba_pct = 0.0;          ///< bytes B wrote, all pairs, % of one line's rate
    double air_utilisation_pct = 0.0;  ///< air busy on pair 0 (packets and turnarounds)
    std::uint64_t radio_overflow = 0;  ///< bytes dropped at a full radio FIFO, all pairs and directions
    /// The air as A measured it (NaN when its protocol does not): the payload rate it paced for at the end
    /// of run 1, as % of one line's rate, and the turnaround at the end of the command run (ms).
    double air_carried_pct = std::numeric_limits<double>::quiet_NaN();
    double air_turnaround_ms = std::numeric_limits<double>::quiet_NaN();
};

using EndpointFactory = std::function<std::unique_ptr<BenchEndpoint>(const EndpointSetup&)>;

/// The radio pair every scenario uses: SiK-like half-duplex radios whose air byte rate equals the serial byte
/// rate, Scenario::turnaround, Scenario::air_packet (252 unless said) with its overhead, 2 KiB FIFO, 4 KiB
/// host UART buffer.
linksim::RadioConfig bench_radio(const Scenario& s, std::uint64_t seed);

/// A command: kCommandBytes A→B; its answer: kAnswerBytes B→A (the size of airsegd's status answer).
inline constexpr std::size_t kCommandBytes = 24;
inline constexpr std::size_t kAnswerBytes = 1536;

/// Three runs of the scenario: bulk Safe alone (goodput, stalls, wire use); bulk plus Fast telemetry A→B at
/// 10 Hz (Fast latency and delivery while bulk saturates the link); commands A→B answered B→A while B pushes
/// telemetry as airsegd does (48 bytes at 2 Hz, 37 bytes at 1 Hz): the command round trip.
ScenarioResult run_scenario(const Scenario& s, const EndpointFactory& make);

}  // namespace airseg::linkbench

#pragma once
// One benchmark scenario: two protocol ends joined by one or two simulated radio pairs, driven in simulated
// time by a fixed workload, with the figures the benchmark reports.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "bench/linkbench/endpoint.hpp"
#include "tools/linksim/radio_config.hpp"

namespace airseg::linkbench {

struct Scenario {
    std::uint32_t baud = 57600;
    LinkMode mode = LinkMode::single;
    std::string impairment = "clean";       ///< label printed in the table
    double byte_corruption = 0.0;           ///< both directions, every pair
    double frame_loss = 0.0;                ///< air packet loss, both directions, every pair
    std::optional<linksim::Outage> outage;  ///< both directions, every pair
    bool bidirectional = false;             ///< bulk Safe traffic both ways (otherwise A→B only)
    Duration duration = std::chrono::seconds(60);
};

struct ScenarioResult {
    bool ran = false;          ///< false when the protocol is not available in this build
    double goodput_pct = 0.0;  ///< intact, unique Safe payload per second (both ways if bidirectional)
                               ///< as % of one line's payload rate (baud/10 bytes/s)
    double fast_p50_ms = 0.0;  ///< Fast A→B latency; NaN when nothing arrived
    double fast_p99_ms = 0.0;
    double fast_delivery_pct = 0.0;  ///< Fast messages sent (until 2 s before the end) that arrived
    double max_stall_s = 0.0;        ///< longest time without a Safe delivery A→B
    std::uint64_t safe_messages = 0;
    std::uint64_t damaged_deliveries = 0;  ///< messages whose content differs from what was sent
};

using EndpointFactory = std::function<std::unique_ptr<BenchEndpoint>(const EndpointSetup&)>;

/// The radio pair every scenario uses: SiK-like half-duplex radios whose air byte rate equals the serial byte
/// rate, 1 ms turnaround, 252-byte air packets, 2 KiB FIFO, 4 KiB host UART buffer.
linksim::RadioConfig bench_radio(const Scenario& s, std::uint64_t seed);

ScenarioResult run_scenario(const Scenario& s, const EndpointFactory& make);

}  // namespace airseg::linkbench

// linkbench: the ground-link transport against the seed's MAREA serial transport over the same simulated
// radios, in simulated time. Deterministic: the same build prints the same figures.
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "bench/linkbench/report.hpp"
#include "bench/linkbench/scenario.hpp"
#include "cli/command_line.hpp"

namespace {

using namespace airseg;
using namespace airseg::linkbench;

constexpr const char* kUsage =
    R"(usage: linkbench [--json] [--verbose] [--duration SECONDS] [--seed N] [--strict]

Runs every scenario on airseg's ground-link transport ("ours") and on a model of the seed's MAREA serial
transport, over the same simulated radio pairs (half duplex, air rate = serial rate, 1 ms turnaround,
252-byte air packets, 2 KiB radio FIFO without flow control), in simulated time.

Scenarios, for 57600 and 115200 baud, single pair and dual pair (split: each end transmits on its own pair):
  clean            run 1: bulk Safe A->B alone (1024-byte messages, 24 kept offered): goodput, stall;
                   run 2: the same bulk plus Fast A->B, 32 bytes at 10 Hz: Fast latency and delivery
                   run 3: commands A->B (24 bytes, urgent channel) answered B->A with 1536 bytes (a
                   status answer) while B pushes telemetry (48 B at 2 Hz, 37 B at 1 Hz), one at a time
                   with 0.5 s between: command round trip p50 and p90
  corrupt=1e-5..3  the same with that probability of a corrupted byte, both directions
  loss=N%          the same with N % of bytes lost independently (0.5, 1, 2, 5), both directions
  ber=X            the same with bit error rate X (1e-5, 3e-5, 1e-4), both directions
  frameloss=N%     the same with N % of air packets lost, both directions
  outage=30s       the same with a 30 s outage of both directions starting at 20 s (90 s run)
  bidir            bulk Safe both ways (dual/single ratio of this row is a target)
  bidir+fast       bulk Safe both ways, and in run 2 Fast both ways: each direction's share of the air
  telemetry        the clean row while B sends airsegd's telemetry (48 B at 2 Hz, 37 B at 1 Hz, Fast)
Single pair only:
  lost answer      run 3 with request ids, B running commands through the vehicle's record of recent
                   commands: the answer to every fourth is lost (B's radio silent 6 s as it arrives), the
                   client gives up after 3 s, starts again and sends it again: none may run twice
Single pair only, radios whose air differs from their serial port ("cfg": the transport is told the radio, as
groundlink.radio tells it; without, it assumes 1 ms turnaround and no per-packet overhead):
  pkt32+8 [cfg]    32-byte air packets with 8 bytes of overhead each
  turn10ms [cfg]   10 ms turnaround (--turnaround-ms does not change these rows)
  turn20ms cfg     20 ms turnaround
  ... adapt        told only the radio's buffer: the transport measures the air (groundlink.radio.adapt)

)";

struct Knobs {
    Duration length = std::chrono::seconds(40);
    Duration turnaround = std::chrono::milliseconds(1);
    double pacing_factor = 1.0;
    std::uint64_t seed = 1000;
    bool adapt = false;
};

std::vector<Scenario> scenarios(const Knobs& k) {
    std::vector<Scenario> list;
    for (std::uint32_t baud : {57600U, 115200U}) {
        for (LinkMode mode : {LinkMode::Single, LinkMode::Dual}) {
            Scenario base;
            base.baud = baud;
            base.mode = mode;
            base.duration = k.length;
            base.turnaround = k.turnaround;
            base.pacing_factor = k.pacing_factor;
            base.seed = k.seed;
            base.radio_adapt = k.adapt;
            list.push_back(base);
            for (auto [label, p] :
                 {std::pair{"corrupt=1e-5", 1e-5}, {"corrupt=1e-4", 1e-4}, {"corrupt=1e-3", 1e-3}}) {
                Scenario s = base;
                s.impairment = label;
                s.byte_corruption = p;
                list.push_back(s);
            }
            for (auto [label, p] :
                 {std::pair{"loss=0.5%", 0.005}, {"loss=1%", 0.01}, {"loss=2%", 0.02}, {"loss=5%", 0.05}}) {
                Scenario s = base;
                s.impairment = label;
                s.byte_loss = p;
                list.push_back(s);
            }
            for (auto [label, p] : {std::pair{"ber=1e-5", 1e-5}, {"ber=3e-5", 3e-5}, {"ber=1e-4", 1e-4}}) {
                Scenario s = base;
                s.impairment = label;
                s.bit_error_rate = p;
                list.push_back(s);
            }
            for (auto [label, p] :
                 {std::pair{"frameloss=10%", 0.1}, {"frameloss=20%", 0.2}, {"frameloss=30%", 0.3}}) {
                Scenario s = base;
                s.impairment = label;
                s.frame_loss = p;
                list.push_back(s);
            }
            Scenario outage = base;
            outage.impairment = "outage=30s";
            outage.outage = linksim::Outage{std::chrono::seconds(20), std::chrono::seconds(30)};
            outage.duration = k.length + std::chrono::seconds(30);
            list.push_back(outage);
            Scenario bidir = base;
            bidir.impairment = "bidir";
            bidir.bidirectional = true;
            list.push_back(bidir);
            Scenario bidir_fast = bidir;
            bidir_fast.impairment = "bidir+fast";
            bidir_fast.fast_both_ways = true;
            list.push_back(bidir_fast);
            Scenario trickle = base;
            trickle.impairment = "telemetry";
            trickle.telemetry_from_b = true;
            list.push_back(trickle);
            if (mode != LinkMode::Single) {
                continue;
            }
            Scenario retried = base;
            retried.impairment = "lost answer";
            retried.lost_answers = true;
            list.push_back(retried);
            // Radios whose air is not their serial port: small air packets with their own overhead, and a
            // slow change of sender; each as the transport assumes it by default, then told (configured).
            // Then told only the radio's buffer, measuring the rest (adapt).
            for (auto [label, told, adapt] : {std::tuple{"pkt32+8", false, false},
                                              {"pkt32+8 cfg", true, false},
                                              {"pkt32+8 adapt", false, true}}) {
                Scenario packets = base;
                packets.impairment = label;
                packets.air_packet = 32;
                packets.air_packet_overhead = 8;
                packets.radio_configured = told;
                packets.radio_adapt = adapt || k.adapt;
                list.push_back(packets);
            }
            for (auto [label, ms, told, adapt] : {std::tuple{"turn10ms", 10, false, false},
                                                  {"turn10ms cfg", 10, true, false},
                                                  {"turn10ms adapt", 10, false, true},
                                                  {"turn20ms cfg", 20, true, false}}) {
                Scenario slow = base;
                slow.impairment = label;
                slow.turnaround = std::chrono::milliseconds(ms);
                slow.radio_configured = told;
                slow.radio_adapt = adapt || k.adapt;
                list.push_back(slow);
            }
        }
    }
    return list;
}

}  // namespace

int main(int argc, char** argv) {
    bool json = false;
    bool strict = false;
    bool verbose = false;
    std::uint32_t seconds = 40;
    Knobs knobs;
    std::string only;
    cli::OptionTable table("Options");
    table.flag("json", "one JSON object per scenario instead of the table", [&] { json = true; })
        .flag("verbose", "also print where the bytes went (wire use, air busy, FIFO overflow)",
              [&] { verbose = true; })
        .value("duration", "S",
               "seconds of simulated time per scenario, whole seconds within [5, 3600] (default 40; the "
               "outage runs 30 s longer)",
               cli::number(seconds, 5, 3600))
        .value("turnaround-ms", "X", "radio turnaround in milliseconds within [0, 1000] (default 1)",
               [&](std::string_view option, std::string_view text) {
                   knobs.turnaround = std::chrono::duration_cast<Duration>(
                       std::chrono::duration<double, std::milli>(cli::parse_double(option, text, 0, 1000)));
               })
        .value("pacing", "F",
               "the transport's link_rate as a fraction of baud/10, within [0.1, 2] (default 1.0)",
               cli::number(knobs.pacing_factor, 0.1, 2.0))
        .value("only", "TEXT",
               "only the scenarios whose \"baud mode impairment\" contains TEXT (e.g. \"57600 single loss\")",
               cli::text(only))
        .value("seed", "N",
               "seed of the radios' impairments (default 1000): the figures of one run are one draw of the "
               "radios' randomness; other seeds show how much a figure (a longest stall) varies",
               cli::number(knobs.seed, 0, std::numeric_limits<std::uint64_t>::max()))
        .flag("adapt",
              "every row with the transport's pacing following the air as it measures it (told the radio's "
              "buffer): what groundlink.radio.adapt costs or gains on each kind of link",
              [&] { knobs.adapt = true; })
        .flag("strict", "exit status 1 when a target fails", [&] { strict = true; })
        .help_and_version(false);
    const cli::Program program{"linkbench", [&] { return std::string(kUsage) + cli::describe(table); }};
    const auto line =
        cli::run(program, std::vector<std::string>(argv + 1, argv + argc), table, std::cout, std::cerr);
    if (line.exit_code) {
        return *line.exit_code;
    }

    std::vector<Row> rows;
    knobs.length = std::chrono::seconds(seconds);
    for (const Scenario& s : scenarios(knobs)) {
        const std::string name = std::to_string(s.baud) + " " + to_string(s.mode) + " " + s.impairment;
        if (name.find(only) == std::string::npos) {
            continue;
        }
        rows.push_back({s, run_scenario(s, make_transport_endpoint), run_scenario(s, make_seed_endpoint)});
    }
    const auto checks = check_targets(rows);
    if (json) {
        print_json(std::cout, rows);
    } else {
        if (!rows.empty() && !rows.front().ours.ran) {
            std::cout
                << "this build has no ground-link transport core: only the seed's figures are measured\n";
        }
        print_table(std::cout, rows);
        if (verbose) {
            print_diagnostics(std::cout, rows);
        }
        print_targets(std::cout, checks);
    }
    bool failed = false;
    for (const auto& c : checks) {
        failed = failed || (c.evaluated && !c.pass);
    }
    return strict && failed ? 1 : 0;
}

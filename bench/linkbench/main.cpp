// linkbench: the ground-link transport against the seed's MAREA serial transport over the same simulated
// radios, in simulated time. Deterministic: the same build prints the same figures.
#include <charconv>
#include <cstring>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "bench/linkbench/report.hpp"
#include "bench/linkbench/scenario.hpp"

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

  --json            one JSON object per scenario instead of the table
  --verbose         also print where the bytes went (wire use, air busy, FIFO overflow)
  --duration S      seconds of simulated time per scenario (default 40; the outage runs 30 s longer)
  --turnaround-ms X  radio turnaround (default 1)
  --pacing F        the transport's link_rate as a fraction of baud/10 (default 1.0)
  --only TEXT       only the scenarios whose "baud mode impairment" contains TEXT (e.g. "57600 single loss")
  --seed N          seed of the radios' impairments (default 1000): the figures of one run are one draw of
                    the radios' randomness; other seeds show how much a figure (a longest stall) varies
  --strict          exit status 1 when a target fails
)";

struct Knobs {
    Duration length = std::chrono::seconds(40);
    Duration turnaround = std::chrono::milliseconds(1);
    double pacing_factor = 1.0;
    std::uint64_t seed = 1000;
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
        }
    }
    return list;
}

}  // namespace

int main(int argc, char** argv) {
    bool json = false;
    bool strict = false;
    bool verbose = false;
    long seconds = 40;
    Knobs knobs;
    std::string only;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--json") {
            json = true;
        } else if (arg == "--verbose") {
            verbose = true;
        } else if (arg == "--strict") {
            strict = true;
        } else if (arg == "--only" && i + 1 < argc) {
            only = argv[++i];
        } else if (arg == "--duration" && i + 1 < argc) {
            const std::string_view v = argv[++i];
            auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), seconds);
            if (ec != std::errc{} || ptr != v.data() + v.size() || seconds < 5 || seconds > 3600) {
                std::cerr << "linkbench: --duration wants whole seconds within [5, 3600], got '" << v
                          << "'\n";
                return 2;
            }
        } else if (arg == "--seed" && i + 1 < argc) {
            const std::string_view v = argv[++i];
            auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), knobs.seed);
            if (ec != std::errc{} || ptr != v.data() + v.size()) {
                std::cerr << "linkbench: --seed wants a whole number, got '" << v << "'\n";
                return 2;
            }
        } else if ((arg == "--turnaround-ms" || arg == "--pacing") && i + 1 < argc) {
            const std::string_view v = argv[++i];
            double x = 0;
            auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            const bool pacing = arg == "--pacing";
            if (ec != std::errc{} || ptr != v.data() + v.size() || x < 0 ||
                (pacing && (x < 0.1 || x > 2.0)) || x > 1000) {
                std::cerr << "linkbench: " << arg << " wants "
                          << (pacing ? "a factor within [0.1, 2]" : "milliseconds within [0, 1000]")
                          << ", got '" << v << "'\n";
                return 2;
            }
            if (pacing) {
                knobs.pacing_factor = x;
            } else {
                knobs.turnaround =
                    std::chrono::duration_cast<Duration>(std::chrono::duration<double, std::milli>(x));
            }
        } else if (arg == "--help" || arg == "-h") {
            std::cout << kUsage;
            return 0;
        } else {
            std::cerr << "linkbench: unknown argument '" << arg << "'\n" << kUsage;
            return 2;
        }
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

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

constexpr const char* kUsage = R"(usage: linkbench [--json] [--duration SECONDS] [--strict]

Runs every scenario on airseg's ground-link transport ("ours") and on a model of the seed's MAREA serial
transport, over the same simulated radio pairs (half duplex, air rate = serial rate, 1 ms turnaround,
252-byte air packets, 2 KiB radio FIFO without flow control), in simulated time.

Scenarios, for 57600 and 115200 baud, single pair and dual pair (split: each end transmits on its own pair):
  clean            bulk Safe A->B (1024-byte messages, 24 kept offered) + Fast A->B 32 bytes at 10 Hz
  corrupt=1e-5..3  the same with that probability of a corrupted byte, both directions
  frameloss=N%     the same with N % of air packets lost, both directions
  outage=30s       the same with a 30 s outage of both directions starting at 20 s (90 s run)
  bidir            bulk Safe both ways (dual/single ratio of this row is a target)

  --json            one JSON object per scenario instead of the table
  --duration S      seconds of simulated time per scenario (default 60; the outage runs 30 s longer)
  --strict          exit status 1 when a target fails
)";

std::vector<Scenario> scenarios(Duration length) {
    std::vector<Scenario> list;
    for (std::uint32_t baud : {57600U, 115200U}) {
        for (LinkMode mode : {LinkMode::single, LinkMode::dual}) {
            Scenario base;
            base.baud = baud;
            base.mode = mode;
            base.duration = length;
            list.push_back(base);
            for (auto [label, p] :
                 {std::pair{"corrupt=1e-5", 1e-5}, {"corrupt=1e-4", 1e-4}, {"corrupt=1e-3", 1e-3}}) {
                Scenario s = base;
                s.impairment = label;
                s.byte_corruption = p;
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
            outage.duration = length + std::chrono::seconds(30);
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
    long seconds = 60;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--json") {
            json = true;
        } else if (arg == "--strict") {
            strict = true;
        } else if (arg == "--duration" && i + 1 < argc) {
            const std::string_view v = argv[++i];
            auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), seconds);
            if (ec != std::errc{} || ptr != v.data() + v.size() || seconds < 5 || seconds > 3600) {
                std::cerr << "linkbench: --duration wants whole seconds within [5, 3600], got '" << v
                          << "'\n";
                return 2;
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
    for (const Scenario& s : scenarios(std::chrono::seconds(seconds))) {
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
        print_targets(std::cout, checks);
    }
    bool failed = false;
    for (const auto& c : checks) {
        failed = failed || (c.evaluated && !c.pass);
    }
    return strict && failed ? 1 : 0;
}

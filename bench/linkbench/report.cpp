#include "bench/linkbench/report.hpp"

#include <cmath>
#include <functional>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

namespace airseg::linkbench {

namespace {

std::string fig(const ScenarioResult& r, double v, int precision) {
    if (!r.ran) {
        return "-";
    }
    if (std::isnan(v)) {
        return "n/a";
    }
    std::ostringstream os;
    os << std::fixed << std::setprecision(precision) << v;
    return os.str();
}

std::string pair(const Row& row, double ScenarioResult::*field, int precision) {
    return fig(row.ours, row.ours.*field, precision) + " / " + fig(row.seed, row.seed.*field, precision);
}

const Row* find(const std::vector<Row>& rows, std::uint32_t baud, LinkMode mode,
                const std::string& impairment) {
    for (const Row& r : rows) {
        if (r.scenario.baud == baud && r.scenario.mode == mode && r.scenario.impairment == impairment) {
            return &r;
        }
    }
    return nullptr;
}

nlohmann::json number(double v) {
    return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v);
}

std::string where(const Row& r) {
    return std::to_string(r.scenario.baud) + " " + to_string(r.scenario.mode) + " " + r.scenario.impairment;
}

}  // namespace

const char* to_string(LinkMode m) {
    return m == LinkMode::Single ? "single" : "dual";
}

void print_table(std::ostream& os, const std::vector<Row>& rows) {
    os << "figures are ours / seed; goodput = intact Safe payload as % of one line's rate (baud/10 B/s)\n";
    os << std::left << std::setw(7) << "baud" << std::setw(8) << "mode" << std::setw(15) << "impairment"
       << std::right << std::setw(17) << "goodput %" << std::setw(19) << "fast p50 ms" << std::setw(19)
       << "fast p99 ms" << std::setw(17) << "fast deliv %" << std::setw(15) << "max stall s" << std::setw(17)
       << "cmd p50 s" << std::setw(17) << "cmd p90 s" << '\n';
    for (const Row& r : rows) {
        os << std::left << std::setw(7) << r.scenario.baud << std::setw(8) << to_string(r.scenario.mode)
           << std::setw(15) << r.scenario.impairment << std::right << std::setw(17)
           << pair(r, &ScenarioResult::goodput_pct, 1) << std::setw(19)
           << pair(r, &ScenarioResult::fast_p50_ms, 0) << std::setw(19)
           << pair(r, &ScenarioResult::fast_p99_ms, 0) << std::setw(17)
           << pair(r, &ScenarioResult::fast_delivery_pct, 0) << std::setw(15)
           << pair(r, &ScenarioResult::max_stall_s, 1) << std::setw(17)
           << pair(r, &ScenarioResult::cmd_p50_s, 2) << std::setw(17)
           << pair(r, &ScenarioResult::cmd_p90_s, 2) << '\n';
    }
}

void print_diagnostics(std::ostream& os, const std::vector<Row>& rows) {
    os << "\ndiagnostics (ours / seed): wire = bytes written by A / by B on all pairs, % of one line's "
          "rate; run 2 = goodput each way in the run with Fast traffic\n";
    os << std::left << std::setw(7) << "baud" << std::setw(8) << "mode" << std::setw(15) << "impairment"
       << std::right << std::setw(17) << "wire A %" << std::setw(17) << "wire B %" << std::setw(17)
       << "air busy %" << std::setw(21) << "FIFO overflow B" << std::setw(19) << "run 2 A->B %"
       << std::setw(19) << "run 2 B->A %" << std::setw(14) << "air est %" << std::setw(15) << "turnaround ms"
       << '\n';
    for (const Row& r : rows) {
        os << std::left << std::setw(7) << r.scenario.baud << std::setw(8) << to_string(r.scenario.mode)
           << std::setw(15) << r.scenario.impairment << std::right << std::setw(17)
           << pair(r, &ScenarioResult::wire_ab_pct, 1) << std::setw(17)
           << pair(r, &ScenarioResult::wire_ba_pct, 1) << std::setw(17)
           << pair(r, &ScenarioResult::air_utilisation_pct, 1) << std::setw(21)
           << (fig(r.ours, static_cast<double>(r.ours.radio_overflow), 0) + " / " +
               fig(r.seed, static_cast<double>(r.seed.radio_overflow), 0))
           << std::setw(19) << pair(r, &ScenarioResult::fast_run_goodput_ab_pct, 1) << std::setw(19)
           << pair(r, &ScenarioResult::fast_run_goodput_ba_pct, 1) << std::setw(14)
           << fig(r.ours, r.ours.air_carried_pct, 1) << std::setw(15)
           << fig(r.ours, r.ours.air_turnaround_ms, 1) << '\n';
    }
}

std::vector<TargetCheck> check_targets(const std::vector<Row>& rows) {
    std::vector<TargetCheck> checks;
    auto add = [&](const std::string& name, const Row* row,
                   const std::function<bool(const ScenarioResult&)>& ok, double ScenarioResult::*shown) {
        if (row == nullptr) {
            return;
        }
        TargetCheck c;
        c.name = name + " [" + where(*row) + "]";
        c.evaluated = row->ours.ran;
        c.pass = row->ours.ran && ok(row->ours);
        c.seed_pass = row->seed.ran && ok(row->seed);
        c.detail =
            "ours " + fig(row->ours, row->ours.*shown, 1) + ", seed " + fig(row->seed, row->seed.*shown, 1);
        checks.push_back(std::move(c));
    };
    for (std::uint32_t baud : {57600U, 115200U}) {
        for (LinkMode mode : {LinkMode::Single, LinkMode::Dual}) {
            add(
                "clean goodput >= 95 %", find(rows, baud, mode, "clean"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 95.0; }, &ScenarioResult::goodput_pct);
            add(
                "bulk beside the vehicle's telemetry trickle: goodput >= 88 %",
                find(rows, baud, mode, "telemetry"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 88.0; }, &ScenarioResult::goodput_pct);
            add(
                "corruption 1e-4 goodput >= 85 %", find(rows, baud, mode, "corrupt=1e-4"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 85.0; }, &ScenarioResult::goodput_pct);
            add(
                "corruption 1e-3 goodput >= 65 %", find(rows, baud, mode, "corrupt=1e-3"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 65.0; }, &ScenarioResult::goodput_pct);
            add(
                "30 % frame loss: Safe delivered, stall <= 5 s", find(rows, baud, mode, "frameloss=30%"),
                [](const ScenarioResult& r) { return r.safe_messages > 0 && r.max_stall_s <= 5.0; },
                &ScenarioResult::max_stall_s);
            add(
                "1 % byte loss goodput >= 40 %", find(rows, baud, mode, "loss=1%"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 40.0; }, &ScenarioResult::goodput_pct);
            add(
                "2 % byte loss goodput >= 25 %", find(rows, baud, mode, "loss=2%"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 25.0; }, &ScenarioResult::goodput_pct);
            add(
                "2 % byte loss command round trip p50 <= 2 s", find(rows, baud, mode, "loss=2%"),
                [](const ScenarioResult& r) { return r.cmd_p50_s <= 2.0; }, &ScenarioResult::cmd_p50_s);
            add(
                "5 % byte loss command round trip p50 <= 5 s", find(rows, baud, mode, "loss=5%"),
                [](const ScenarioResult& r) { return r.cmd_p50_s <= 5.0; }, &ScenarioResult::cmd_p50_s);
            add(
                "32-byte air packets with 8 bytes of overhead, configured: goodput >= 60 %",
                find(rows, baud, mode, "pkt32+8 cfg"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 60.0; }, &ScenarioResult::goodput_pct);
            add(
                "10 ms turnaround, configured: goodput >= 75 %", find(rows, baud, mode, "turn10ms cfg"),
                [](const ScenarioResult& r) { return r.goodput_pct >= 75.0; }, &ScenarioResult::goodput_pct);
            for (const char* configured : {"pkt32+8 cfg", "turn10ms cfg", "turn20ms cfg"}) {
                add(
                    "configured radio: no radio buffer overflow", find(rows, baud, mode, configured),
                    [](const ScenarioResult& r) { return r.radio_overflow == 0; },
                    &ScenarioResult::goodput_pct);
            }
            add(
                "lost answer retried by a client started again: answered (p90 <= 10 s), none run twice "
                "(figure: run twice)",
                find(rows, baud, mode, "lost answer"),
                [](const ScenarioResult& r) {
                    // The last retried command may still be on its way when the run ends.
                    return r.cmd_retried > 0 && r.cmd_retried_answered >= 1 &&
                           r.cmd_retried_answered + 1 >= r.cmd_retried && r.cmd_applied_twice == 0 &&
                           r.cmd_p90_s <= 10.0;
                },
                &ScenarioResult::cmd_twice);
            // Told only the radio's buffer and measuring the rest: well above blind, far less overflow.
            for (const char* radio : {"pkt32+8", "turn10ms"}) {
                const Row* blind = find(rows, baud, mode, radio);
                const Row* measured = find(rows, baud, mode, std::string(radio) + " adapt");
                if (blind == nullptr || !blind->ours.ran || blind->scenario.radio_adapt) {
                    continue;  // (with --adapt every row measures: there is no blind row to compare)
                }
                const ScenarioResult b = blind->ours;
                add(
                    "measured air: goodput >= 50 % and >= 1.5 x blind, radio overflow <= a third of blind",
                    measured,
                    [b](const ScenarioResult& r) {
                        return r.goodput_pct >= 50.0 && r.goodput_pct >= 1.5 * b.goodput_pct &&
                               3 * r.radio_overflow <= b.radio_overflow;
                    },
                    &ScenarioResult::goodput_pct);
            }
            if (baud == 57600) {
                add(
                    "Fast p99 <= 150 ms under saturating bulk", find(rows, baud, mode, "clean"),
                    [](const ScenarioResult& r) {
                        return !std::isnan(r.fast_p99_ms) && r.fast_p99_ms <= 150.0;
                    },
                    &ScenarioResult::fast_p99_ms);
            }
        }
        for (LinkMode mode : {LinkMode::Single, LinkMode::Dual}) {
            const Row* alone = find(rows, baud, mode, "clean");
            const Row* both = find(rows, baud, mode, "bidir+fast");
            if (alone == nullptr || both == nullptr) {
                continue;
            }
            // Each direction keeps a third of what one direction alone carries, and no Safe message waits
            // more than 5 s, with bulk and Fast traffic both ways.
            TargetCheck c;
            c.name =
                "bulk and Fast both ways: each direction >= 33 % of one direction alone, stall <= 5 s [" +
                where(*both) + "]";
            const auto fair = [&](const ScenarioResult& b, const ScenarioResult& a) {
                const double floor = a.goodput_pct / 3.0;
                return b.fast_run_goodput_ab_pct >= floor && b.fast_run_goodput_ba_pct >= floor &&
                       b.fast_run_stall_ab_s <= 5.0 && b.fast_run_stall_ba_s <= 5.0;
            };
            c.evaluated = both->ours.ran && alone->ours.ran;
            c.pass = c.evaluated && fair(both->ours, alone->ours);
            c.seed_pass = both->seed.ran && alone->seed.ran && fair(both->seed, alone->seed);
            std::ostringstream d;
            d << std::fixed << std::setprecision(1);
            for (const auto* side : {&both->ours, &both->seed}) {
                d << (side == &both->ours ? "ours" : ", seed") << " A->B " << side->fast_run_goodput_ab_pct
                  << " % (stall " << side->fast_run_stall_ab_s << " s), B->A "
                  << side->fast_run_goodput_ba_pct << " % (stall " << side->fast_run_stall_ba_s << " s)";
            }
            d << " of " << alone->ours.goodput_pct << " / " << alone->seed.goodput_pct << " % alone";
            c.detail = d.str();
            checks.push_back(std::move(c));
        }
        const Row* single = find(rows, baud, LinkMode::Single, "bidir");
        const Row* dual = find(rows, baud, LinkMode::Dual, "bidir");
        if (single != nullptr && dual != nullptr) {
            auto ratio = [](const ScenarioResult& d, const ScenarioResult& s) {
                return s.goodput_pct > 0.0 ? d.goodput_pct / s.goodput_pct : 0.0;
            };
            TargetCheck c;
            c.name = "dual split >= 1.9 x single, both directions saturated [" + std::to_string(baud) + "]";
            c.evaluated = single->ours.ran && dual->ours.ran;
            c.pass = c.evaluated && ratio(dual->ours, single->ours) >= 1.9;
            c.seed_pass = ratio(dual->seed, single->seed) >= 1.9;
            std::ostringstream d;
            d << std::fixed << std::setprecision(2) << "ours ";
            if (c.evaluated) {
                d << ratio(dual->ours, single->ours);
            } else {
                d << '-';
            }
            d << ", seed " << ratio(dual->seed, single->seed);
            c.detail = d.str();
            checks.push_back(std::move(c));
        }
    }
    return checks;
}

void print_targets(std::ostream& os, const std::vector<TargetCheck>& checks) {
    os << "\ntargets (ours; the seed's verdict in brackets)\n";
    for (const auto& c : checks) {
        os << (c.evaluated ? (c.pass ? "PASS " : "FAIL ") : "n/a  ") << "(" << (c.seed_pass ? "pass" : "fail")
           << ")  " << c.name << ": " << c.detail << '\n';
    }
}

void print_json(std::ostream& os, const std::vector<Row>& rows) {
    for (const Row& r : rows) {
        nlohmann::json j;
        j["baud"] = r.scenario.baud;
        j["mode"] = to_string(r.scenario.mode);
        j["impairment"] = r.scenario.impairment;
        j["duration_s"] = std::chrono::duration<double>(r.scenario.duration).count();
        auto put = [&j](const std::string& prefix, const ScenarioResult& x) {
            if (!x.ran) {
                j[prefix + "goodput_pct"] = nullptr;
                return;
            }
            j[prefix + "goodput_pct"] = x.goodput_pct;
            j[prefix + "fast_p50_ms"] = number(x.fast_p50_ms);
            j[prefix + "fast_p99_ms"] = number(x.fast_p99_ms);
            j[prefix + "fast_delivery_pct"] = x.fast_delivery_pct;
            j[prefix + "max_stall_s"] = x.max_stall_s;
            j[prefix + "cmd_p50_s"] = number(x.cmd_p50_s);
            j[prefix + "cmd_p90_s"] = number(x.cmd_p90_s);
            j[prefix + "cmd_sent"] = x.cmd_sent;
            j[prefix + "cmd_answered"] = x.cmd_answered;
            j[prefix + "cmd_retried"] = x.cmd_retried;
            j[prefix + "cmd_retried_answered"] = x.cmd_retried_answered;
            j[prefix + "cmd_applied_twice"] = x.cmd_applied_twice;
            j[prefix + "safe_messages"] = x.safe_messages;
            j[prefix + "damaged_deliveries"] = x.damaged_deliveries;
            j[prefix + "wire_ab_pct"] = x.wire_ab_pct;
            j[prefix + "wire_ba_pct"] = x.wire_ba_pct;
            j[prefix + "air_utilisation_pct"] = x.air_utilisation_pct;
            j[prefix + "radio_overflow_bytes"] = x.radio_overflow;
        };
        put("", r.ours);
        put("seed_", r.seed);
        os << j.dump() << '\n';
    }
}

}  // namespace airseg::linkbench

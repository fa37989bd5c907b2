#pragma once
// The checks every system scenario ends with: Safe messages neither lost nor duplicated, plan progress intact
// on the board, the daemon alive. Plans are straight lines expanded with the flight plan library, as the
// board should reach them.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/reached_log.hpp"
#include "tests/support/system_bench.hpp"

namespace airseg::test::sys {

using Json = nlohmann::json;
constexpr auto kGenerous = std::chrono::seconds(90);
constexpr auto kPoll = std::chrono::milliseconds(250);

inline std::uint64_t counter(const Json& doc, const std::string& pointer) {
    const auto p = Json::json_pointer(pointer);
    return doc.contains(p) && doc[p].is_number() ? doc[p].get<std::uint64_t>() : 0;
}

/// A section of the status document, or {} while it is missing or null (a status call can time out).
inline Json section(const Json& doc, const std::string& name) {
    const auto it = doc.find(name);
    return it != doc.end() && it->is_object() ? *it : Json::object();
}

/// Commands the ground link received (the status document from the local socket is not one).
inline std::uint64_t ground_commands(SystemBench& bench) {
    return counter(bench.status(), "/groundlink/commands");
}

/// Result of sending uniquely identifiable commands over the radio: `rates vehicle=V`, V different for each,
/// answered with that V in requested_hz.
struct CommandTally {
    int sent = 0;
    int answered = 0;      // exit 0 with the command's own value
    int wrong_answer = 0;  // an answer that is not this command's
    int failed = 0;        // no answer / refused
    std::vector<std::string> problems;
};

/// A value no other command of the run uses: 0.5, 0.6, ... Hz (rates.set accepts 0..20 Hz).
inline double unique_rate(int serial) {
    return std::round((0.5 + 0.1 * serial) * 10.0) / 10.0;
}

inline std::string rate_text(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

/// How many times airsegd's log shows the radio request `rates vehicle=V` arriving (it logs each request it
/// executes, before answering it).
inline int times_requested(SystemBench& bench, double v) {
    const std::string log = bench.daemon_err();
    // Its request id (airsegctl adds one) follows the rates in the logged request.
    const std::string needle = "{\"cmd\":\"rates.set\",\"rates\":{\"vehicle\":" + Json(v).dump() + "}";
    int n = 0;
    for (auto at = log.find(needle); at != std::string::npos; at = log.find(needle, at + needle.size())) {
        ++n;
    }
    return n;
}

/// One uniquely identifiable command over the radio; counts it into `tally`.
inline void send_unique(SystemBench& bench, int serial, CommandTally& tally, long timeout_ms = 60'000) {
    const double v = unique_rate(serial);
    ++tally.sent;
    const auto r = bench.ctl({"rates", "vehicle=" + rate_text(v)}, timeout_ms);
    const auto j = Json::parse(r.out, nullptr, false);
    if (r.exit_code != 0 || !j.is_object()) {
        ++tally.failed;
        tally.problems.push_back("#" + std::to_string(serial) + ": exit " + std::to_string(r.exit_code) +
                                 " " + r.out + r.err);
        return;
    }
    const auto got = j.value("requested_hz", Json::object()).value("vehicle", -1.0);
    if (std::abs(got - v) > 1e-6) {
        ++tally.wrong_answer;
        tally.problems.push_back("#" + std::to_string(serial) + ": answer for " + rate_text(got));
        return;
    }
    ++tally.answered;
}

/// Every command answered exactly once with its own answer, and the daemon counted exactly that many.
inline void expect_each_answered_once(const CommandTally& t, std::uint64_t commands_before,
                                      std::uint64_t commands_after) {
    std::string why;
    for (const auto& p : t.problems) {
        why += p + "\n";
    }
    EXPECT_EQ(t.answered, t.sent) << why;
    EXPECT_EQ(t.wrong_answer, 0) << why;
    EXPECT_EQ(commands_after - commands_before, static_cast<std::uint64_t>(t.sent))
        << "the ground link received each command exactly once";
}

inline void expect_daemon_alive(SystemBench& bench) {
    EXPECT_TRUE(bench.daemon_running()) << bench.daemon_err();
    const auto doc = bench.status();
    EXPECT_TRUE(doc.contains("services")) << "status answers on the local socket: " << doc.dump();
}

// ---- plans ---------------------------------------------------------------------------------------------

/// A straight line of `count` waypoints north of home, `step` metres apart.
inline std::string line_plan(const std::string& name, int count, double step, double east_m = 8) {
    std::ostringstream o;
    o.precision(10);
    o << "plan:\n  name: " << name << "\n  elements:\n";
    const double lat = SystemBench::kHomeLat, lon = SystemBench::kHomeLon;
    for (int i = 0; i < count; ++i) {
        o << "    - waypoint: {lat: " << lat + (step * (i + 1)) / 111320.0
          << ", lon: " << lon + east_m / (111320.0 * std::cos(lat * std::numbers::pi / 180.0)) << "}\n";
    }
    return o.str();
}

inline Json plan_section(SystemBench& bench) {
    return section(bench.status(), "plan");
}

/// The reached events as plan waypoint indices ("?" for a place not in the plan), for failure messages.
inline std::string as_indices(const std::vector<Reached>& log, const std::vector<E7>& expected) {
    std::string out;
    for (const auto& r : log) {
        std::string idx = "?";
        for (std::size_t k = 0; k < expected.size(); ++k) {
            if (same_place(r.at, expected[k])) {
                idx = std::to_string(k);
                break;
            }
        }
        out += idx + " ";
    }
    return out;
}

/// The board reached `expected[from..]` in order, each once: the reached events `log` (those after the
/// plan's start) may begin with waypoints before `from` only as a prefix of the plan (a replay from an
/// earlier position is a failure), and after the end only the final stop repeats.
inline void expect_reached_in_order(const std::vector<Reached>& log, const std::vector<E7>& expected,
                                    std::size_t first_index = 0) {
    ASSERT_FALSE(expected.empty());
    std::size_t i = 0;
    for (std::size_t k = first_index; k < expected.size(); ++k, ++i) {
        ASSERT_LT(i, log.size()) << "waypoint " << k << " of " << expected.size() << " never reached";
        ASSERT_PRED2(same_place, log[i].at, expected[k]) << "reached event #" << i << " is not waypoint " << k
                                                         << "; reached: " << as_indices(log, expected);
    }
    for (; i < log.size(); ++i) {
        EXPECT_PRED2(same_place, log[i].at, expected.back()) << "after the end, only the final stop";
    }
    EXPECT_LE(log.size(), expected.size() - first_index + 1);
}

/// Plan progress through a fault that makes waypoints be driven again: every event is either the next
/// waypoint or an earlier one (a replay: driving on from there); never a later one (a skip) or a place
/// outside the plan; every waypoint is reached. Returns the number of events of waypoints reached before.
inline std::size_t expect_no_skip(const std::vector<Reached>& log, const std::vector<E7>& expected) {
    std::size_t high = 0, replays = 0;  // high: the first waypoint never reached
    for (std::size_t i = 0; i < log.size(); ++i) {
        std::size_t k = expected.size();
        for (std::size_t j = 0; j < expected.size(); ++j) {
            if (same_place(log[i].at, expected[j])) {
                k = j;
                break;
            }
        }
        if (k == expected.size()) {
            ADD_FAILURE() << "reached event #" << i
                          << " is no plan waypoint; reached: " << as_indices(log, expected);
            return replays;
        }
        if (high == expected.size() && k + 1 == expected.size()) {
            continue;  // the final stop
        }
        if (k > high) {
            ADD_FAILURE() << "waypoint " << high << " skipped; reached: " << as_indices(log, expected);
            return replays;
        }
        replays += k < high ? 1 : 0;  // a waypoint reached before, driven again
        high = std::max(high, k + 1);
    }
    EXPECT_EQ(high, expected.size()) << "reached: " << as_indices(log, expected);
    return replays;
}

}  // namespace airseg::test::sys

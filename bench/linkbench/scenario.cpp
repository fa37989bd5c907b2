#include "bench/linkbench/scenario.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "services/common/command_record.hpp"
#include "tools/linksim/radio_model.hpp"

namespace airseg::linkbench {

namespace {

using linksim::Side;

constexpr std::size_t kSafeSize = 1024;
constexpr std::size_t kFastSize = 32;
constexpr Duration kFastPeriod = std::chrono::milliseconds(100);
constexpr std::uint16_t kFastStreams = 8;
constexpr std::uint32_t kFastBackBit = 1U << 30;  // Fast ids sent B→A
constexpr std::size_t kBulkBacklog = 24;          // Safe messages the application keeps offered
constexpr Duration kStep = std::chrono::milliseconds(1);
// lost_answers: how long B's radio is silent as the command arrives, and how long its client waits.
constexpr Duration kLostAnswerOutage = std::chrono::seconds(6);
constexpr Duration kClientGivesUp = std::chrono::seconds(3);

// Message content: a 4-byte id (little-endian) then bytes derived from it, so damage is detectable.
std::vector<std::uint8_t> make_payload(std::uint32_t id, std::size_t size, std::uint8_t salt) {
    std::vector<std::uint8_t> p(size);
    for (std::size_t i = 0; i < size; ++i) {
        p[i] = i < 4 ? static_cast<std::uint8_t>(id >> (8 * i))
                     : static_cast<std::uint8_t>(id * 31 + i * 7 + salt);
    }
    return p;
}

std::optional<std::uint32_t> check_payload(const std::vector<std::uint8_t>& p, std::size_t size,
                                           std::uint8_t salt) {
    if (p.size() != size) {
        return std::nullopt;
    }
    const std::uint32_t id = static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
                             static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
    return p == make_payload(id, size, salt) ? std::optional(id) : std::nullopt;
}

constexpr std::uint8_t kSaltSafeAB = 1;
constexpr std::uint8_t kSaltSafeBA = 2;
constexpr std::uint8_t kSaltFast = 3;
constexpr std::uint8_t kSaltCommand = 4;
constexpr std::uint8_t kSaltAnswer = 5;
constexpr std::uint8_t kSaltTelemetry = 6;
// airsegd's own telemetry to the ground: the vehicle's state at 2 Hz, the link statistics at 1 Hz.
constexpr std::size_t kVehicleBytes = 48;
constexpr std::size_t kLinkStatsBytes = 37;
constexpr Duration kCommandPause = std::chrono::milliseconds(500);  // operator's pause between commands

double percentile(std::vector<double> v, double q) {
    if (v.empty()) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    std::sort(v.begin(), v.end());
    const auto i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
    return v[std::min(i, v.size() - 1)];
}

double ms(Duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
}

// A frame the protocol handed over, being written to the host UART as a blocking write would.
struct PendingWrite {
    std::vector<std::uint8_t> bytes;
    std::size_t written = 0;
    bool empty() const { return written >= bytes.size(); }
};

}  // namespace

linksim::RadioConfig bench_radio(const Scenario& s, std::uint64_t seed) {
    linksim::RadioConfig c;
    c.baud = s.baud;
    c.duplex = linksim::Duplex::Half;
    c.turnaround = s.turnaround;
    c.max_air_packet = s.air_packet;
    c.air_packet_overhead = s.air_packet_overhead;
    c.radio_buffer = 2048;
    c.host_buffer = 4096;
    c.seed = seed;
    for (auto& d : c.impairment) {
        d.byte_corruption = s.byte_corruption;
        d.byte_loss = s.byte_loss;
        d.bit_error_rate = s.bit_error_rate;
        d.frame_loss = s.frame_loss;
        if (s.outage) {
            d.outages.push_back(*s.outage);
        }
    }
    return c;
}

namespace {

EndpointSetup setup(const Scenario& s, bool is_a, TimePoint t0, std::uint32_t incarnation = 0) {
    EndpointSetup e{s.baud, s.mode, is_a, incarnation, t0, s.pacing_factor, std::nullopt};
    if (s.radio_configured || s.radio_adapt) {
        const auto radio = bench_radio(s, 0);
        e.radio = EndpointSetup::Radio{radio.turnaround,   radio.max_air_packet, radio.air_packet_overhead,
                                       radio.radio_buffer, s.radio_configured,   s.radio_adapt};
    }
    return e;
}

// Two ends joined by the scenario's radio pairs, with a blocking-write model of each host UART; both runs
// drive it the same way: deliver what the radios output, then write what the ends have to send.
struct Wiring {
    Wiring(const Scenario& s, const EndpointFactory& make, std::uint64_t seed, TimePoint t0)
        : paths(s.mode == LinkMode::Dual ? 2 : 1), ends{make(setup(s, true, t0)), make(setup(s, false, t0))} {
        for (std::size_t p = 0; p < paths; ++p) {
            pairs.emplace_back(bench_radio(s, seed + p), t0);
        }
    }
    [[nodiscard]] bool ready() const { return ends[0] && ends[1]; }

    /// The end at `side` as a program started again: a new session, and nothing of the old one's half-written
    /// frame.
    void restart(Side side, const Scenario& s, const EndpointFactory& make, TimePoint now,
                 std::uint32_t incarnation) {
        ends[linksim::index(side)] = make(setup(s, side == Side::A, now, incarnation));
        for (auto& w : pending[linksim::index(side)]) {
            w = PendingWrite{};
        }
    }

    /// Radio output to the ends, due timeouts, then every delivered message to `on_message(side, m, now)`.
    template <typename OnMessage>
    void deliver(TimePoint now, OnMessage&& on_message) {
        for (std::size_t p = 0; p < paths; ++p) {
            for (Side side : {Side::A, Side::B}) {
                auto bytes = pairs[p].poll_output(side, now);
                if (!bytes.empty()) {
                    ends[linksim::index(side)]->handle_bytes(p, bytes, now);
                }
            }
        }
        for (Side side : {Side::A, Side::B}) {
            auto& e = *ends[linksim::index(side)];
            if (e.poll_timeout() <= now) {
                e.handle_timeout(now);
            }
            while (auto m = e.poll_message()) {
                on_message(side, *m, now);
            }
        }
    }

    /// Frames the ends have ready, into the UARTs until one is full (the write blocks until it drains).
    void transmit(TimePoint now) {
        for (Side side : {Side::A, Side::B}) {
            for (std::size_t p = 0; p < paths; ++p) {
                auto& w = pending[linksim::index(side)][p];
                while (true) {
                    if (w.empty()) {
                        auto frame = ends[linksim::index(side)]->poll_transmit(p, now);
                        if (!frame) {
                            break;
                        }
                        w = PendingWrite{std::move(*frame), 0};
                    }
                    w.written += pairs[p].push(side, std::span(w.bytes).subspan(w.written), now);
                    if (!w.empty()) {
                        break;
                    }
                }
            }
        }
    }

    std::size_t paths;
    std::vector<linksim::RadioModel> pairs;
    std::array<std::unique_ptr<BenchEndpoint>, 2> ends;
    std::array<std::array<PendingWrite, 2>, 2> pending{};  // [side][path]
};

// One simulated run. Without Fast traffic it measures bulk goodput and stalls; with it, Fast latency and
// delivery while the same bulk load saturates the link.
ScenarioResult run_pass(const Scenario& s, const EndpointFactory& make, bool with_fast) {
    ScenarioResult result;
    const TimePoint t0{};
    const TimePoint end = t0 + s.duration;

    Wiring wiring(s, make, s.seed, t0);
    if (!wiring.ready()) {
        return result;
    }
    auto& ends = wiring.ends;
    auto& pairs = wiring.pairs;

    std::array<std::uint32_t, 2> next_safe_id{0, 0};
    std::array<std::vector<bool>, 2> safe_seen;  // by receiving side
    std::array<std::uint64_t, 2> safe_bytes{0, 0};
    TimePoint last_ab_delivery = t0;
    Duration max_stall{0};
    std::array<TimePoint, 2> last_delivery{t0, t0};  // by receiving side
    std::array<Duration, 2> longest_gap{};

    std::uint32_t next_fast_id = 0;
    TimePoint next_fast = t0;
    std::map<std::uint32_t, TimePoint> fast_sent;
    std::vector<double> fast_latency;
    std::uint64_t fast_counted = 0;
    std::uint64_t fast_delivered_counted = 0;
    const TimePoint fast_count_until = end - std::chrono::seconds(2);

    auto on_message = [&](Side to, const BenchMessage& m, TimePoint now) {
        if (!m.safe && m.bytes.size() != kFastSize) {
            if (!check_payload(m.bytes, m.bytes.size(), kSaltTelemetry)) {
                ++result.damaged_deliveries;
            }
            return;
        }
        if (!m.safe) {
            auto id = check_payload(m.bytes, kFastSize, kSaltFast);
            if (!id) {
                ++result.damaged_deliveries;
                return;
            }
            auto it = fast_sent.find(*id);
            if (it != fast_sent.end()) {
                fast_latency.push_back(ms(now - it->second));
                if (it->second <= fast_count_until) {
                    ++fast_delivered_counted;
                }
                fast_sent.erase(it);
            }
            return;
        }
        const std::uint8_t salt = to == Side::B ? kSaltSafeAB : kSaltSafeBA;
        auto id = check_payload(m.bytes, kSafeSize, salt);
        if (!id) {
            ++result.damaged_deliveries;
            return;
        }
        auto& seen = safe_seen[linksim::index(to)];
        if (*id >= seen.size()) {
            seen.resize(*id + 1, false);
        }
        if (seen[*id]) {
            return;
        }
        seen[*id] = true;
        safe_bytes[linksim::index(to)] += m.bytes.size();
        ++result.safe_messages;
        auto& last = last_delivery[linksim::index(to)];
        longest_gap[linksim::index(to)] = std::max(longest_gap[linksim::index(to)], now - last);
        last = now;
        if (to == Side::B) {
            max_stall = std::max(max_stall, now - last_ab_delivery);
            last_ab_delivery = now;
        }
    };

    TimePoint next_vehicle = t0;
    TimePoint next_link_stats = t0;
    std::uint32_t telemetry_id = 0;
    for (TimePoint now = t0; now <= end;) {
        wiring.deliver(now, on_message);
        while (s.telemetry_from_b && next_vehicle <= now) {
            ends[1]->send_fast(0, make_payload(telemetry_id++, kVehicleBytes, kSaltTelemetry), now);
            next_vehicle += std::chrono::milliseconds(500);
        }
        while (s.telemetry_from_b && next_link_stats <= now) {
            ends[1]->send_fast(1, make_payload(telemetry_id++, kLinkStatsBytes, kSaltTelemetry), now);
            next_link_stats += std::chrono::seconds(1);
        }
        // Workload: Fast telemetry A→B at 10 Hz, bulk Safe kept offered.
        while (with_fast && next_fast <= now) {
            const auto payload = make_payload(next_fast_id, kFastSize, kSaltFast);
            ends[0]->send_fast(static_cast<std::uint16_t>(next_fast_id % kFastStreams), payload, now);
            fast_sent[next_fast_id] = now;
            if (now <= fast_count_until) {
                ++fast_counted;
            }
            if (s.fast_both_ways) {
                const std::uint32_t back = next_fast_id | kFastBackBit;
                ends[1]->send_fast(static_cast<std::uint16_t>(next_fast_id % kFastStreams),
                                   make_payload(back, kFastSize, kSaltFast), now);
                fast_sent[back] = now;
                if (now <= fast_count_until) {
                    ++fast_counted;
                }
            }
            ++next_fast_id;
            next_fast += kFastPeriod;
        }
        for (Side side : {Side::A, Side::B}) {
            if (side == Side::B && !s.bidirectional) {
                break;
            }
            auto& e = *ends[linksim::index(side)];
            const std::uint8_t salt = side == Side::A ? kSaltSafeAB : kSaltSafeBA;
            auto& id = next_safe_id[linksim::index(side)];
            while (e.safe_backlog() < kBulkBacklog && e.send_safe(make_payload(id, kSafeSize, salt), now)) {
                ++id;
            }
        }
        wiring.transmit(now);
        const TimePoint fast_due = with_fast ? next_fast : kNever;
        const TimePoint telemetry_due = s.telemetry_from_b ? std::min(next_vehicle, next_link_stats) : kNever;
        TimePoint next = std::min(
            {now + kStep, fast_due, telemetry_due, ends[0]->poll_timeout(), ends[1]->poll_timeout()});
        now = std::max(next, now + std::chrono::microseconds(10));
    }
    max_stall = std::max(max_stall, end - last_ab_delivery);
    for (std::size_t to = 0; to < 2; ++to) {
        longest_gap[to] = std::max(longest_gap[to], end - last_delivery[to]);
    }

    const double line = s.baud / 10.0;
    const double seconds = std::chrono::duration<double>(s.duration).count();
    result.ran = true;
    result.goodput_pct = 100.0 * static_cast<double>(safe_bytes[0] + safe_bytes[1]) / (line * seconds);
    result.fast_p50_ms = percentile(fast_latency, 0.50);
    result.fast_p99_ms = percentile(fast_latency, 0.99);
    result.fast_delivery_pct = fast_counted == 0 ? 0.0
                                                 : 100.0 * static_cast<double>(fast_delivered_counted) /
                                                       static_cast<double>(fast_counted);
    result.max_stall_s = std::chrono::duration<double>(max_stall).count();
    // Received by B: sent A→B.
    result.fast_run_goodput_ab_pct = 100.0 * static_cast<double>(safe_bytes[1]) / (line * seconds);
    result.fast_run_goodput_ba_pct = 100.0 * static_cast<double>(safe_bytes[0]) / (line * seconds);
    result.fast_run_stall_ab_s = std::chrono::duration<double>(longest_gap[1]).count();
    result.fast_run_stall_ba_s = std::chrono::duration<double>(longest_gap[0]).count();
    result.air_utilisation_pct = 100.0 * pairs[0].air_utilisation(Side::A, end);
    if (const auto air = ends[0]->air_measure()) {
        result.air_carried_pct = 100.0 * air->carried / line;
    }
    for (const auto& pair : pairs) {
        result.wire_ab_pct += 100.0 * static_cast<double>(pair.stats(Side::A).bytes_in) / (line * seconds);
        result.wire_ba_pct += 100.0 * static_cast<double>(pair.stats(Side::B).bytes_in) / (line * seconds);
        result.radio_overflow += pair.stats(Side::A).overflow_dropped + pair.stats(Side::B).overflow_dropped;
    }
    return result;
}

// Commands A→B, one at a time, each answered B→A at once; B pushes telemetry as airsegd does.
void run_commands(const Scenario& s, const EndpointFactory& make, ScenarioResult& result) {
    const TimePoint t0{};
    const TimePoint end = t0 + s.duration;
    Wiring wiring(s, make, s.seed + 1000, t0);
    auto& ends = wiring.ends;

    std::uint32_t next_id = 0;
    bool in_flight = false;
    TimePoint sent_at = t0;    // of the command in flight, first sent
    TimePoint resend_at = t0;  // when its client gives up and starts again (lost_answers)
    bool retried = false;      // the command in flight was sent again
    std::uint32_t incarnation = 0;
    TimePoint next_command = t0 + std::chrono::seconds(2);
    std::vector<double> rtt;
    std::vector<std::uint32_t> to_answer;
    TimePoint next_vehicle = t0;
    TimePoint next_link_stats = t0;
    std::uint32_t telemetry_id = 0;
    const bool with_record = ends[1]->request_ids();
    CommandRecord record;
    std::map<std::uint32_t, int> applied;  // by command id: times the vehicle ran it
    std::set<std::uint32_t> silenced;      // commands whose answer the radio lost

    // The vehicle: each command once per request id when it keeps a record, every time it arrives without.
    auto run_command = [&](std::uint32_t id, TimePoint now) {
        if (s.lost_answers && id % 4 == 1 && silenced.insert(id).second) {
            wiring.pairs[0].add_outage(Side::B, now, kLostAnswerOutage);
        }
        if (!with_record) {
            ++applied[id];
            to_answer.push_back(id);
            return;
        }
        const auto admit = record.admit(std::to_string(id), id, now,
                                        [&to_answer, id](const CommandResult&) { to_answer.push_back(id); });
        if (admit == CommandRecord::Admit::Run) {
            ++applied[id];
            record.finish(std::to_string(id), id, CommandResult::ok(), now);
            to_answer.push_back(id);
        }
    };

    auto on_message = [&](Side to, const BenchMessage& m, TimePoint now) {
        if (!m.safe) {
            return;
        }
        if (to == Side::B) {
            if (auto id = check_payload(m.bytes, kCommandBytes, kSaltCommand)) {
                run_command(*id, now);
            } else {
                ++result.damaged_deliveries;
            }
            return;
        }
        auto id = check_payload(m.bytes, kAnswerBytes, kSaltAnswer);
        if (!id) {
            ++result.damaged_deliveries;
            return;
        }
        if (in_flight && *id + 1 == next_id) {
            rtt.push_back(std::chrono::duration<double>(now - sent_at).count());
            ++result.cmd_answered;
            if (retried) {
                ++result.cmd_retried_answered;
            }
            in_flight = false;
            next_command = now + kCommandPause;
        }
    };

    for (TimePoint now = t0; now <= end;) {
        wiring.deliver(now, on_message);
        for (const std::uint32_t id : to_answer) {
            ends[1]->send_urgent(make_payload(id, kAnswerBytes, kSaltAnswer), now);
        }
        to_answer.clear();
        if (!in_flight && now >= next_command) {
            if (ends[0]->send_urgent(make_payload(next_id, kCommandBytes, kSaltCommand), now)) {
                ++next_id;
                ++result.cmd_sent;
                in_flight = true;
                retried = false;
                sent_at = now;
                resend_at = now + kClientGivesUp;
            }
        }
        if (s.lost_answers && in_flight && now >= resend_at) {
            // The operator's client timed out: started again, it sends the same command, same request id.
            wiring.restart(Side::A, s, make, now, ++incarnation);
            ends[0]->send_urgent(make_payload(next_id - 1, kCommandBytes, kSaltCommand), now);
            if (!retried) {
                ++result.cmd_retried;
            }
            retried = true;
            resend_at = now + kClientGivesUp;
        }
        while (next_vehicle <= now) {
            ends[1]->send_fast(0, make_payload(telemetry_id++, 48, kSaltFast), now);
            next_vehicle += std::chrono::milliseconds(500);
        }
        while (next_link_stats <= now) {
            ends[1]->send_fast(1, make_payload(telemetry_id++, 37, kSaltFast), now);
            next_link_stats += std::chrono::seconds(1);
        }
        wiring.transmit(now);
        TimePoint next = std::min(
            {now + kStep, next_vehicle, next_link_stats, ends[0]->poll_timeout(), ends[1]->poll_timeout()});
        if (!in_flight) {
            next = std::min(next, next_command);
        } else if (s.lost_answers) {
            next = std::min(next, resend_at);
        }
        now = std::max(next, now + std::chrono::microseconds(10));
    }
    for (const auto& [id, times] : applied) {
        if (times > 1) {
            ++result.cmd_applied_twice;
        }
    }
    result.cmd_twice = static_cast<double>(result.cmd_applied_twice);
    // A command still unanswered long after it was sent counts; one sent just before the end does not.
    if (in_flight && end - sent_at > std::chrono::seconds(5)) {
        rtt.push_back(std::numeric_limits<double>::infinity());
    }
    result.cmd_p50_s = percentile(rtt, 0.50);
    result.cmd_p90_s = percentile(rtt, 0.90);
    if (const auto air = ends[0]->air_measure(); air && air->turnaround_ms >= 0.0) {
        result.air_turnaround_ms = air->turnaround_ms;
    }
}

}  // namespace

ScenarioResult run_scenario(const Scenario& s, const EndpointFactory& make) {
    ScenarioResult bulk = run_pass(s, make, false);
    if (!bulk.ran) {
        return bulk;
    }
    const ScenarioResult mixed = run_pass(s, make, true);
    bulk.fast_p50_ms = mixed.fast_p50_ms;
    bulk.fast_p99_ms = mixed.fast_p99_ms;
    bulk.fast_delivery_pct = mixed.fast_delivery_pct;
    bulk.fast_run_goodput_ab_pct = mixed.fast_run_goodput_ab_pct;
    bulk.fast_run_goodput_ba_pct = mixed.fast_run_goodput_ba_pct;
    bulk.fast_run_stall_ab_s = mixed.fast_run_stall_ab_s;
    bulk.fast_run_stall_ba_s = mixed.fast_run_stall_ba_s;
    bulk.damaged_deliveries += mixed.damaged_deliveries;
    run_commands(s, make, bulk);
    return bulk;
}

}  // namespace airseg::linkbench

// The ground-link transport's cost per delivered byte: two cores on a simulated 57600-baud half-duplex radio
// pair, driven as airsegd drives one (driven_link.hpp), with the traffic airsegd and airsegctl exchange.
// Deterministic: the same run always makes the same calls, so callgrind's instruction counts repeat exactly.
// bench/transport/callgrind.sh runs it under callgrind and prints instructions per delivered payload byte.
//
//   bench_transport [--scenario=upload|telemetry] [--seconds=N] [--read=BYTES] [--unkeyed]
//                   [--measure=none|a|b|both|poll_transmit]
#include <cstdio>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bench/transport/driven_link.hpp"
#include "cli/command_line.hpp"

namespace {

using namespace airseg;
using namespace airseg::transport_bench;
namespace gl = airseg::groundlink;

constexpr int kAir = 0;     // airsegd
constexpr int kGround = 1;  // airsegctl
// Priorities and topics of the ground protocol (services/groundlink/protocol/ground_protocol.hpp).
constexpr std::uint8_t kControl = 0;
constexpr std::uint8_t kTelemetry = 1;
constexpr std::uint8_t kStatus = 2;
constexpr std::uint8_t kBulk = 3;
// Encoded sizes of the ground protocol's messages.
constexpr std::size_t kTelemetryBytes = 29;
constexpr std::size_t kLinkStatsBytes = 18;
constexpr std::size_t kReceptionBytes = 6;
constexpr std::size_t kCommandBytes = 40;
constexpr std::size_t kResultBytes = 300;
constexpr std::size_t kEventBytes = 80;
constexpr double kAirRate = 5760.0;  // 57600 baud, 8N1

struct Options {
    std::string scenario = "upload";
    double seconds = 60.0;
    std::size_t read_bytes = 16;
    bool keyed = true;
    Selection measure = Selection::None;
};

/// One of names' keys, or a UsageError that lists them.
template <class T>
cli::Apply one_of(T& target, std::map<std::string, T, std::less<>> names, std::string wanted) {
    return [&target, names = std::move(names), wanted = std::move(wanted)](std::string_view option,
                                                                           std::string_view text) {
        const auto it = names.find(text);
        if (it == names.end()) {
            throw cli::UsageError(std::string(option) + ": expected " + wanted + ", got '" +
                                  std::string(text) + "'");
        }
        target = it->second;
    };
}

/// The options, or the exit code after --help or a bad command line.
std::optional<int> parse(int argc, char** argv, Options& o) {
    cli::OptionTable table("Options");
    table
        .value("scenario", "NAME",
               "upload (the full exchange with a flight plan upload) or telemetry (default upload)",
               one_of<std::string>(o.scenario, {{"upload", "upload"}, {"telemetry", "telemetry"}},
                                   "upload or telemetry"))
        .value("seconds", "N", "simulated seconds measured, after 5 s to set the session up (default 60)",
               cli::number(o.seconds, 0, 1e6))
        .value("read", "BYTES", "bytes per read from the simulated serial port (default 16)",
               cli::number(o.read_bytes, 1, 1 << 20))
        .flag("unkeyed", "run the transport without a key (default keyed)", [&o] { o.keyed = false; })
        .value("measure", "WHICH",
               "the calls callgrind collects: none, a (airsegd's end), b (airsegctl's end), both or "
               "poll_transmit (default none)",
               one_of(o.measure,
                      {{"none", Selection::None},
                       {"a", Selection::EndA},
                       {"b", Selection::EndB},
                       {"both", Selection::Both},
                       {"poll_transmit", Selection::PollTransmit}},
                      "none, a, b, both or poll_transmit"))
        .help_and_version(false);
    const cli::Program program{"bench_transport", [&table] {
                                   return "Usage: bench_transport [OPTION]...\n\n"
                                          "The ground-link transport's calls on a simulated 57600-baud radio "
                                          "pair,\nfor callgrind (bench/transport/callgrind.sh).\n\n" +
                                          cli::describe(table);
                               }};
    return cli::run(program, std::vector<std::string>(argv + 1, argv + argc), table, std::cout, std::cerr)
        .exit_code;
}

gl::TransportConfig config(std::uint64_t nonce, bool keyed) {
    gl::TransportConfig c;  // airsegd's defaults at 57600 baud: one path, half duplex
    c.link_rate_bytes_per_s = kAirRate;
    c.boot_nonce = nonce;
    if (keyed) {
        std::array<std::uint8_t, gl::kKeyBytes> k{};
        for (std::size_t i = 0; i < k.size(); ++i) {
            k[i] = static_cast<std::uint8_t>(i * 7 + 3);
        }
        c.key = k;
    }
    return c;
}

/// A message of `n` bytes carrying `id` in its first four, so the receiver can check order.
std::vector<std::uint8_t> message(std::size_t n, std::uint32_t id) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>((id * 131 + i * 7) & 0xFFU);
    }
    for (std::size_t i = 0; i < 4 && i < n; ++i) {
        v[i] = static_cast<std::uint8_t>(id >> (8 * i));
    }
    return v;
}

std::uint32_t id_of(const std::vector<std::uint8_t>& v) {
    std::uint32_t id = 0;
    for (std::size_t i = 0; i < 4 && i < v.size(); ++i) {
        id |= static_cast<std::uint32_t>(v[i]) << (8 * i);
    }
    return id;
}

struct Periodic {
    Duration every;
    TimePoint next;
};

class Scenario {
  public:
    Scenario(const Options& o, DrivenLink& link) : o_(o), link_(link) {
        link_.on_message([this](int end, const gl::Delivered& m) { on_message(end, m); });
    }

    void run() {
        const TimePoint t0 = link_.now();
        Periodic telemetry{std::chrono::milliseconds(500), t0};
        Periodic stats{std::chrono::seconds(1), t0};
        Periodic reception{std::chrono::seconds(1), t0 + std::chrono::milliseconds(300)};
        Periodic command{std::chrono::seconds(2), t0 + std::chrono::milliseconds(700)};
        Periodic event{std::chrono::seconds(5), t0 + std::chrono::milliseconds(1100)};
        Periodic upload{std::chrono::milliseconds(100), t0};
        const bool full = o_.scenario == "upload";
        const TimePoint measure_from = t0 + std::chrono::seconds(5);  // the session is up and settled
        const TimePoint end =
            measure_from + std::chrono::duration_cast<Duration>(std::chrono::duration<double>(o_.seconds));
        bool counting = false;
        while (link_.now() < end) {
            TimePoint next = std::min({telemetry.next, stats.next, reception.next, end});
            if (full) {
                next = std::min({next, command.next, event.next, upload.next});
            }
            if (!counting) {
                next = std::min(next, measure_from);
            }
            link_.run_until(next);
            const TimePoint now = link_.now();
            if (!counting && now >= measure_from) {
                if (!link_.core(kAir).link_up() || !link_.core(kGround).link_up()) {
                    throw std::runtime_error("transport bench: no session after 5 s");
                }
                counting = true;
                link_.set_counting(true);
            }
            // airsegd pushes telemetry only while the link is up (groundlink_service.cpp).
            if (due(telemetry, now) && link_.core(kAir).link_up()) {
                link_.send_fast(kAir, kTelemetry, 1, message(kTelemetryBytes, seq_++));
            }
            if (due(stats, now) && link_.core(kAir).link_up()) {
                link_.send_fast(kAir, kStatus, 2, message(kLinkStatsBytes, seq_++));
            }
            if (due(reception, now) && link_.core(kGround).link_up()) {
                link_.send_fast(kGround, kStatus, 4, message(kReceptionBytes, seq_++));
            }
            if (!full) {
                continue;
            }
            if (due(command, now)) {
                send_safe(kGround, kControl, kCommandBytes);
            }
            if (due(event, now)) {
                send_safe(kAir, kStatus, kEventBytes);
            }
            // The ground streams a flight plan in messages of a few hundred bytes, a few ahead of the link.
            if (due(upload, now)) {
                while (link_.core(kGround).safe_pending(kBulk) < 4) {
                    send_safe(kGround, kBulk, 256 + (upload_sent_++ * 37) % 160);
                }
            }
        }
    }

    [[nodiscard]] std::uint64_t safe_sent() const { return safe_sent_; }
    [[nodiscard]] std::uint64_t safe_delivered() const { return safe_delivered_; }
    [[nodiscard]] std::uint64_t order_errors() const { return order_errors_; }

  private:
    static bool due(Periodic& p, TimePoint now) {
        if (now < p.next) {
            return false;
        }
        p.next += p.every;
        return true;
    }

    void send_safe(int end, std::uint8_t priority, std::size_t bytes) {
        const std::uint32_t id = next_id_[static_cast<std::size_t>(end)][priority]++;
        if (link_.send_safe(end, priority, message(bytes, id)) != gl::SendResult::Accepted) {
            throw std::runtime_error("transport bench: a Safe message was refused");
        }
        ++safe_sent_;
    }

    void on_message(int end, const gl::Delivered& m) {
        if (m.cls != gl::MessageClass::Safe) {
            return;
        }
        ++safe_delivered_;
        auto& expected = expected_id_[static_cast<std::size_t>(end)][m.priority];
        order_errors_ += id_of(m.bytes) == expected ? 0 : 1;
        expected = id_of(m.bytes) + 1;
        if (end == kAir && m.priority == kControl) {
            send_safe(kAir, kControl, kResultBytes);  // every command gets its result
        }
    }

    const Options& o_;
    DrivenLink& link_;
    std::uint32_t seq_ = 0;
    std::uint32_t upload_sent_ = 0;
    std::array<std::array<std::uint32_t, gl::kMaxPriorities>, 2> next_id_{};
    std::array<std::array<std::uint32_t, gl::kMaxPriorities>, 2> expected_id_{};
    std::uint64_t safe_sent_ = 0;
    std::uint64_t safe_delivered_ = 0;
    std::uint64_t order_errors_ = 0;
};

void print_end(const char* name, const EndTally& t) {
    std::printf("%s.delivered_bytes=%llu\n", name, static_cast<unsigned long long>(t.delivered_bytes));
    std::printf("%s.delivered_messages=%llu\n", name, static_cast<unsigned long long>(t.delivered_messages));
    std::printf("%s.wire_bytes=%llu\n", name, static_cast<unsigned long long>(t.wire_bytes));
    std::printf("%s.wire_digest=%016llx\n", name, static_cast<unsigned long long>(t.wire_digest));
    std::printf("%s.frames=%llu\n", name, static_cast<unsigned long long>(t.calls.frames));
    std::printf("%s.poll_transmit_calls=%llu\n", name,
                static_cast<unsigned long long>(t.calls.poll_transmit));
    std::printf("%s.handle_bytes_calls=%llu\n", name, static_cast<unsigned long long>(t.calls.handle_bytes));
    std::printf("%s.handle_timeout_calls=%llu\n", name,
                static_cast<unsigned long long>(t.calls.handle_timeout));
    std::printf("%s.send_calls=%llu\n", name, static_cast<unsigned long long>(t.calls.sends));
    std::printf("%s.pumps=%llu\n", name, static_cast<unsigned long long>(t.calls.pumps));
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    if (const auto exit_code = parse(argc, argv, o)) {
        return *exit_code;
    }
    try {
        DrivenLink link(config(0xA11CE, o.keyed), config(0xB0B, o.keyed), kAirRate, o.read_bytes, o.measure);
        Scenario s(o, link);
        s.run();
        std::printf("scenario=%s\nseconds=%g\nread_bytes=%zu\nkeyed=%d\n", o.scenario.c_str(), o.seconds,
                    o.read_bytes, o.keyed ? 1 : 0);
        print_end("a", link.tally(kAir));
        print_end("b", link.tally(kGround));
        std::printf("safe_sent=%llu\nsafe_delivered=%llu\norder_errors=%llu\n",
                    static_cast<unsigned long long>(s.safe_sent()),
                    static_cast<unsigned long long>(s.safe_delivered()),
                    static_cast<unsigned long long>(s.order_errors()));
        std::printf("retransmissions=%llu\n",
                    static_cast<unsigned long long>(link.core(kAir).stats().tx_safe.retransmissions +
                                                    link.core(kGround).stats().tx_safe.retransmissions));
        return s.order_errors() == 0 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
}

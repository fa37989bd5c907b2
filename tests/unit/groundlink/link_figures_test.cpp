// Link behaviour figures in simulated time at 57600 baud (5760 B/s, half-duplex air per pair), asserted with
// a margin below the design targets so that a regression shows up here before it reaches the link benchmark.
#include <gtest/gtest.h>

#include <map>

#include "tests/unit/groundlink/sim_link.hpp"

namespace airseg::groundlink {
namespace {

using namespace std::chrono_literals;

struct Figures {
    double goodput = 0.0;  // Safe bulk bytes delivered / (5760 B/s x run time)
    double max_stall_s = 0.0;
    double fast_p99_ms = 0.0;
    std::size_t fast_received = 0;
    Duration max_backlog{};
};

enum class FastFrom { None, Sender, Receiver };

Figures measure(std::size_t paths, test::Impairments imp, FastFrom fast_from, Duration run,
                std::uint64_t seed) {
    TransportConfig a = test::base_config(1);
    TransportConfig b = test::base_config(2);
    if (paths == 2) {
        a.paths = b.paths = 2;
        a.path_mode = b.path_mode = PathMode::Split;
        b.split_tx_path = 1;
    }
    std::vector<test::PathModel> models(paths);
    for (auto& m : models) {
        m.imp = imp;
    }
    test::SimLink link(a, b, models, seed);
    link.run_for(2s);
    const TimePoint start = link.now();
    const TimePoint end = start + run;
    std::uint32_t next = 0;
    std::map<std::uint32_t, TimePoint> fast_sent;
    std::vector<double> latency;
    std::size_t seen_b = 0;
    std::size_t seen_a = 0;
    std::uint64_t bytes = 0;
    TimePoint last_delivery = start;
    TimePoint next_fast = start;
    Figures f;
    auto collect_fast = [&](const Delivered& d) {
        const auto it = fast_sent.find(test::id_of(d.bytes));
        if (it != fast_sent.end()) {
            latency.push_back(std::chrono::duration<double, std::milli>(link.now() - it->second).count());
        }
    };
    while (link.now() < end) {
        while (link.a().core->send_safe(3, test::pattern(1000, next), link.now()) == SendResult::Accepted) {
            ++next;
        }
        link.run_until(link.now() + 100ms, [&] {
            if (fast_from != FastFrom::None && link.now() >= next_fast) {
                auto& from = fast_from == FastFrom::Sender ? link.a() : link.b();
                for (std::uint16_t topic = 0; topic < 3; ++topic) {
                    const auto id = static_cast<std::uint32_t>(0x40000000U + fast_sent.size());
                    fast_sent[id] = link.now();
                    from.core->send_fast(1, topic, test::pattern(60, id), link.now());
                }
                next_fast += 100ms;
            }
            for (; seen_b < link.b().received.size(); ++seen_b) {
                const auto& d = link.b().received[seen_b];
                if (d.cls == MessageClass::Safe) {
                    bytes += d.bytes.size();
                    f.max_stall_s = std::max(
                        f.max_stall_s, std::chrono::duration<double>(link.now() - last_delivery).count());
                    last_delivery = link.now();
                } else {
                    collect_fast(d);
                }
            }
            for (; seen_a < link.a().received.size(); ++seen_a) {
                collect_fast(link.a().received[seen_a]);
            }
            for (std::size_t p = 0; p < paths; ++p) {
                f.max_backlog = std::max(f.max_backlog, link.air_backlog(p));
            }
            return false;
        });
        EXPECT_FALSE(link.livelocked());
    }
    std::sort(latency.begin(), latency.end());
    f.fast_received = latency.size();
    if (!latency.empty()) {
        f.fast_p99_ms = latency[std::min(latency.size() - 1, latency.size() * 99 / 100)];
    }
    f.goodput = static_cast<double>(bytes) / (5760.0 * std::chrono::duration<double>(run).count());
    return f;
}

TEST(GroundlinkLinkFigures, CleanLinkBulkGoodput) {
    const auto f = measure(1, {}, FastFrom::None, 60s, 1);
    EXPECT_GT(f.goodput, 0.94);       // target 0.95
    EXPECT_LT(f.max_backlog, 400ms);  // pacing keeps the radio queue to about a frame
}

TEST(GroundlinkLinkFigures, BulkGoodputUnderByteCorruption) {
    test::Impairments light;
    light.byte_corrupt = 1e-4;
    EXPECT_GT(measure(1, light, FastFrom::None, 90s, 2).goodput, 0.82);  // target 0.85
    test::Impairments heavy;
    heavy.byte_corrupt = 1e-3;
    EXPECT_GT(measure(1, heavy, FastFrom::None, 90s, 3).goodput, 0.63);  // target 0.65
}

TEST(GroundlinkLinkFigures, ThirtyPercentFrameLossNeverStallsFiveSeconds) {
    test::Impairments lossy;
    lossy.loss = 0.3;
    for (std::uint64_t seed : {4U, 5U}) {
        const auto f = measure(1, lossy, FastFrom::None, 90s, seed);
        EXPECT_GT(f.goodput, 0.4);
        EXPECT_LT(f.max_stall_s, 5.0) << "seed " << seed;
    }
}

TEST(GroundlinkLinkFigures, FastLatencyWhileBulkSaturates) {
    const auto same = measure(1, {}, FastFrom::Sender, 60s, 6);
    EXPECT_GT(same.fast_received, 1700U);
    EXPECT_LT(same.fast_p99_ms, 150.0);
    EXPECT_GT(same.goodput, 0.4);
    const auto reverse = measure(1, {}, FastFrom::Receiver, 60s, 7);
    EXPECT_GT(reverse.fast_received, 1700U);
    EXPECT_LT(reverse.fast_p99_ms, 150.0);
    EXPECT_GT(reverse.goodput, 0.25);
    EXPECT_LT(reverse.max_backlog, 600ms);  // the bulk end yields the air
}

TEST(GroundlinkLinkFigures, SplitCarriesNearlyTwiceSingle) {
    const auto single = measure(1, {}, FastFrom::None, 60s, 8);
    const auto split = measure(2, {}, FastFrom::None, 60s, 8);
    EXPECT_GT(split.goodput, 1.85 * single.goodput);  // target 1.9
}

TEST(GroundlinkLinkFigures, BothEndsSaturatingShareTheAirWithoutAQueue) {
    test::SimLink link(test::base_config(1), test::base_config(2), {test::PathModel{}}, 9);
    std::array<std::uint32_t, 2> next{};
    std::array<std::uint64_t, 2> bytes{};
    Duration max_backlog{};
    for (int s = 0; s < 60; ++s) {
        for (int e = 0; e < 2; ++e) {
            while (link.end(e).core->send_safe(3, test::pattern(1000, next[static_cast<std::size_t>(e)]),
                                               link.now()) == SendResult::Accepted) {
                ++next[static_cast<std::size_t>(e)];
            }
        }
        link.run_until(link.now() + 1s, [&] {
            if (s >= 5) {  // both start from idle at once and overshoot for a moment; then it drains
                max_backlog = std::max(max_backlog, link.air_backlog(0));
            }
            return false;
        });
    }
    for (int e = 0; e < 2; ++e) {
        for (const auto& d : link.end(1 - e).received) {
            bytes[static_cast<std::size_t>(e)] += d.bytes.size();
        }
    }
    const double total = static_cast<double>(bytes[0] + bytes[1]) / (5760.0 * 60.0);
    EXPECT_GT(total, 0.8);
    EXPECT_GT(static_cast<double>(std::min(bytes[0], bytes[1])),
              0.3 * static_cast<double>(bytes[0] + bytes[1]));
    EXPECT_LT(max_backlog, 1s);  // a few frames: each end may write one before it hears the other's
    const auto& s = link.a().core->stats();
    EXPECT_LT(static_cast<double>(s.tx_safe.retransmissions), 0.1 * static_cast<double>(s.tx_safe.segments));
}

}  // namespace
}  // namespace airseg::groundlink

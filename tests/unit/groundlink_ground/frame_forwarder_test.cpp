#include "services/groundlink/frame_forwarder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace airseg::groundlink {
namespace {

using Delivery = autopilot::ForwardedFrame::Delivery;
using std::chrono::milliseconds;
using std::chrono::seconds;

autopilot::ForwardedFrame frame(std::uint32_t id, Delivery delivery, std::size_t size, std::uint8_t tag) {
    return {id, delivery, std::vector<std::uint8_t>(size, tag)};
}

/// A source offering frames of several ids at fixed periods; the forwarder is polled only at its own
/// poll_timeout() and after each offer, as the service's timer does.
struct Rig {
    struct Source {
        std::uint32_t id;
        Delivery delivery;
        std::size_t size;
        Duration period;
        TimePoint next;
        std::uint8_t tag = 0;
    };
    explicit Rig(FrameForwarderConfig config, double link_rate = 5760)
        : fwd(std::move(config), link_rate, now) {}

    void add(std::uint32_t id, Delivery delivery, std::size_t size, double hz) {
        sources.push_back({id, delivery, size,
                           std::chrono::duration_cast<Duration>(std::chrono::duration<double>(1.0 / hz)),
                           now});
    }
    void run(Duration span) {
        const TimePoint end = now + span;
        while (true) {
            TimePoint next = fwd.poll_timeout();
            for (const auto& s : sources) {
                next = std::min(next, s.next);
            }
            if (next >= end) {
                break;
            }
            now = std::max(now, next);
            for (auto& s : sources) {
                if (s.next <= now) {
                    fwd.offer(frame(s.id, s.delivery, s.size, ++s.tag), now);
                    s.next += s.period;
                }
            }
            while (auto out = fwd.poll(now)) {
                sent.push_back({now, std::move(*out)});
            }
        }
        now = end;
    }
    std::size_t count(std::uint32_t id) const {
        return static_cast<std::size_t>(
            std::count_if(sent.begin(), sent.end(), [id](const auto& s) { return s.second.id == id; }));
    }
    std::size_t bytes_between(TimePoint from, TimePoint to, double overhead) const {
        double total = 0;
        for (const auto& [at, out] : sent) {
            if (at >= from && at < to) {
                total += static_cast<double>(out.bytes.size()) + overhead;
            }
        }
        return static_cast<std::size_t>(total);
    }

    TimePoint now = TimePoint{} + std::chrono::hours(1);
    FrameForwarder fwd;
    std::vector<Source> sources;
    std::vector<std::pair<TimePoint, FrameForwarder::Out>> sent;
};

TEST(FrameForwarder, RateLimitsEachIdAndSendsTheNewestFrame) {
    FrameForwarderConfig c;
    c.enabled = true;
    c.rate_hz = {{30, 2.0}};
    c.default_hz = 1.0;
    Rig rig(c);
    rig.add(30, Delivery::Freshest, 28, 10.0);  // ATTITUDE at 10 Hz, forwarded at 2
    rig.add(0, Delivery::Freshest, 17, 1.0);    // HEARTBEAT at 1 Hz, the default rate
    rig.run(seconds(10));
    EXPECT_NEAR(static_cast<double>(rig.count(30)), 20.0, 1.0);
    EXPECT_NEAR(static_cast<double>(rig.count(0)), 10.0, 1.0);
    // Every frame sent of id 30 is the newest offered by then (tags count up with each offer).
    std::uint8_t last = 0;
    for (const auto& [at, out] : rig.sent) {
        if (out.id == 30) {
            EXPECT_GT(out.bytes.front(), last);
            last = out.bytes.front();
        }
    }
    EXPECT_GT(rig.fwd.stats().replaced, 70u);
    EXPECT_EQ(rig.fwd.stats().dropped, 0u);
    // Two frames of an id are never closer than its interval allows (with one tick of slack for rounding).
    TimePoint prev{};
    for (const auto& [at, out] : rig.sent) {
        if (out.id == 30) {
            if (prev != TimePoint{}) {
                EXPECT_GE(at - prev, milliseconds(499));
            }
            prev = at;
        }
    }
}

// Each freshest id's own counts say whether its rate at the ground fell short in the forwarder (held back: a
// long gap) or after it: with the budget free, an id's longest gap is its interval; with a budget too small
// for what waits (a parameter download taking its turns), it is longer. Replaced frames are counted per id.
TEST(FrameForwarder, EachFreshestIdCountsItsOwnFramesAndItsLongestGap) {
    auto run = [](double budget, bool download) {
        FrameForwarderConfig c;
        c.enabled = true;
        c.rate_hz = {{33, 1.0}};
        c.budget_bytes_per_s = budget;
        Rig rig(c);
        rig.add(33, Delivery::Freshest, 36, 5.0);  // GLOBAL_POSITION_INT at 5 Hz, forwarded at 1
        rig.add(0, Delivery::Freshest, 17, 1.0);   // HEARTBEAT at 1 Hz
        if (download) {
            rig.add(22, Delivery::Reliable, 37, 20.0);  // PARAM_VALUE, 740 bytes/s offered
        }
        rig.run(seconds(20));
        return std::pair{rig.fwd.stats(), rig.count(33)};
    };
    const auto [free, sent_free] = run(1728, false);
    const auto& position = free.freshest_by_id.at(33);
    EXPECT_EQ(position.offered, 100u);
    EXPECT_EQ(position.forwarded, sent_free);
    EXPECT_NEAR(static_cast<double>(position.forwarded), 20.0, 1.0);
    EXPECT_EQ(position.offered, position.forwarded + position.replaced + position.stale + 1)  // one waiting
        << "forwarded " << position.forwarded << ", replaced " << position.replaced;
    EXPECT_LE(position.longest_gap, milliseconds(1001));
    EXPECT_EQ(free.freshest_by_id.at(0).replaced, 0u);
    EXPECT_EQ(free.freshest_by_id.count(22), 0u) << "reliable frames are not freshest ones";
    std::uint64_t replaced = 0;
    for (const auto& [id, c] : free.freshest_by_id) {
        replaced += c.replaced;
    }
    EXPECT_EQ(replaced, free.replaced);

    const auto [starved, sent_starved] = run(40, true);
    EXPECT_LT(sent_starved, sent_free);
    EXPECT_GT(starved.freshest_by_id.at(33).longest_gap, milliseconds(1500));
}

TEST(FrameForwarder, ReliableFramesAllArriveInOrderBetweenTelemetry) {
    FrameForwarderConfig c;
    c.enabled = true;
    c.default_hz = 5.0;
    Rig rig(c);
    rig.add(30, Delivery::Freshest, 28, 10.0);
    rig.add(22, Delivery::Reliable, 25, 20.0);  // a parameter download
    rig.run(seconds(5));
    EXPECT_EQ(rig.count(22), 100u);
    EXPECT_NEAR(static_cast<double>(rig.count(30)), 25.0, 1.0);
    std::uint8_t last = 0;
    for (const auto& [at, out] : rig.sent) {
        if (out.id == 22) {
            EXPECT_EQ(out.bytes.front(), static_cast<std::uint8_t>(last + 1));
            last = out.bytes.front();
        }
    }
}

TEST(FrameForwarder, KeepsWithinTheByteBudget) {
    FrameForwarderConfig c;
    c.enabled = true;
    c.budget_bytes_per_s = 500;
    c.default_hz = 50.0;
    Rig rig(c);
    // Offered: about 4 kB/s, eight times the budget.
    for (std::uint32_t id = 100; id < 110; ++id) {
        rig.add(id, Delivery::Freshest, 40, 10.0);
    }
    rig.add(22, Delivery::Reliable, 25, 5.0);
    rig.run(seconds(20));
    const double budget = 500;
    // Over any whole second after the start, at most the budget (plus the burst saved up and one frame).
    for (int s = 1; s < 20; ++s) {
        const TimePoint from = rig.sent.front().first + seconds(s);
        EXPECT_LE(rig.bytes_between(from, from + seconds(1), c.overhead_bytes), budget * (1 + c.burst_s) + 48)
            << "second " << s;
    }
    // And it uses the budget: over the whole run close to it.
    const auto total = rig.bytes_between(rig.sent.front().first, rig.now, c.overhead_bytes);
    EXPECT_GT(static_cast<double>(total), budget * 19);
    EXPECT_LE(static_cast<double>(total), budget * 20 + budget * c.burst_s + 48);
    // The reliable frames kept their turn.
    EXPECT_GE(rig.count(22), 95u);
    // What is left of the budget is shared evenly among the telemetry ids: none starves.
    std::size_t fewest = rig.sent.size(), most = 0;
    for (std::uint32_t id = 100; id < 110; ++id) {
        fewest = std::min(fewest, rig.count(id));
        most = std::max(most, rig.count(id));
    }
    EXPECT_GE(fewest, 12u);
    EXPECT_LE(most - fewest, 2u);
}

TEST(FrameForwarder, DefaultBudgetIsAShareOfTheLinkRate) {
    FrameForwarder fwd(FrameForwarderConfig{}, 5760, TimePoint{});
    EXPECT_DOUBLE_EQ(fwd.budget_bytes_per_s(), 5760 * FrameForwarderConfig::kDefaultBudgetShare);
}

TEST(FrameForwarder, RateZeroFiltersAndAFullReliableQueueDrops) {
    FrameForwarderConfig c;
    c.rate_hz = {{36, 0.0}};
    c.reliable_queue_bytes = 100;
    c.budget_bytes_per_s = 1;  // nothing goes out during the test
    c.burst_s = 0;
    TimePoint now{};
    FrameForwarder fwd(c, 5760, now);
    fwd.offer(frame(36, Delivery::Freshest, 20, 1), now);
    EXPECT_EQ(fwd.stats().filtered, 1u);
    for (int i = 0; i < 5; ++i) {
        fwd.offer(frame(22, Delivery::Reliable, 30, 1), now);
    }
    EXPECT_EQ(fwd.stats().dropped, 2u);  // 3 x 30 bytes fit in 100
    fwd.offer(frame(30, Delivery::Freshest, 20, 1), now);
    fwd.clear();
    EXPECT_EQ(fwd.stats().dropped, 2u + 3u + 1u);
    EXPECT_EQ(fwd.poll_timeout(), kNever);
    EXPECT_FALSE(fwd.poll(now + seconds(10)));
}

// An outage in the middle of a parameter download: the values not yet sent stay queued and all go once the
// link is back; the telemetry that waited is dropped as stale.
TEST(FrameForwarder, AParameterDownloadSurvivesAnOutageWhole) {
    FrameForwarderConfig c;
    c.budget_bytes_per_s = 1728;  // 30 % of 57600 baud
    TimePoint now = TimePoint{} + seconds(100);
    FrameForwarder fwd(c, 5760, now);
    constexpr int kParams = 280;
    for (int i = 0; i < kParams; ++i) {
        fwd.offer(frame(22, Delivery::Reliable, 37, static_cast<std::uint8_t>(i)), now);
    }
    fwd.offer(frame(30, Delivery::Freshest, 40, 1), now);
    std::vector<std::uint8_t> tags;
    // One second of link, then 8 s down (nothing polled), then up again.
    for (TimePoint end = now + seconds(1); now < end; now += milliseconds(10)) {
        while (auto out = fwd.poll(now)) {
            if (out->id == 22) {
                tags.push_back(out->bytes.front());
            }
        }
    }
    const auto before_outage = tags.size();
    EXPECT_GT(before_outage, 10u);
    EXPECT_LT(before_outage, static_cast<std::size_t>(kParams));
    fwd.offer(frame(30, Delivery::Freshest, 40, 2), now);
    fwd.link_down();
    EXPECT_EQ(fwd.stats().stale, 1u);
    EXPECT_EQ(fwd.stats().reliable_queued, kParams - before_outage);
    now += seconds(8);
    for (TimePoint end = now + seconds(20); now < end; now += milliseconds(10)) {
        while (auto out = fwd.poll(now)) {
            EXPECT_EQ(out->id, 22u) << "telemetry from before the outage went out after it";
            tags.push_back(out->bytes.front());
        }
    }
    ASSERT_EQ(tags.size(), static_cast<std::size_t>(kParams));
    for (int i = 0; i < kParams; ++i) {
        EXPECT_EQ(tags[static_cast<std::size_t>(i)], static_cast<std::uint8_t>(i)) << "out of order at " << i;
    }
    EXPECT_EQ(fwd.stats().dropped, 0u);
    EXPECT_EQ(fwd.stats().reliable_queued, 0u);
}

// A full parameter download fits the default bound with room; beyond the bound frames are counted.
TEST(FrameForwarder, TheDefaultBoundHoldsAFullParameterDownloadAndCountsWhatIsBeyond) {
    FrameForwarderConfig c;
    TimePoint now{};
    FrameForwarder fwd(c, 5760, now);
    const std::size_t fit = c.reliable_queue_bytes / 37;
    EXPECT_GE(fit, 2u * 280u);
    for (std::size_t i = 0; i < fit + 5; ++i) {
        fwd.offer(frame(22, Delivery::Reliable, 37, 1), now);
    }
    EXPECT_EQ(fwd.stats().dropped, 5u);
    EXPECT_EQ(fwd.stats().reliable_queued, fit);
}

// A reliable frame the transport refused goes first again, and costs the budget nothing.
TEST(FrameForwarder, AFramePutBackGoesFirst) {
    FrameForwarderConfig c;
    TimePoint now{};
    FrameForwarder fwd(c, 5760, now);
    fwd.offer(frame(22, Delivery::Reliable, 30, 1), now);
    fwd.offer(frame(22, Delivery::Reliable, 30, 2), now);
    auto first = fwd.poll(now);
    ASSERT_TRUE(first);
    fwd.put_back(std::move(*first));
    EXPECT_EQ(fwd.stats().forwarded, 0u);
    auto again = fwd.poll(now);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->bytes.front(), 1);
}

TEST(FrameForwarderConfig, RefusesBadRates) {
    FrameForwarderConfig c;
    EXPECT_TRUE(c.validate().empty());
    c.rate_hz = {{30, 100.0}};
    c.budget_bytes_per_s = -1;
    EXPECT_EQ(c.validate().size(), 2u);
}

}  // namespace
}  // namespace airseg::groundlink

#include "services/groundlink/telemetry_scheduler.hpp"

#include <gtest/gtest.h>

#include <map>

namespace airseg::groundlink {
namespace {

constexpr double k57600 = 5760.0;

/// Drives the scheduler in simulated time: jumps to each deadline, counts what fell due, and feeds the link
/// quality once a second as the service does.
struct Sim {
    explicit Sim(TelemetrySchedulerConfig c = {}, double link_rate = k57600)
        : now(TimePoint{} + std::chrono::hours(1)), scheduler(c, link_rate, now), rate(link_rate) {}

    std::map<TelemetryKind, int> run(Duration d, LinkQuality q) {
        std::map<TelemetryKind, int> counts;
        const TimePoint end = now + d;
        TimePoint next_tick = now + std::chrono::seconds(1);
        for (int guard = 0; guard < 1'000'000; ++guard) {
            while (auto k = scheduler.poll_due(now)) {
                ++counts[*k];
            }
            const TimePoint next = std::min({scheduler.poll_timeout(), next_tick, end});
            EXPECT_GT(next, now) << "the scheduler must not ask to be woken in the past";
            if (next >= end) {
                now = end;
                break;
            }
            now = next;
            if (now == next_tick) {
                q.link_rate_bytes_per_s = rate;
                scheduler.update_link(q, now);
                next_tick += std::chrono::seconds(1);
            }
        }
        return counts;
    }

    TimePoint now;
    TelemetryScheduler scheduler;
    double rate;
};

const LinkQuality kGood{true, 0.0, 0.0, k57600};
const LinkQuality kWeak{true, 0.3, 0.0, k57600};

TEST(TelemetryScheduler, SendsEachKindAtItsRequestedRateOnAGoodLink) {
    Sim sim;
    auto counts = sim.run(std::chrono::seconds(10), kGood);
    EXPECT_NEAR(counts[TelemetryKind::Vehicle], 20, 1);
    EXPECT_NEAR(counts[TelemetryKind::LinkStats], 10, 1);
    EXPECT_DOUBLE_EQ(sim.scheduler.effective_hz(TelemetryKind::Vehicle), 2.0);
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), 1.0);
}

TEST(TelemetryScheduler, PollsLateByUpToTheSlackKeepEveryRate) {
    // The service polls at the first wake-up after a deadline, up to poll_slack() late (wake_sharing.hpp).
    Sim sim;
    const Duration slack = sim.scheduler.poll_slack();
    EXPECT_EQ(slack, std::chrono::milliseconds(250));  // half the vehicle sample's 500 ms
    std::map<TelemetryKind, int> counts;
    const TimePoint end = sim.now + std::chrono::seconds(20);
    for (int i = 0; sim.now < end; ++i) {
        // Late by a different share of the slack each time, never beyond it.
        sim.now = sim.scheduler.poll_timeout() + slack * (i % 5) / 4;
        while (auto k = sim.scheduler.poll_due(sim.now)) {
            ++counts[*k];
        }
    }
    EXPECT_NEAR(counts[TelemetryKind::Vehicle], 40, 1);
    EXPECT_NEAR(counts[TelemetryKind::LinkStats], 20, 1);
    TelemetrySchedulerConfig off;
    off.rate_hz = {0.0, 0.0};
    EXPECT_EQ(TelemetryScheduler(off, k57600, sim.now).poll_slack(), Duration::zero());
}

TEST(TelemetryScheduler, KeepsPushedTelemetryWithinTheLinkBudget) {
    TelemetrySchedulerConfig c;
    c.rate_hz = {10.0, 1.0};  // 10 × 48 + 37 = 517 B/s wanted
    Sim sim(c, 960.0);        // 9600 baud: budget 25 % = 240 B/s
    EXPECT_DOUBLE_EQ(sim.scheduler.budget_bytes_per_s(), 240.0);
    auto counts = sim.run(std::chrono::seconds(20), LinkQuality{true, 0, 0, 960.0});
    const double bytes_per_s =
        (counts[TelemetryKind::Vehicle] * 48.0 + counts[TelemetryKind::LinkStats] * 37.0) / 20.0;
    EXPECT_LE(bytes_per_s, 240.0 * 1.05);
    EXPECT_GT(bytes_per_s, 240.0 * 0.9);
    EXPECT_LT(sim.scheduler.effective_hz(TelemetryKind::Vehicle), 10.0);
    EXPECT_GE(sim.scheduler.effective_hz(TelemetryKind::LinkStats), c.min_hz);
}

TEST(TelemetryScheduler, LowersUnderAWeakLinkAndRestoresAfterRecovery) {
    Sim sim;
    sim.run(std::chrono::seconds(5), kGood);
    auto weak = sim.run(std::chrono::seconds(20), kWeak);
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), 0.125);
    EXPECT_TRUE(sim.scheduler.weak());
    EXPECT_EQ(sim.scheduler.lowerings(), 3u);
    EXPECT_DOUBLE_EQ(sim.scheduler.effective_hz(TelemetryKind::Vehicle), 0.25);
    EXPECT_DOUBLE_EQ(sim.scheduler.effective_hz(TelemetryKind::LinkStats), 0.2);  // the floor
    // Over the last 10 s the factor was already at its floor: about 2.5 samples, never none.
    auto floor = sim.run(std::chrono::seconds(10), kWeak);
    EXPECT_NEAR(floor[TelemetryKind::Vehicle], 2.5, 1);
    EXPECT_LT(weak[TelemetryKind::Vehicle], 40 / 2);

    // Good again: one doubling per 10 s of good link, back to the requested rates.
    sim.run(std::chrono::seconds(9), kGood);
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), 0.125) << "must not restore before recover_after";
    sim.run(std::chrono::seconds(25), kGood);
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), 1.0);
    EXPECT_EQ(sim.scheduler.restorations(), 3u);
    auto restored = sim.run(std::chrono::seconds(10), kGood);
    EXPECT_NEAR(restored[TelemetryKind::Vehicle], 20, 1);
}

TEST(TelemetryScheduler, ReplacedTelemetryCountsAsAWeakLink) {
    Sim sim;
    sim.run(std::chrono::seconds(6), LinkQuality{true, 0.0, 0.5, k57600});
    EXPECT_LT(sim.scheduler.factor(), 1.0);
}

TEST(TelemetryScheduler, LossBetweenTheThresholdsHoldsTheFactor) {
    Sim sim;
    sim.run(std::chrono::seconds(4), kWeak);
    const double lowered = sim.scheduler.factor();
    ASSERT_LT(lowered, 1.0);
    sim.run(std::chrono::seconds(60), LinkQuality{true, 0.1, 0.0, k57600});
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), lowered);
}

TEST(TelemetryScheduler, ALinkDownChangesNothing) {
    Sim sim;
    sim.run(std::chrono::seconds(4), kWeak);
    const double lowered = sim.scheduler.factor();
    ASSERT_LT(lowered, 1.0);
    sim.run(std::chrono::seconds(60), LinkQuality{false, 0.0, 0.0, k57600});
    EXPECT_DOUBLE_EQ(sim.scheduler.factor(), lowered);
}

TEST(TelemetryScheduler, RatesFromTheGroundAreCheckedAndTakeEffect) {
    Sim sim;
    EXPECT_TRUE(sim.scheduler.set_rate(TelemetryKind::Vehicle, 25.0, sim.now).has_value());
    EXPECT_TRUE(sim.scheduler.set_rate(TelemetryKind::Vehicle, -1.0, sim.now).has_value());
    EXPECT_FALSE(sim.scheduler.set_rate(TelemetryKind::Vehicle, 5.0, sim.now).has_value());
    EXPECT_FALSE(sim.scheduler.set_rate(TelemetryKind::LinkStats, 0.0, sim.now).has_value());
    auto counts = sim.run(std::chrono::seconds(10), kGood);
    EXPECT_NEAR(counts[TelemetryKind::Vehicle], 50, 1);
    EXPECT_EQ(counts[TelemetryKind::LinkStats], 0) << "rate 0 turns a kind off";

    // A reload (SIGHUP) puts the configured rates back.
    sim.scheduler.set_config(TelemetrySchedulerConfig{}, sim.now);
    EXPECT_DOUBLE_EQ(sim.scheduler.requested_hz(TelemetryKind::Vehicle), 2.0);
    EXPECT_DOUBLE_EQ(sim.scheduler.effective_hz(TelemetryKind::LinkStats), 1.0);
}

TEST(TelemetryScheduler, ALatePollDoesNotBurst) {
    Sim sim;
    while (sim.scheduler.poll_due(sim.now)) {
    }
    sim.now += std::chrono::seconds(5);  // the strand was busy for 5 s
    int due = 0;
    while (sim.scheduler.poll_due(sim.now)) {
        ++due;
    }
    EXPECT_EQ(due, 2) << "one message per kind, not the 15 missed ones";
    EXPECT_GT(sim.scheduler.poll_timeout(), sim.now);
}

TEST(TelemetryScheduler, KindsDueTogetherShareTheWholeSecondGrid) {
    // Started off the grid: after the first messages every deadline is a multiple of its period on the
    // steady clock, so the 2 Hz and 1 Hz kinds come due at the same instant each whole second (one wake-up
    // with the daemon's other 1 s ticks, not one per kind).
    TelemetrySchedulerConfig c;
    TelemetryScheduler scheduler(c, k57600,
                                 TimePoint{} + std::chrono::hours(1) + std::chrono::milliseconds(137));
    TimePoint now = TimePoint{} + std::chrono::hours(1) + std::chrono::milliseconds(137);
    std::map<TimePoint, int> due_at;
    for (int wake = 0; wake < 40; ++wake) {
        while (scheduler.poll_due(now)) {
            ++due_at[now];
        }
        now = scheduler.poll_timeout();
    }
    int together = 0;
    for (const auto& [t, n] : due_at) {
        if (t == due_at.begin()->first) {
            continue;
        }
        EXPECT_EQ(t.time_since_epoch() % std::chrono::milliseconds(500), Duration::zero());
        const bool whole_second = t.time_since_epoch() % std::chrono::seconds(1) == Duration::zero();
        EXPECT_EQ(n, whole_second ? 2 : 1);
        together += whole_second ? 1 : 0;
    }
    EXPECT_GE(together, 19);
    // A later rate change keeps to the grid of the new period.
    ASSERT_FALSE(scheduler.set_rate(TelemetryKind::Vehicle, 4.0, now + std::chrono::milliseconds(3)));
    EXPECT_EQ(scheduler.poll_timeout().time_since_epoch() % std::chrono::milliseconds(250), Duration::zero());
}

TEST(TelemetryScheduler, ConfigValidationNamesTheKey) {
    TelemetrySchedulerConfig c;
    EXPECT_TRUE(c.validate().empty());
    c.rate_hz[0] = 30;
    c.budget_share = 0;
    c.good_loss = 0.5;
    const auto problems = c.validate();
    ASSERT_EQ(problems.size(), 3u);
    EXPECT_NE(problems[0].find("groundlink.telemetry.rates.vehicle"), std::string::npos);
    EXPECT_NE(problems[1].find("budget_share"), std::string::npos);
}

TEST(TelemetryScheduler, KindNamesRoundTrip) {
    for (auto k : kAllTelemetryKinds) {
        EXPECT_EQ(telemetry_kind_from_string(to_string(k)), k);
    }
    EXPECT_FALSE(telemetry_kind_from_string("position"));
}

}  // namespace
}  // namespace airseg::groundlink

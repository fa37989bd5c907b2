// The air measurement alone, fed the seconds of a link it cannot see: a radio whose buffer overflows at a
// pace above its air, and one whose air loses frames to noise whatever the pace. The pace must come down
// for the first and stay for the second.
#include "services/groundlink/transport/air_estimate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace airseg::groundlink {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr double kConfigured = 5760.0;
constexpr std::size_t kSegment = 256;

/// One saturated second of a sender whose data always waits for the pacing: it writes `pace` bytes/s in
/// frames of one segment each; of those, the air delivers at most `air` bytes/s and `noise` of the
/// segments are lost whatever the pace. What the air cannot carry overflows the radio's buffer and is lost.
struct Air {
    double air = kConfigured;
    double noise = 0.0;

    void second(AirEstimate& e, TimePoint& now) const {
        const double pace = e.carried();
        const auto sent = static_cast<std::size_t>(pace / kSegment);
        const double through = std::min(pace, air) / pace;  // share the air carries
        const auto delivered =
            static_cast<std::size_t>(std::floor(static_cast<double>(sent) * through * (1 - noise)));
        for (std::size_t i = 0; i < sent; ++i) {
            e.on_sent(kSegment + 16, true);
        }
        e.on_acked(delivered * kSegment, delivered);
        e.on_lost(sent - delivered);
        now += seconds(1);
        e.update(now);
    }
};

TEST(AirEstimate, StartsAtTheConfiguredRateAndStaysThereOnAnAirThatCarriesIt) {
    TimePoint now{};
    AirEstimate e(kConfigured, now);
    EXPECT_DOUBLE_EQ(e.carried(), kConfigured);
    const Air air{kConfigured * 1.5, 0.0};
    for (int i = 0; i < 60; ++i) {
        air.second(e, now);
    }
    EXPECT_DOUBLE_EQ(e.carried(), kConfigured);  // never past the configured rate
    EXPECT_EQ(e.overflows(), 0u);
    EXPECT_NEAR(e.delivered(), kConfigured, 0.05 * kConfigured);
}

TEST(AirEstimate, AnAirSlowerThanConfiguredBringsThePaceDownNearIt) {
    TimePoint now{};
    AirEstimate e(kConfigured, now);
    const Air air{0.6 * kConfigured, 0.0};
    double least = kConfigured;
    double most_after_settling = 0.0;
    for (int i = 0; i < 90; ++i) {
        air.second(e, now);
        least = std::min(least, e.carried());
        if (i >= 45) {
            most_after_settling = std::max(most_after_settling, e.carried());
        }
    }
    EXPECT_GE(e.overflows(), 1u);
    EXPECT_LT(most_after_settling, 0.75 * kConfigured);  // it stays near the air, not the configuration
    EXPECT_GE(least, kConfigured / 4);                   // and never under the floor
    EXPECT_GT(e.carried(), 0.45 * kConfigured);
}

TEST(AirEstimate, NoiseThatASlowerPaceDoesNotCureLeavesThePaceAlone) {
    TimePoint now{};
    AirEstimate e(kConfigured, now);
    const Air air{2 * kConfigured, 0.3};  // 30 % of segments lost, whatever the pace
    double total = 0.0;
    double most_lately = 0.0;
    for (int i = 0; i < 120; ++i) {
        air.second(e, now);
        total += e.carried();
        if (i >= 100) {
            most_lately = std::max(most_lately, e.carried());
        }
    }
    EXPECT_EQ(e.overflows(), 0u);
    // Trials come and go (each a few seconds 15 % slower); the pace always goes back.
    EXPECT_GT(total / 120, 0.9 * kConfigured);
    EXPECT_DOUBLE_EQ(most_lately, kConfigured);
}

TEST(AirEstimate, SecondsThatAreNotSaturatedJudgeNothing) {
    TimePoint now{};
    AirEstimate e(kConfigured, now);
    for (int i = 0; i < 30; ++i) {
        // A trickle: a few frames, nothing waiting, half of it lost.
        e.on_sent(40, false);
        e.on_sent(40, false);
        e.on_acked(24, 1);
        e.on_lost(1);
        now += seconds(1);
        EXPECT_FALSE(e.update(now));
    }
    EXPECT_DOUBLE_EQ(e.carried(), kConfigured);
    EXPECT_DOUBLE_EQ(e.delivered(), 0.0);
}

TEST(AirEstimate, TurnaroundIsHalfWhatTheQuickestSmallRoundTripLeavesUnexplained) {
    TimePoint now{};
    AirEstimate e(kConfigured, now);
    EXPECT_EQ(e.round_trips(), 0u);
    // Exchanges of 30 ms of bytes that took 50, 70 and 90 ms: the least leaves 20 ms, two changes of sender.
    e.on_round_trip(milliseconds(70), milliseconds(30), now);
    e.on_round_trip(milliseconds(50), milliseconds(30), now);
    e.on_round_trip(milliseconds(90), milliseconds(30), now);
    e.on_round_trip(milliseconds(400), std::nullopt, now);  // a long frame's: timed, not used for it
    EXPECT_EQ(e.round_trips(), 3u);
    EXPECT_EQ(e.turnaround(), milliseconds(10));
    EXPECT_EQ(e.base_rtt(), milliseconds(50));
    // Forgotten after a long quiet: the next figure stands alone.
    now += seconds(40);
    e.on_round_trip(milliseconds(130), milliseconds(30), now);
    EXPECT_EQ(e.turnaround(), milliseconds(50));
}

}  // namespace
}  // namespace airseg::groundlink

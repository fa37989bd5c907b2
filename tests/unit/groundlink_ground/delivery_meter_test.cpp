#include "services/groundlink/delivery_meter.hpp"

#include <gtest/gtest.h>

#include <random>

namespace airseg::groundlink {
namespace {

constexpr auto kLag = std::chrono::milliseconds(300);

/// Pushes at `hz` for `seconds`; each message arrives after 100 ms unless lost (seeded); the ground reports
/// its cumulative count every second.
struct Link {
    TimePoint now = TimePoint{} + std::chrono::hours(1);
    DeliveryMeter meter;
    std::mt19937 rng{5};
    std::uint32_t received = 0;
    std::vector<TimePoint> in_flight;
    std::vector<double> estimates;

    double mean_estimate() const {
        double sum = 0;
        for (double e : estimates) {
            sum += e;
        }
        return estimates.empty() ? -1 : sum / static_cast<double>(estimates.size());
    }

    void run(double hz, double loss, int seconds) {
        const auto period = std::chrono::duration_cast<Duration>(std::chrono::duration<double>(1.0 / hz));
        TimePoint next_push = now, next_report = now + std::chrono::seconds(1);
        const TimePoint end = now + std::chrono::seconds(seconds);
        std::bernoulli_distribution lost(loss);
        while (now < end) {
            now = std::min({next_push, next_report, in_flight.empty() ? kNever : in_flight.front()});
            if (!in_flight.empty() && in_flight.front() <= now) {
                in_flight.erase(in_flight.begin());
                ++received;
            }
            if (now == next_push) {
                meter.on_pushed(now);
                if (!lost(rng)) {
                    in_flight.push_back(now + std::chrono::milliseconds(100));
                }
                next_push += period;
            }
            if (now == next_report) {
                meter.on_report(received, now, kLag);
                if (meter.loss()) {
                    estimates.push_back(*meter.loss());
                }
                next_report += std::chrono::seconds(1);
            }
        }
    }
};

TEST(DeliveryMeter, NoEstimateBeforeEnoughMessages) {
    Link l;
    l.run(1.0, 0.0, 10);
    EXPECT_FALSE(l.meter.loss());
    l.run(1.0, 0.0, 20);
    ASSERT_TRUE(l.meter.loss());
    EXPECT_NEAR(*l.meter.loss(), 0.0, 0.01);
}

TEST(DeliveryMeter, MeasuresTheShareThatDoesNotArrive) {
    Link l;
    l.run(3.0, 0.2, 300);
    ASSERT_TRUE(l.meter.loss());
    // Each estimate spans about 16 messages: coarse (±0.1), but unbiased.
    EXPECT_NEAR(l.mean_estimate(), 0.2, 0.04);
    EXPECT_NEAR(*l.meter.loss(), 0.2, 0.25);
    Link clean;
    clean.run(3.0, 0.0, 60);
    EXPECT_NEAR(*clean.meter.loss(), 0.0, 1e-9) << "messages still in flight are not counted as lost";
}

TEST(DeliveryMeter, FollowsALinkThatRecovers) {
    Link l;
    l.run(3.0, 0.6, 30);
    EXPECT_GT(*l.meter.loss(), 0.3);
    l.run(3.0, 0.0, 30);
    EXPECT_NEAR(*l.meter.loss(), 0.0, 1e-9);
}

TEST(DeliveryMeter, AGroundRestartStartsAgain) {
    Link l;
    l.run(3.0, 0.0, 10);
    ASSERT_TRUE(l.meter.loss());
    l.meter.on_report(0, l.now + std::chrono::seconds(1), kLag);  // the count went backwards
    EXPECT_FALSE(l.meter.loss());
    EXPECT_EQ(l.meter.pushed(), 0u);
}

}  // namespace
}  // namespace airseg::groundlink

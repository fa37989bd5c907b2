#include "hal/blink_pattern.hpp"

#include <gtest/gtest.h>

namespace airseg::hal {
namespace {

using std::chrono::milliseconds;

// Samples a pattern every millisecond over `span` and returns the times at which the level changed.
std::vector<Duration> sampled_changes(LedPattern p, Duration span) {
    std::vector<Duration> changes;
    bool last = led_level(p, Duration::zero());
    for (Duration t = milliseconds(1); t < span; t += milliseconds(1)) {
        const bool now = led_level(p, t);
        if (now != last) {
            changes.push_back(t);
            last = now;
        }
    }
    return changes;
}

TEST(HalBlinkPatternTest, BootingBlinksFastAndEvenly) {
    EXPECT_TRUE(led_level(LedPattern::Booting, milliseconds(0)));
    EXPECT_TRUE(led_level(LedPattern::Booting, milliseconds(99)));
    EXPECT_FALSE(led_level(LedPattern::Booting, milliseconds(100)));
    EXPECT_TRUE(led_level(LedPattern::Booting, milliseconds(200)));
    EXPECT_EQ(blink_period(LedPattern::Booting), milliseconds(200));
}

TEST(HalBlinkPatternTest, ReadyBlinksSlowly) {
    EXPECT_TRUE(led_level(LedPattern::Ready, milliseconds(999)));
    EXPECT_FALSE(led_level(LedPattern::Ready, milliseconds(1000)));
    EXPECT_FALSE(led_level(LedPattern::Ready, milliseconds(1999)));
    EXPECT_TRUE(led_level(LedPattern::Ready, milliseconds(2000)));
}

TEST(HalBlinkPatternTest, LinkUpIsMostlyOnWithABlip) {
    int on = 0;
    for (int ms = 0; ms < 2000; ++ms) {
        on += led_level(LedPattern::LinkUp, milliseconds(ms)) ? 1 : 0;
    }
    EXPECT_EQ(on, 1900);
    EXPECT_FALSE(led_level(LedPattern::LinkUp, milliseconds(1950)));
}

TEST(HalBlinkPatternTest, FaultFlashesTwicePerSecond) {
    const auto changes = sampled_changes(LedPattern::Fault, milliseconds(1000));
    EXPECT_EQ(changes, (std::vector<Duration>{milliseconds(100), milliseconds(200), milliseconds(300)}));
}

TEST(HalBlinkPatternTest, OffNeverLightsOrChanges) {
    EXPECT_TRUE(sampled_changes(LedPattern::Off, milliseconds(5000)).empty());
    EXPECT_FALSE(led_level(LedPattern::Off, milliseconds(123)));
    EXPECT_EQ(next_led_change(LedPattern::Off, milliseconds(0)), Duration::max());
}

TEST(HalBlinkPatternTest, NegativeElapsedCountsAsStart) {
    EXPECT_TRUE(led_level(LedPattern::Booting, -milliseconds(50)));
    EXPECT_EQ(next_led_change(LedPattern::Booting, -milliseconds(50)), milliseconds(100));
}

// next_led_change must predict exactly the changes that sampling finds, for every pattern and from any time.
TEST(HalBlinkPatternTest, NextChangeAgreesWithSampling) {
    for (auto p : {LedPattern::Booting, LedPattern::Ready, LedPattern::LinkUp, LedPattern::Fault}) {
        const Duration span = 3 * blink_period(p);
        const auto sampled = sampled_changes(p, span);
        std::vector<Duration> predicted;
        for (Duration t = next_led_change(p, Duration::zero()); t < span; t = next_led_change(p, t)) {
            predicted.push_back(t);
        }
        EXPECT_EQ(predicted, sampled) << p;
        // From a point between changes, the prediction is the next sampled change.
        const Duration mid = sampled[1] - milliseconds(1);
        EXPECT_EQ(next_led_change(p, mid), sampled[1]) << p;
    }
}

}  // namespace
}  // namespace airseg::hal

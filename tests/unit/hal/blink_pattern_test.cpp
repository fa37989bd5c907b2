#include "hal/blink_pattern.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace airseg::hal {
namespace {

using std::chrono::milliseconds;

constexpr std::array<BlinkStep, 2> kEven = {{{true, milliseconds(100)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 2> kBlip = {{{true, milliseconds(1900)}, {false, milliseconds(100)}}};
constexpr std::array<BlinkStep, 4> kDouble = {{{true, milliseconds(100)},
                                               {false, milliseconds(100)},
                                               {true, milliseconds(100)},
                                               {false, milliseconds(700)}}};
// Two dark steps in a row: the only change in the cycle is at its end.
constexpr std::array<BlinkStep, 3> kSplitDark = {
    {{true, milliseconds(300)}, {false, milliseconds(200)}, {false, milliseconds(500)}}};
constexpr std::array<BlinkStep, 1> kDark = {{{false, milliseconds(1000)}}};
constexpr std::array<BlinkStep, 2> kLit = {{{true, milliseconds(100)}, {true, milliseconds(100)}}};

// Samples a pattern every millisecond over `span` and returns the times at which the level changed.
std::vector<Duration> sampled_changes(BlinkPattern p, Duration span) {
    std::vector<Duration> changes;
    bool last = blink_level(p, Duration::zero());
    for (Duration t = milliseconds(1); t < span; t += milliseconds(1)) {
        const bool now = blink_level(p, t);
        if (now != last) {
            changes.push_back(t);
            last = now;
        }
    }
    return changes;
}

TEST(HalBlinkPatternTest, StepsFollowEachOtherAndTheCycleRepeats) {
    EXPECT_TRUE(blink_level(kEven, milliseconds(0)));
    EXPECT_TRUE(blink_level(kEven, milliseconds(99)));
    EXPECT_FALSE(blink_level(kEven, milliseconds(100)));
    EXPECT_FALSE(blink_level(kEven, milliseconds(199)));
    EXPECT_TRUE(blink_level(kEven, milliseconds(200)));
    EXPECT_EQ(blink_period(kEven), milliseconds(200));
    EXPECT_EQ(blink_period(kDouble), milliseconds(1000));
}

TEST(HalBlinkPatternTest, UnevenStepsKeepTheirLengths) {
    int on = 0;
    for (int ms = 0; ms < 2000; ++ms) {
        on += blink_level(kBlip, milliseconds(ms)) ? 1 : 0;
    }
    EXPECT_EQ(on, 1900);
    EXPECT_FALSE(blink_level(kBlip, milliseconds(1950)));
    EXPECT_EQ(sampled_changes(kDouble, milliseconds(1000)),
              (std::vector<Duration>{milliseconds(100), milliseconds(200), milliseconds(300)}));
}

TEST(HalBlinkPatternTest, ASteadyPatternNeverChanges) {
    EXPECT_TRUE(sampled_changes(kDark, milliseconds(5000)).empty());
    EXPECT_FALSE(blink_level(kDark, milliseconds(123)));
    EXPECT_EQ(next_blink_change(kDark, milliseconds(0)), Duration::max());
    EXPECT_TRUE(blink_level(kLit, milliseconds(150)));
    EXPECT_EQ(next_blink_change(kLit, milliseconds(0)), Duration::max());
}

TEST(HalBlinkPatternTest, AnEmptyPatternIsDark) {
    EXPECT_EQ(blink_period({}), Duration::zero());
    EXPECT_FALSE(blink_level({}, milliseconds(10)));
    EXPECT_EQ(next_blink_change({}, milliseconds(10)), Duration::max());
}

TEST(HalBlinkPatternTest, NegativeElapsedCountsAsStart) {
    EXPECT_TRUE(blink_level(kEven, -milliseconds(50)));
    EXPECT_EQ(next_blink_change(kEven, -milliseconds(50)), milliseconds(100));
}

// next_blink_change must predict exactly the changes that sampling finds, for any pattern and from any time.
TEST(HalBlinkPatternTest, NextChangeAgreesWithSampling) {
    for (BlinkPattern p :
         {BlinkPattern(kEven), BlinkPattern(kBlip), BlinkPattern(kDouble), BlinkPattern(kSplitDark)}) {
        const Duration span = 3 * blink_period(p);
        const auto sampled = sampled_changes(p, span);
        std::vector<Duration> predicted;
        for (Duration t = next_blink_change(p, Duration::zero()); t < span; t = next_blink_change(p, t)) {
            predicted.push_back(t);
        }
        EXPECT_EQ(predicted, sampled) << "period " << blink_period(p).count();
        // From a point between changes, the prediction is the next sampled change.
        const Duration mid = sampled[1] - milliseconds(1);
        EXPECT_EQ(next_blink_change(p, mid), sampled[1]) << "period " << blink_period(p).count();
    }
}

}  // namespace
}  // namespace airseg::hal

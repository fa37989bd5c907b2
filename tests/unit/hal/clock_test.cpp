#include "hal/clock.hpp"

#include <gtest/gtest.h>

namespace airseg::hal {
namespace {

TEST(HalManualClockTest, StartsAwayFromZeroAndMovesOnlyWhenTold) {
    ManualClock clock;
    EXPECT_NE(clock.now(), TimePoint{});
    const TimePoint t0 = clock.now();
    EXPECT_EQ(clock.now(), t0);
    clock.advance(milliseconds(250));
    EXPECT_EQ(clock.now() - t0, milliseconds(250));
    clock.advance(seconds(2));
    EXPECT_EQ(clock.now() - t0, milliseconds(2250));
}

TEST(HalManualClockTest, NegativeAdvanceIsIgnoredButSetMayGoBack) {
    ManualClock clock(TimePoint{} + seconds(10));
    clock.advance(-seconds(5));
    EXPECT_EQ(clock.now(), TimePoint{} + seconds(10));
    clock.set(TimePoint{} + seconds(3));
    EXPECT_EQ(clock.now(), TimePoint{} + seconds(3));
}

TEST(HalManualClockTest, UsableThroughTheInterface) {
    ManualClock manual;
    const Clock& clock = manual;
    const TimePoint before = clock.now();
    manual.advance(microseconds(1));
    EXPECT_GT(clock.now(), before);
}

TEST(HalSteadyClockTest, IsMonotonic) {
    SteadyClock clock;
    const TimePoint a = clock.now();
    const TimePoint b = clock.now();
    EXPECT_LE(a, b);
}

}  // namespace
}  // namespace airseg::hal

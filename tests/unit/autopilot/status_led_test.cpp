// The status LED core in simulated time: how each pattern blinks, which pattern each situation shows, and the
// levels a person would see on the line, sampled every 10 ms.
#include "services/autopilot/status_led.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace airseg::autopilot {
namespace {

const TimePoint kStart = TimePoint{} + std::chrono::hours(2);

AutopilotStatus connecting() {
    AutopilotStatus s;
    s.link_up = true;
    return s;
}
AutopilotStatus ready() {
    AutopilotStatus s;
    s.link_up = true;
    s.ready = true;
    return s;
}
AutopilotStatus lost() {
    return AutopilotStatus{};
}

// Level changes seen when sampling [from, to) every 10 ms, and the on-time fraction.
struct Seen {
    int changes = 0;
    double on_fraction = 0;
};
Seen watch(const StatusLed& led, TimePoint from, TimePoint to) {
    Seen s;
    int on = 0;
    int samples = 0;
    bool last = led.level(from);
    for (TimePoint t = from; t < to; t += milliseconds(10)) {
        const bool l = led.level(t);
        s.changes += l != last ? 1 : 0;
        on += l ? 1 : 0;
        ++samples;
        last = l;
    }
    s.on_fraction = static_cast<double>(on) / samples;
    return s;
}

bool lit(LedPattern p, Duration elapsed) {
    return hal::blink_level(blink_steps(p), elapsed);
}

// The changes next_blink_change predicts from the start until `span`.
std::vector<Duration> predicted_changes(LedPattern p, Duration span) {
    std::vector<Duration> changes;
    for (Duration t = hal::next_blink_change(blink_steps(p), Duration::zero()); t < span;
         t = hal::next_blink_change(blink_steps(p), t)) {
        changes.push_back(t);
    }
    return changes;
}

TEST(StatusLedPattern, BootingBlinksFastAndEvenly) {
    EXPECT_TRUE(lit(LedPattern::Booting, milliseconds(0)));
    EXPECT_TRUE(lit(LedPattern::Booting, milliseconds(99)));
    EXPECT_FALSE(lit(LedPattern::Booting, milliseconds(100)));
    EXPECT_TRUE(lit(LedPattern::Booting, milliseconds(200)));
    EXPECT_EQ(hal::blink_period(blink_steps(LedPattern::Booting)), milliseconds(200));
}

TEST(StatusLedPattern, ReadyBlinksSlowly) {
    EXPECT_TRUE(lit(LedPattern::Ready, milliseconds(999)));
    EXPECT_FALSE(lit(LedPattern::Ready, milliseconds(1000)));
    EXPECT_FALSE(lit(LedPattern::Ready, milliseconds(1999)));
    EXPECT_TRUE(lit(LedPattern::Ready, milliseconds(2000)));
}

TEST(StatusLedPattern, LinkUpIsMostlyOnWithABlip) {
    int on = 0;
    for (int ms = 0; ms < 2000; ++ms) {
        on += lit(LedPattern::LinkUp, milliseconds(ms)) ? 1 : 0;
    }
    EXPECT_EQ(on, 1900);
    EXPECT_FALSE(lit(LedPattern::LinkUp, milliseconds(1950)));
}

TEST(StatusLedPattern, FaultFlashesTwicePerSecond) {
    EXPECT_EQ(predicted_changes(LedPattern::Fault, milliseconds(1000)),
              (std::vector<Duration>{milliseconds(100), milliseconds(200), milliseconds(300)}));
    for (int ms : {0, 99, 200, 299}) {
        EXPECT_TRUE(lit(LedPattern::Fault, milliseconds(ms))) << ms;
    }
    for (int ms : {100, 199, 300, 999}) {
        EXPECT_FALSE(lit(LedPattern::Fault, milliseconds(ms))) << ms;
    }
}

TEST(StatusLedPattern, OffNeverLightsOrChanges) {
    for (int ms = 0; ms < 5000; ++ms) {
        ASSERT_FALSE(lit(LedPattern::Off, milliseconds(ms))) << ms;
    }
    EXPECT_EQ(hal::next_blink_change(blink_steps(LedPattern::Off), milliseconds(0)), Duration::max());
}

// Every blinking pattern changes level exactly where next_blink_change says, millisecond by millisecond.
TEST(StatusLedPattern, LevelChangesOnlyWherePredicted) {
    for (auto p : {LedPattern::Booting, LedPattern::Ready, LedPattern::LinkUp, LedPattern::Fault}) {
        const Duration span = 3 * hal::blink_period(blink_steps(p));
        const auto predicted = predicted_changes(p, span);
        ASSERT_GE(predicted.size(), 2U) << p;
        auto next = predicted.begin();
        for (Duration t = milliseconds(1); t < span; t += milliseconds(1)) {
            const bool changed = lit(p, t) != lit(p, t - milliseconds(1));
            const bool expected = next != predicted.end() && *next == t;
            ASSERT_EQ(changed, expected) << p << " at " << t.count();
            next += expected ? 1 : 0;
        }
        EXPECT_EQ(next, predicted.end()) << p;
    }
}

TEST(StatusLed, ShowsBootingThenReadyThenGroundLinkThenFaultThenRecovers) {
    StatusLed led(kStart);
    TimePoint t = kStart;
    EXPECT_EQ(led.pattern(), LedPattern::Booting);
    EXPECT_EQ(watch(led, t, t + seconds(1)).changes, 9);  // 100 ms on / 100 ms off

    t += seconds(1);
    led.autopilot(connecting(), t);  // heartbeats, parameters still downloading
    EXPECT_EQ(led.pattern(), LedPattern::Booting);

    t += seconds(4);
    led.autopilot(ready(), t);
    EXPECT_EQ(led.pattern(), LedPattern::Ready);
    EXPECT_EQ(led.since(), t);
    const Seen slow = watch(led, t, t + seconds(4));
    EXPECT_EQ(slow.changes, 3);  // 1 s on / 1 s off
    EXPECT_NEAR(slow.on_fraction, 0.5, 0.01);

    t += seconds(4);
    led.ground_link(true, t);
    EXPECT_EQ(led.pattern(), LedPattern::LinkUp);
    const Seen linked = watch(led, t, t + seconds(4));
    EXPECT_GT(linked.on_fraction, 0.9);  // on, with a short dark blip that shows the daemon alive
    EXPECT_GE(linked.changes, 2);

    t += seconds(4);
    led.autopilot(lost(), t);  // heartbeats stopped
    EXPECT_EQ(led.pattern(), LedPattern::Fault);
    led.ground_link(false, t + milliseconds(500));
    EXPECT_EQ(led.pattern(), LedPattern::Fault) << "a fault outranks the ground link";
    EXPECT_EQ(led.since(), t) << "the fault pattern is not restarted by other news";

    t += seconds(3);
    led.autopilot(connecting(), t);  // heartbeats again, resynchronising: still the fault until READY
    EXPECT_EQ(led.pattern(), LedPattern::Fault);
    t += seconds(3);
    led.autopilot(ready(), t);
    EXPECT_EQ(led.pattern(), LedPattern::Ready);
}

TEST(StatusLed, ResetPulsesWithoutReadyAreAFaultButAnEarlyMissingAutopilotIsNot) {
    StatusLed led(kStart);
    led.autopilot(lost(), kStart + seconds(1));  // never connected yet: still booting
    EXPECT_EQ(led.pattern(), LedPattern::Booting);
    AutopilotStatus pulsed;
    pulsed.reset_pulses = 1;
    led.autopilot(pulsed, kStart + seconds(25));
    EXPECT_EQ(led.pattern(), LedPattern::Fault);
    AutopilotStatus back = ready();
    back.reset_pulses = 1;
    led.autopilot(back, kStart + seconds(40));
    EXPECT_EQ(led.pattern(), LedPattern::Ready);
    back.ready = false;  // rebooted on its own: booting again, not a fault (no new pulse)
    led.autopilot(back, kStart + seconds(60));
    EXPECT_EQ(led.pattern(), LedPattern::Booting);
}

TEST(StatusLed, NextChangeIsWhereTheLevelFlips) {
    StatusLed led(kStart);
    led.autopilot(ready(), kStart + milliseconds(300));
    TimePoint t = kStart + milliseconds(300);
    for (int i = 0; i < 6; ++i) {
        const TimePoint next = led.next_change(t);
        ASSERT_NE(next, kNever);
        EXPECT_EQ(next - t, seconds(1));
        EXPECT_NE(led.level(next), led.level(next - milliseconds(1)));
        t = next;
    }
}

}  // namespace
}  // namespace airseg::autopilot

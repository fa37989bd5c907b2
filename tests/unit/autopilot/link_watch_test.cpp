// LinkWatch in simulated time: link up/down (and the daemon's own stalls), baud probing, the reset-pulse
// budget, reboot evidence (and what is not evidence).
#include "services/autopilot/ardupilot/link_watch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace airseg::autopilot::ardupilot {
namespace {

const TimePoint kOpen = TimePoint{} + std::chrono::hours(1);

/// A heartbeat of a running autopilot, reboots watched for: true when the link came up with it.
bool beat(LinkWatch& w, TimePoint t) {
    return w.on_heartbeat(t, false, true).came_up;
}

LinkWatchConfig quiet_open() {
    LinkWatchConfig c;
    c.reset_on_open = false;
    c.heartbeat_timeout = seconds(3);
    c.unresponsive_timeout = seconds(20);
    c.max_reset_pulses = 3;
    return c;
}

TEST(LinkWatch, LinkGoesDownAfterHeartbeatTimeoutAndTheReadGrace) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.up());
    const TimePoint hb = kOpen + seconds(1);
    EXPECT_TRUE(beat(w, hb));
    EXPECT_TRUE(w.up());
    EXPECT_EQ(w.poll_timeout(), hb + seconds(3));

    auto due = w.handle_timeout(hb + seconds(3) - milliseconds(1));
    EXPECT_FALSE(due.lost);
    EXPECT_TRUE(w.up());

    EXPECT_FALSE(w.handle_timeout(hb + seconds(3)).lost);
    due = w.handle_timeout(hb + seconds(3) + LinkWatch::kReadGrace);
    ASSERT_TRUE(due.lost);
    EXPECT_EQ(*due.lost, seconds(3) + LinkWatch::kReadGrace);
    EXPECT_FALSE(w.up());
    EXPECT_EQ(w.link_losses(), 1u);
    EXPECT_FALSE(due.pulse);  // silent for 3 s of a 20 s unresponsive timer

    // The next heartbeat brings it up again, once.
    EXPECT_TRUE(beat(w, hb + seconds(5)));
    EXPECT_FALSE(beat(w, hb + seconds(6)));
}

// The verdict says what the port carried without a heartbeat: nothing (a silent board or a cut line), or the
// autopilot's frames (a board that stopped beating) and when the last bytes came (a reader that stopped).
TEST(LinkWatch, AVerdictSaysWhatThePortCarriedSinceTheLastHeartbeat) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    w.on_bytes(17, kOpen);
    w.on_frame();
    beat(w, kOpen);
    auto due = w.handle_timeout(kOpen + seconds(3));
    due = w.handle_timeout(kOpen + seconds(3) + LinkWatch::kReadGrace);
    ASSERT_TRUE(due.lost);
    EXPECT_EQ(due.lost_detail, "nothing read from the port since the last one");

    beat(w, kOpen + seconds(4));
    for (int i = 0; i < 5; ++i) {
        w.on_bytes(40, kOpen + seconds(4) + milliseconds(100 * i));
        w.on_frame();
    }
    w.on_bytes(3, kOpen + seconds(5));  // noise: no frame
    due = w.handle_timeout(kOpen + seconds(7));
    due = w.handle_timeout(kOpen + seconds(7) + LinkWatch::kReadGrace);
    ASSERT_TRUE(due.lost);
    EXPECT_EQ(due.lost_detail,
              "203 bytes read since the last one, 5 of the autopilot's frames among them, the last bytes 2.2 "
              "s ago");
    EXPECT_EQ(w.silence_text(kOpen + seconds(8)),
              "203 bytes read since the last one, 5 of the autopilot's "
              "frames among them, the last bytes 3.0 s ago");
}

TEST(LinkWatch, HeartbeatsInTimeKeepTheLinkUp) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    ASSERT_TRUE(beat(w, kOpen));
    TimePoint now = kOpen;
    TimePoint next_hb = kOpen + milliseconds(2900);
    while (now < kOpen + seconds(120)) {
        now = std::min(next_hb, w.poll_timeout());
        if (now == next_hb) {
            EXPECT_FALSE(beat(w, now));
            next_hb = now + milliseconds(2900);
        } else {
            const auto due = w.handle_timeout(now);
            EXPECT_FALSE(due.lost);
            EXPECT_FALSE(due.pulse);
        }
        ASSERT_TRUE(w.up());
    }
}

TEST(LinkWatch, ResetPulsesAreCappedUntilRefilled) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    std::vector<std::pair<TimePoint, unsigned>> pulses;
    unsigned exhausted = 0;
    TimePoint now = kOpen;
    for (int i = 0; i < 6; ++i) {
        now = w.poll_timeout();
        const auto due = w.handle_timeout(now);
        if (due.pulse) {
            pulses.emplace_back(now, *due.pulse);
        }
        exhausted += due.pulses_exhausted ? 1 : 0;
    }
    ASSERT_EQ(pulses.size(), 3u);
    for (unsigned i = 0; i < 3; ++i) {
        EXPECT_EQ(pulses[i].first, kOpen + seconds(20) * (i + 1));
        EXPECT_EQ(pulses[i].second, i + 1);
    }
    EXPECT_EQ(exhausted, 3u);
    EXPECT_EQ(w.reset_pulses(), 3u);
    EXPECT_FALSE(w.take_pulse());

    w.refill_pulses();
    EXPECT_EQ(w.take_pulse(), 1u);
    EXPECT_EQ(w.reset_pulses(), 4u);
}

TEST(LinkWatch, NoPulseWhileTheLinkIsUpOrThePortClosed) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(3));
    EXPECT_TRUE(w.on_port_closed());  // it was up
    EXPECT_FALSE(w.up());
    EXPECT_EQ(w.poll_timeout(), kNever);
    const auto due = w.handle_timeout(kOpen + seconds(100));
    EXPECT_FALSE(due.lost || due.baud || due.pulse || due.pulses_exhausted);
}

TEST(LinkWatch, ResetOnOpenWaitsForTheBootWindow) {
    LinkWatchConfig c = quiet_open();
    c.reset_on_open = true;
    c.boot_timeout = seconds(30);
    LinkWatch w(c);
    w.on_port_open(kOpen);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(50));
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(50) - milliseconds(1)).pulse);
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(50)).pulse, 1u);

    // A pulse restarts the unresponsive timer.
    w.on_reset_pulsed(kOpen + seconds(51));
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(71));
}

TEST(LinkWatch, BaudProbingGoesRoundUntilTheAutopilotAnswers) {
    LinkWatchConfig c = quiet_open();
    c.bauds = {57600, 115200, 38400};
    c.baud_probe = seconds(3);
    LinkWatch w(c);
    w.on_port_open(kOpen);
    EXPECT_EQ(w.baud(), 57600u);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(3));
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(3)).baud, 115200u);
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(6)).baud, 38400u);
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(9)).baud, 57600u);
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(11)).baud);
    w.on_frame();
    EXPECT_EQ(w.baud(), 57600u);
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(12)).baud);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(20));  // only the unresponsive timer is left
}

TEST(LinkWatch, ANewBaudGetsHalfTheUnresponsiveTimeBeforeAPulse) {
    LinkWatchConfig c = quiet_open();
    c.bauds = {57600, 115200};
    c.baud_probe = seconds(15);
    LinkWatch w(c);
    w.on_port_open(kOpen);
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(15)).baud, 115200u);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(25));  // not the 20 s from the open
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(20)).pulse);
    EXPECT_EQ(w.handle_timeout(kOpen + seconds(25)).pulse, 1u);
}

TEST(LinkWatch, OneBaudIsNeverProbed) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_EQ(w.poll_timeout(), kOpen + seconds(20));
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(19)).baud);
}

// --- the verdict on an overdue heartbeat, and the daemon's own stalls -------------------------------------

// A daemon stopped (SIGSTOP) or starved for a few seconds wakes with its timer and its port ready at once;
// the timer's handler may run first. The heartbeats sent meanwhile are in the port: the link was never lost.
TEST(LinkWatch, ADaemonThatWasNotRunningReadsThePortBeforeItJudges) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    TimePoint t = kOpen;
    for (int i = 0; i < 10; ++i, t += seconds(1)) {
        beat(w, t);
    }
    const TimePoint last = t - seconds(1);
    // Stopped from just after the last heartbeat read until 4.6 s later: four heartbeats wait in the port.
    const TimePoint woke = last + milliseconds(4600);
    EXPECT_FALSE(w.handle_timeout(woke).lost);
    for (int i = 0; i < 4; ++i) {
        EXPECT_FALSE(beat(w, woke + microseconds(50 * i))) << "the link never went down";
    }
    EXPECT_TRUE(w.up());
    EXPECT_EQ(w.link_losses(), 0u);
    EXPECT_EQ(w.poll_timeout(), woke + microseconds(150) + seconds(3));
}

TEST(LinkWatch, AStallThatBeganBeforeTheDeadlineAndEndedJustAfterIsNoLoss) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    // Stopped from 0.9 s to 3.02 s: the timer fires only 20 ms late, the heartbeats of 1 s and 2 s unread.
    EXPECT_FALSE(w.handle_timeout(kOpen + milliseconds(3020)).lost);
    EXPECT_FALSE(beat(w, kOpen + milliseconds(3021)));
    EXPECT_FALSE(beat(w, kOpen + milliseconds(3021)));
    EXPECT_FALSE(w.handle_timeout(kOpen + milliseconds(3270)).lost);
    EXPECT_TRUE(w.up());
}

TEST(LinkWatch, StoppedAgainDuringTheGraceTheVerdictWaitsForAWakeOnTime) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(4)).lost);  // late: grace
    // Stopped again before the read: the grace's wake comes 2 s late. Judged again after another grace.
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(6)).lost);
    EXPECT_FALSE(beat(w, kOpen + seconds(6) + milliseconds(1)));
    EXPECT_TRUE(w.up());
}

// A daemon that is starved for good (every wake 0.5 s late) still sees a dead autopilot's link go down: the
// grace is extended for at most heartbeat_timeout.
TEST(LinkWatch, ADeadAutopilotIsLostEvenWhenEveryWakeComesLate) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    std::optional<TimePoint> lost_at;
    for (int i = 0; i < 100 && !lost_at; ++i) {
        const TimePoint now = w.poll_timeout() + milliseconds(500);
        if (w.handle_timeout(now).lost) {
            lost_at = now;
        }
    }
    ASSERT_TRUE(lost_at);
    EXPECT_GE(*lost_at - kOpen, seconds(3) + seconds(3));
    EXPECT_LE(*lost_at - kOpen, seconds(3) + milliseconds(500) + seconds(3) + seconds(1));
    EXPECT_FALSE(w.up());
}

// A daemon short of CPU drains a backlog of seconds in reads slower than one grace: while the port still
// holds bytes, the verdict waits for them (the heartbeat may be among them), within heartbeat_timeout.
TEST(LinkWatch, TheVerdictWaitsWhileThePortStillHoldsUnreadBytes) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    const TimePoint overdue = kOpen + seconds(3);
    EXPECT_FALSE(w.handle_timeout(overdue).lost);  // the grace
    // Each look comes on time, and each finds the backlog still being read.
    for (int i = 1; i <= 3; ++i) {
        EXPECT_FALSE(w.handle_timeout(w.poll_timeout(), true).lost) << "look " << i;
    }
    EXPECT_EQ(w.verdicts_deferred(), 3u);
    EXPECT_FALSE(beat(w, w.poll_timeout() - milliseconds(10))) << "the link never went down";
    EXPECT_EQ(w.link_losses(), 0u);

    // Without bytes waiting, a grace that ends on time is judged at once: the same look, the other answer.
    LinkWatch idle(quiet_open());
    idle.on_port_open(kOpen);
    beat(idle, kOpen);
    EXPECT_FALSE(idle.handle_timeout(overdue).lost);
    EXPECT_TRUE(idle.handle_timeout(idle.poll_timeout(), false).lost);
    EXPECT_EQ(idle.verdicts_deferred(), 0u);
}

// Bytes that keep coming without a heartbeat among them (a board that streams but stopped beating, line
// noise) put the verdict off for at most heartbeat_timeout.
TEST(LinkWatch, UnreadBytesPutTheVerdictOffForAtMostTheHeartbeatTimeout) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    beat(w, kOpen);
    std::optional<TimePoint> lost_at;
    for (int i = 0; i < 100 && !lost_at; ++i) {
        const TimePoint now = w.poll_timeout();
        if (w.handle_timeout(now, true).lost) {
            lost_at = now;
        }
    }
    ASSERT_TRUE(lost_at);
    EXPECT_GE(*lost_at - kOpen, seconds(3) + seconds(3));
    EXPECT_LE(*lost_at - kOpen, seconds(3) + seconds(3) + LinkWatch::kReadGrace);
    EXPECT_FALSE(w.up());
    EXPECT_EQ(w.link_losses(), 1u);
}

// --- reboot evidence ------------------------------------------------------------------------------------

/// Feeds time_boot_ms samples every `step` from `from` for `span`: the board's clock `clock(t)` at each.
template <class Clock>
unsigned reboots_over(LinkWatch& w, TimePoint from, Duration span, Duration step, Clock clock,
                      std::vector<std::string>* evidence = nullptr) {
    unsigned n = 0;
    for (TimePoint t = from; t < from + span; t += step) {
        auto e = w.on_time_boot(clock(t), t, true);
        if (!e && w.poll_timeout() <= t) {
            e = w.handle_timeout(t).reboot;
        }
        if (e) {
            ++n;
            if (evidence) {
                evidence->push_back(*e);
            }
        }
    }
    return n;
}

TEST(LinkWatch, AClockThatWentBackAndRanOnIsAReboot) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    const auto ms_since = [](TimePoint a, TimePoint b) {
        return static_cast<std::uint32_t>(std::chrono::duration_cast<milliseconds>(b - a).count());
    };
    EXPECT_EQ(reboots_over(w, kOpen, seconds(60), milliseconds(200),
                           [&](TimePoint t) { return 100000 + ms_since(kOpen, t); }),
              0u);
    // Rebooted: the clock restarts near 0 and runs on. Declared once it ran on for kClockConfirm.
    const TimePoint boot = kOpen + seconds(60);
    std::vector<std::string> evidence;
    EXPECT_EQ(reboots_over(
                  w, boot, seconds(60), milliseconds(200),
                  [&](TimePoint t) { return 2500 + ms_since(boot, t); }, &evidence),
              1u);
    ASSERT_EQ(evidence.size(), 1u);
    EXPECT_EQ(evidence[0], "time_boot_ms went back from 159800 to 2500 ms and ran on from there");
}

TEST(LinkWatch, AClockRunningFasterThanOursAfterARebootIsStillOne) {
    // A simulated board (SITL, airseg-apmsim --speedup 10) runs its clock faster than the daemon's.
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    std::uint32_t ms = 200000;
    for (TimePoint t = kOpen; t < kOpen + seconds(5); t += milliseconds(100)) {
        EXPECT_FALSE(w.on_time_boot(ms += 1000, t, true));
    }
    unsigned n = 0;
    ms = 1000;
    for (TimePoint t = kOpen + seconds(5); t < kOpen + seconds(10); t += milliseconds(100)) {
        n += w.on_time_boot(ms += 1000, t, true) ? 1 : 0;
    }
    EXPECT_EQ(n, 1u);
}

TEST(LinkWatch, AClockFlippingBetweenTwoValuesIsNeverAReboot) {
    // GLOBAL_POSITION_INT with time_boot_ms alternating 2^32-1 and 0, 50 frames a second for 10 minutes.
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    std::uint64_t i = 0;
    EXPECT_EQ(reboots_over(w, kOpen, std::chrono::minutes(10), milliseconds(20),
                           [&](TimePoint) { return (i++ % 2) ? 0u : 0xFFFFFFFFu; }),
              0u);
    EXPECT_EQ(w.reboots_held(), 0u);
}

TEST(LinkWatch, AClockFlippingFarEveryFewSecondsIsDeclaredAtMostOncePerSpacing) {
    // 2 s on one clock, 2 s on another, for 10 minutes: each switch back looks like a restart.
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    const unsigned n = reboots_over(w, kOpen, std::chrono::minutes(10), milliseconds(100), [&](TimePoint t) {
        const auto s = std::chrono::duration_cast<seconds>(t - kOpen).count();
        return (s / 2) % 2 ? 5000u : 900000u;
    });
    EXPECT_GE(n, 1u);
    EXPECT_LE(n, 600u / 10u + 1u) << "one reboot per kRebootSpacing at most";
}

TEST(LinkWatch, AClockThatWrapsIsNoReboot) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    std::uint32_t ms = 0xFFFFFFFFu - 3000u;
    EXPECT_EQ(reboots_over(w, kOpen, seconds(20), milliseconds(100), [&](TimePoint) { return ms += 100; }),
              0u);
}

TEST(LinkWatch, OurOwnStallIsNoRestartOfTheirClock) {
    // The daemon did not run for 5 s: its clock moved on 5 s between two samples, the board's by 20 ms (the
    // sample read late was sent right after the previous one).
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.on_time_boot(100000, kOpen, true));
    EXPECT_FALSE(w.on_time_boot(100020, kOpen + seconds(5), true));
    EXPECT_FALSE(w.on_time_boot(100040, kOpen + seconds(5), true));
    EXPECT_FALSE(w.on_time_boot(105000, kOpen + seconds(6), true));
    EXPECT_EQ(w.reboots_held(), 0u);
}

TEST(LinkWatch, ClockSamplesWhileWaitingForABootOnlyMoveTheReference) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.on_time_boot(100000, kOpen, true));
    for (int i = 0; i < 30; ++i) {
        EXPECT_FALSE(w.on_time_boot(1000 + 100 * i, kOpen + milliseconds(100 * i), false));
    }
    EXPECT_FALSE(w.on_time_boot(5000, kOpen + seconds(4), true));
    w.forget_boot_clock();
    EXPECT_FALSE(w.on_time_boot(0, kOpen + seconds(90), true));
}

TEST(LinkWatch, AHeartbeatGapEndedByABootingHeartbeatIsAReboot) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    ASSERT_TRUE(w.on_heartbeat(kOpen, false, true).came_up);
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(1), false, true).reboot);
    // Booting without a gap (a calibration on a running board): not a reboot.
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(2), true, true).reboot);
    // A gap, then running: not a reboot either (a lossy link).
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(5), false, true).reboot);
    // A gap ended by a booting heartbeat.
    const auto seen = w.on_heartbeat(kOpen + seconds(8), true, true);
    ASSERT_TRUE(seen.reboot);
    EXPECT_EQ(*seen.reboot, "a heartbeat gap of 3.0 s ended by a booting heartbeat");
    // While the boot is being waited for, nothing is evidence.
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(30), true, false).reboot);
}

// A boot shorter than kBootGap (at a simulator's speedup, or heartbeats read late after it) shows in the mode
// at once, where the clock's evidence would take kClockConfirm more: meanwhile the daemon would drive the
// booted board on the mission it kept in storage.
TEST(LinkWatch, AHeartbeatInTheBootModeAfterARunningOneIsAReboot) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    w.on_heartbeat(kOpen, false, true);
    const auto seen = w.on_heartbeat(kOpen + milliseconds(900), true, true, "AUTO");
    ASSERT_TRUE(seen.reboot);
    EXPECT_EQ(
        *seen.reboot,
        "the heartbeat's mode went from AUTO to INITIALISING, which the firmware holds only while it boots");
    // Not while a boot is waited for (the port just opened on a board that resets, a reset pulse).
    LinkWatch opening(quiet_open());
    opening.on_port_open(kOpen);
    opening.on_heartbeat(kOpen, false, true);
    EXPECT_FALSE(opening.on_heartbeat(kOpen + seconds(1), true, false, "AUTO").reboot);
    // A gap and the mode together are one reboot, told by the gap.
    LinkWatch both(quiet_open());
    both.on_port_open(kOpen);
    both.on_heartbeat(kOpen, false, true);
    const auto gap = both.on_heartbeat(kOpen + seconds(3), true, true, "HOLD");
    ASSERT_TRUE(gap.reboot);
    EXPECT_EQ(*gap.reboot, "a heartbeat gap of 3.0 s ended by a booting heartbeat");
    EXPECT_EQ(both.reboots_held(), 0u);
}

TEST(LinkWatch, RebootEvidenceWithinTheSpacingIsHeldAndDeclaredAtItsEnd) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    w.on_heartbeat(kOpen, false, true);
    ASSERT_TRUE(w.on_heartbeat(kOpen + seconds(2), true, true).reboot);
    w.on_heartbeat(kOpen + seconds(3), false, true);
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(5), true, true).reboot) << "2nd within kRebootSpacing";
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(8), true, true).reboot) << "3rd: the same held declaration";
    EXPECT_EQ(w.reboots_held(), 2u);
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(11)).reboot);
    const auto due = w.handle_timeout(kOpen + seconds(2) + LinkWatch::kRebootSpacing);
    ASSERT_TRUE(due.reboot);
    EXPECT_EQ(*due.reboot, "a heartbeat gap of 2.0 s ended by a booting heartbeat");
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(13)).reboot);
    // A boot waited for (the driver declared a reboot, or pulsed the reset line) drops what was held.
    w.on_heartbeat(kOpen + seconds(14), false, true);
    EXPECT_FALSE(w.on_heartbeat(kOpen + seconds(17), true, true).reboot);
    w.forget_boot_clock();
    EXPECT_FALSE(w.handle_timeout(kOpen + seconds(40)).reboot);
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

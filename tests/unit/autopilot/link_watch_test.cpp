// LinkWatch in simulated time: link up/down, baud probing, the reset-pulse budget, reboot evidence.
#include "services/autopilot/ardupilot/link_watch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace airseg::autopilot::ardupilot {
namespace {

const TimePoint kOpen = TimePoint{} + std::chrono::hours(1);

LinkWatchConfig quiet_open() {
    LinkWatchConfig c;
    c.reset_on_open = false;
    c.heartbeat_timeout = seconds(3);
    c.unresponsive_timeout = seconds(20);
    c.max_reset_pulses = 3;
    return c;
}

TEST(LinkWatch, LinkGoesDownExactlyAfterHeartbeatTimeout) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.up());
    const TimePoint hb = kOpen + seconds(1);
    EXPECT_TRUE(w.on_heartbeat(hb));
    EXPECT_TRUE(w.up());
    EXPECT_EQ(w.poll_timeout(), hb + seconds(3));

    auto due = w.handle_timeout(hb + seconds(3) - milliseconds(1));
    EXPECT_FALSE(due.lost);
    EXPECT_TRUE(w.up());

    due = w.handle_timeout(hb + seconds(3));
    ASSERT_TRUE(due.lost);
    EXPECT_EQ(*due.lost, seconds(3));
    EXPECT_FALSE(w.up());
    EXPECT_FALSE(due.pulse);  // silent for 3 s of a 20 s unresponsive timer

    // The next heartbeat brings it up again, once.
    EXPECT_TRUE(w.on_heartbeat(hb + seconds(5)));
    EXPECT_FALSE(w.on_heartbeat(hb + seconds(6)));
}

TEST(LinkWatch, HeartbeatsInTimeKeepTheLinkUp) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    ASSERT_TRUE(w.on_heartbeat(kOpen));
    TimePoint now = kOpen;
    TimePoint next_hb = kOpen + milliseconds(2900);
    while (now < kOpen + seconds(120)) {
        now = std::min(next_hb, w.poll_timeout());
        if (now == next_hb) {
            EXPECT_FALSE(w.on_heartbeat(now));
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
    w.on_heartbeat(kOpen);
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

TEST(LinkWatch, TimeBootRunningSlowIsRebootEvidence) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.on_time_boot(100000, kOpen, true));
    EXPECT_FALSE(w.on_time_boot(110000, kOpen + seconds(10), true));  // in step
    EXPECT_FALSE(w.on_time_boot(118500, kOpen + seconds(20), true));  // within the slack
    EXPECT_EQ(w.on_time_boot(5000, kOpen + seconds(25), true), "time_boot_ms went back");
    // A clock that went on, but far less than ours during a silence.
    EXPECT_EQ(w.on_time_boot(6000, kOpen + seconds(60), true), "time_boot_ms restarted during a silence");
    // Not watching (waiting for a boot): only the reference moves.
    EXPECT_FALSE(w.on_time_boot(1000, kOpen + seconds(61), false));
    EXPECT_FALSE(w.on_time_boot(2000, kOpen + seconds(62), true));
    w.forget_boot_clock();
    EXPECT_FALSE(w.on_time_boot(0, kOpen + seconds(90), true));
}

TEST(LinkWatch, BootBannersCountOnlyRightAfterTheLinkCameBack) {
    LinkWatch w(quiet_open());
    w.on_port_open(kOpen);
    EXPECT_FALSE(w.reboot_banner("ardurover v2.42", kOpen));  // never up yet
    w.on_heartbeat(kOpen + seconds(1));
    EXPECT_TRUE(w.reboot_banner("ardurover v2.42", kOpen + seconds(5)));
    EXPECT_TRUE(w.reboot_banner("initialising apm", kOpen + seconds(5)));
    EXPECT_FALSE(w.reboot_banner("reached waypoint #3", kOpen + seconds(5)));
    EXPECT_FALSE(w.reboot_banner("ardurover v2.42", kOpen + seconds(1) + LinkWatch::kGapWindow));
}

}  // namespace
}  // namespace airseg::autopilot::ardupilot

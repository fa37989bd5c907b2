// The ground's reception report in simulated time (the groundlink SimLink: two transports over a 57600-baud
// half-duplex radio): at least once a second, and in place of the uplink's keepalive when the ground has
// nothing else to say.
#include "groundside/reception_report_timing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "services/groundlink/protocol/ground_protocol.hpp"
#include "tests/unit/groundlink/sim_link.hpp"

namespace airseg::groundside {
namespace {

namespace gl = groundlink;
namespace proto = groundlink::protocol;
using gl::test::SimLink;

constexpr int kGround = 1;

gl::TransportConfig ground_config() {
    auto c = gl::test::base_config(22);
    c.probe_with_next_poll = false;  // as GroundEnd sets it
    return c;
}

// The vehicle pushes its telemetry every 500 ms; the ground sends `uplink_every` a command of its own (none
// when zero) and reports as ReportTiming says.
struct Bench {
    explicit Bench(std::uint64_t seed)
        : link(gl::test::base_config(11), ground_config(), {gl::test::PathModel{}}, seed) {
        link.run_until(link.now() + std::chrono::seconds(10),
                       [this] { return link.a().core->link_up() && link.b().core->link_up(); });
        link.before_poll = [this](int end) {
            if (end == kGround) {
                report_if_due();
            }
        };
    }

    // What GroundEnd does at its timer and before each input.
    void report_if_due() {
        const TimePoint now = link.now();
        if (timing.due(now, *link.b().core)) {
            link.b().core->send_fast(proto::kPriorityStatus, proto::kTopicReception,
                                     proto::encode(proto::ReceptionReport{7}), now);
            timing.sent(now);
            reports.push_back(now);
        }
    }

    // Runs `d` of the vehicle's telemetry, the ground's reports and, every `uplink_every`, its commands.
    void run(Duration d, Duration uplink_every = Duration::zero()) {
        const TimePoint end = link.now() + d;
        TimePoint next_push = link.now();
        TimePoint next_uplink = uplink_every > Duration::zero() ? link.now() : kNever;
        TimePoint next_check = link.now();
        while (link.now() < end) {
            link.run_until(std::min({next_push, next_uplink, next_check, end}), [] { return false; });
            const TimePoint now = link.now();
            if (now >= next_push) {
                link.a().core->send_fast(proto::kPriorityTelemetry, proto::kTopicTelemetry,
                                         gl::test::pattern(30, 1), now);
                next_push += std::chrono::milliseconds(500);
            }
            if (now >= next_uplink) {
                link.b().core->send_fast(proto::kPriorityTelemetry, 99, gl::test::pattern(8, 2), now);
                next_uplink += uplink_every;
            }
            if (now >= next_check) {
                report_if_due();
                next_check = timing.next_check(now, *link.b().core);
                if (next_check <= now) {
                    ADD_FAILURE() << "the next check is not later than now";
                    return;
                }
            }
            link.step();  // what was queued goes out now
        }
    }

    std::size_t reports_heard() {
        return static_cast<std::size_t>(
            std::count_if(link.a().received.begin(), link.a().received.end(),
                          [](const gl::Delivered& m) { return m.topic == proto::kTopicReception; }));
    }

    SimLink link;
    ReportTiming timing;
    std::vector<TimePoint> reports;
};

TEST(ReceptionReportTiming, AnIdleUplinkCarriesOneFramePerProbeIntervalAndAReportAtLeastEverySecond) {
    Bench b(1);
    ASSERT_TRUE(b.link.b().core->link_up());
    const std::size_t frames_before = b.link.recorded(kGround).size();
    b.run(std::chrono::seconds(60));
    const std::size_t frames = b.link.recorded(kGround).size() - frames_before;
    // One report 20 ms before each probe's own timer (750 ms of quiet): 60 / 0.73 frames. With a report once
    // a second besides the probes, the uplink carried 121 frames here.
    EXPECT_LE(frames, 84u);
    EXPECT_GE(frames, 80u);
    EXPECT_EQ(frames, b.reports.size());  // every frame of the idle uplink is a report
    ASSERT_GE(b.reports.size(), 60u);
    for (std::size_t i = 1; i < b.reports.size(); ++i) {
        EXPECT_LE(b.reports[i] - b.reports[i - 1], ReportTiming::kPeriod);
        EXPECT_GE(b.reports[i] - b.reports[i - 1], ReportTiming::kMinGap);
    }
    EXPECT_EQ(b.reports_heard(), b.reports.size());  // a clean radio: every report arrives
    EXPECT_TRUE(b.link.a().core->link_up());
}

TEST(ReceptionReportTiming, AnUplinkBusyWithOtherTrafficReportsOnceASecond) {
    Bench b(2);
    ASSERT_TRUE(b.link.b().core->link_up());
    b.run(std::chrono::seconds(30), std::chrono::milliseconds(100));  // a joystick's 10 Hz
    ASSERT_GE(b.reports.size(), 29u);
    EXPECT_LE(b.reports.size(), 31u);
    for (std::size_t i = 1; i < b.reports.size(); ++i) {
        EXPECT_EQ(b.reports[i] - b.reports[i - 1], ReportTiming::kPeriod);
    }
}

TEST(ReceptionReportTiming, NothingIsReportedWhileTheLinkIsDown) {
    Bench b(3);
    b.link.path(0).b_to_a_up = false;
    b.link.path(0).a_to_b_up = false;
    b.run(std::chrono::seconds(10));  // link_down_after (3 s) passes
    ASSERT_FALSE(b.link.b().core->link_up());
    const std::size_t reports = b.reports.size();
    b.run(std::chrono::seconds(10));
    EXPECT_EQ(b.reports.size(), reports);
}

}  // namespace
}  // namespace airseg::groundside

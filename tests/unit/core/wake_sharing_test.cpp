// WakeSharing and SlackTimer: periodic work runs at the first wake-up after it is due, on its own timer only
// when nothing woke the process within its slack. Real io_context, real timers.
#include "services/common/wake_sharing.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <vector>

#include "services/common/deadline_timer.hpp"
#include "services/common/slack_timer.hpp"

namespace airseg {
namespace {

const TimePoint kT0 = TimePoint(seconds(1000));

TEST(WakeSharing, RunsOnlyWhatIsDueAndForgetsIt) {
    WakeSharing sharing;
    std::vector<int> ran;
    sharing.add(kT0 + milliseconds(10), [&] { ran.push_back(1); });
    sharing.add(kT0 + milliseconds(30), [&] { ran.push_back(2); });
    sharing.woke(kT0 + milliseconds(5));
    EXPECT_TRUE(ran.empty());
    sharing.woke(kT0 + milliseconds(10));
    EXPECT_EQ(ran, std::vector<int>{1});
    sharing.woke(kT0 + milliseconds(20));
    EXPECT_EQ(ran, std::vector<int>{1});
    EXPECT_EQ(sharing.waiting(), 1u);
    sharing.woke(kT0 + milliseconds(40));
    EXPECT_EQ(ran, (std::vector<int>{1, 2}));
    EXPECT_EQ(sharing.waiting(), 0u);
    EXPECT_EQ(sharing.shared(), 2u);
}

TEST(WakeSharing, ARemovedRegistrationNeverRunsAndTheNextOneStillDoes) {
    WakeSharing sharing;
    std::vector<int> ran;
    const auto first = sharing.add(kT0 + milliseconds(10), [&] { ran.push_back(1); });
    sharing.add(kT0 + milliseconds(20), [&] { ran.push_back(2); });
    sharing.remove(first);
    sharing.remove(first);  // twice: ignored
    sharing.woke(kT0 + milliseconds(15));
    EXPECT_TRUE(ran.empty());
    sharing.woke(kT0 + milliseconds(25));
    EXPECT_EQ(ran, std::vector<int>{2});
}

TEST(WakeSharing, ARunMayRegisterAgain) {
    WakeSharing sharing;
    int runs = 0;
    std::function<void()> tick = [&] {
        ++runs;
        sharing.add(kT0 + milliseconds(100 * (runs + 1)), tick);
    };
    sharing.add(kT0 + milliseconds(100), tick);
    sharing.woke(kT0 + milliseconds(150));
    sharing.woke(kT0 + milliseconds(160));
    sharing.woke(kT0 + milliseconds(250));
    EXPECT_EQ(runs, 2);
    EXPECT_EQ(sharing.waiting(), 1u);
}

class SlackTimerTest : public ::testing::Test {
  protected:
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    WakeSharing sharing;

    // Calls sharing.woke() at `at`, as a port's read handler does when bytes arrive.
    void input_at(asio::steady_timer& input, TimePoint at) {
        input.expires_at(at);
        input.async_wait([this](const boost::system::error_code& ec) {
            if (!ec) {
                sharing.woke(SteadyClock::now());
            }
        });
    }
};

TEST_F(SlackTimerTest, WithNothingElseAwakeItRunsAtDuePlusSlack) {
    SlackTimer timer(strand, &sharing);
    const TimePoint due = SteadyClock::now() + milliseconds(20);
    std::vector<TimePoint> ran;
    timer.arm(due, milliseconds(60), [&] { ran.push_back(SteadyClock::now()); });
    EXPECT_EQ(timer.due(), due);
    io.run();
    ASSERT_EQ(ran.size(), 1u);
    EXPECT_GE(ran[0], due + milliseconds(60));
    EXPECT_EQ(timer.due(), kNever);
    EXPECT_EQ(sharing.waiting(), 0u);
}

TEST_F(SlackTimerTest, AnInputAfterDueRunsItOnceAtThatWakeUp) {
    SlackTimer timer(strand, &sharing);
    asio::steady_timer input(io);
    const TimePoint start = SteadyClock::now();
    // 100 ms apart: under qemu-arm beside a loaded suite, setting up took longer than the 10 ms before the
    // first input this case once allowed, and that input came after due.
    const TimePoint due = start + milliseconds(200);
    std::vector<TimePoint> ran;
    timer.arm(due, seconds(5), [&] { ran.push_back(SteadyClock::now()); });
    input_at(input, start + milliseconds(100));  // before due: runs nothing
    ASSERT_LT(SteadyClock::now(), start + milliseconds(100)) << "set up too slowly to come before due";
    io.run_for(start + milliseconds(150) - SteadyClock::now());
    EXPECT_TRUE(ran.empty());
    input_at(input, start + milliseconds(300));
    io.restart();
    io.run();  // returns once nothing is pending: the wait for due + 5 s was dropped
    ASSERT_EQ(ran.size(), 1u);
    EXPECT_GE(ran[0], start + milliseconds(300));
    EXPECT_LT(ran[0], due + seconds(5));
    EXPECT_EQ(sharing.shared(), 1u);
}

TEST_F(SlackTimerTest, ATickThatWakesTheProcessTakesTheOthersDueAlong) {
    SlackTimer early(strand, &sharing);
    SlackTimer plain(strand, &sharing);
    const TimePoint start = SteadyClock::now();
    TimePoint early_ran{};
    TimePoint plain_ran{};
    early.arm(start + milliseconds(5), seconds(5), [&] { early_ran = SteadyClock::now(); });
    plain.arm(start + milliseconds(30), Duration::zero(), [&] { plain_ran = SteadyClock::now(); });
    io.run();
    EXPECT_GE(plain_ran, start + milliseconds(30));
    EXPECT_GE(early_ran, plain_ran);  // in the same wake-up, right after
    EXPECT_LT(early_ran, start + seconds(1));
}

TEST_F(SlackTimerTest, CancelledItRunsNeitherWay) {
    SlackTimer timer(strand, &sharing);
    asio::steady_timer input(io);
    const TimePoint start = SteadyClock::now();
    bool ran = false;
    timer.arm(start + milliseconds(5), milliseconds(20), [&] { ran = true; });
    timer.cancel();
    EXPECT_EQ(sharing.waiting(), 0u);
    input_at(input, start + milliseconds(10));
    io.run();
    EXPECT_FALSE(ran);
}

TEST_F(SlackTimerTest, WithoutSharingItIsAPlainTimerAtDue) {
    SlackTimer timer(strand, nullptr);
    const TimePoint due = SteadyClock::now() + milliseconds(20);
    TimePoint ran{};
    timer.arm(due, seconds(5), [&] { ran = SteadyClock::now(); });
    io.run();
    EXPECT_GE(ran, due);
    EXPECT_LT(ran, due + seconds(5));
}

std::int64_t voluntary_switches() {
    rusage usage{};
    getrusage(RUSAGE_THREAD, &usage);
    return usage.ru_nvcsw;
}

// asio reprograms its timerfd only for a new earliest deadline: without help, a deadline moved later, past
// another one, still woke the thread at its old instant. Counted as the thread's voluntary sleeps.
TEST(TimerWakeUps, ADeadlineMovedLaterPastAnotherNoLongerWakesAtItsOldInstant) {
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    DeadlineTimer timer(strand);
    asio::steady_timer other(io);
    const TimePoint start = SteadyClock::now();
    int fired = 0;
    // Deadlines 100 ms apart: under qemu-arm beside a loaded suite, setting up took more than the 20 ms
    // this case once allowed, and a wake-up already due at io.run() is no sleep to count.
    timer.arm(start + milliseconds(100), [&] { ++fired; });
    other.expires_at(start + milliseconds(350));
    other.async_wait([](const boost::system::error_code&) {});
    timer.arm(start + milliseconds(600), [&] { ++fired; });
    const auto before = voluntary_switches();
    ASSERT_LT(SteadyClock::now(), start + milliseconds(350)) << "set up too slowly to count the sleeps";
    io.run();
    EXPECT_EQ(fired, 1);
    EXPECT_GE(SteadyClock::now(), start + milliseconds(600));
    // Asleep until the other timer, then until the new deadline; not also at +100 ms.
    EXPECT_EQ(voluntary_switches() - before, 2);
}

TEST(TimerWakeUps, ASlackTimerRunAtAnotherWakeUpLeavesNoWakeUpAtItsDeadline) {
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    WakeSharing sharing;
    SlackTimer tick(strand, &sharing);
    asio::steady_timer input(io);
    asio::steady_timer end(io);
    const TimePoint start = SteadyClock::now();
    int ran = 0;
    // As above, 100 ms apart or more.
    tick.arm(start + milliseconds(50), milliseconds(300), [&] { ++ran; });
    input.expires_at(start + milliseconds(100));
    input.async_wait([&](const boost::system::error_code&) { sharing.woke(SteadyClock::now()); });
    end.expires_at(start + milliseconds(750));
    end.async_wait([](const boost::system::error_code&) {});
    const auto before = voluntary_switches();
    ASSERT_LT(SteadyClock::now(), start + milliseconds(100)) << "set up too slowly to count the sleeps";
    io.run();
    EXPECT_EQ(ran, 1);
    // Asleep until the input, then until the end; not also at the tick's own deadline (+350 ms).
    EXPECT_EQ(voluntary_switches() - before, 2);
}

}  // namespace
}  // namespace airseg

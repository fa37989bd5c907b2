// DeadlineTimer on a real io_context: the instants it fires at, and the completions it must not deliver.
#include "services/common/deadline_timer.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <vector>

namespace airseg {
namespace {

class DeadlineTimerTest : public ::testing::Test {
  protected:
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    std::vector<TimePoint> fired_a;
    std::vector<TimePoint> fired_b;

    auto record(std::vector<TimePoint>& into) {
        return [&into] { into.push_back(SteadyClock::now()); };
    }

    // Arms `first_in` from now, then `second_in`: only the second fires, at its deadline.
    void expect_second_arm_wins(Duration first_in, Duration second_in) {
        DeadlineTimer timer(strand);
        const TimePoint start = SteadyClock::now();
        timer.arm(start + first_in, record(fired_a));
        timer.arm(start + second_in, record(fired_b));
        io.run();
        EXPECT_TRUE(fired_a.empty());
        ASSERT_EQ(fired_b.size(), 1u);
        EXPECT_GE(fired_b[0], start + second_in);
        if (second_in < first_in) {
            EXPECT_LT(fired_b[0], start + first_in);
        }
    }
};

TEST_F(DeadlineTimerTest, FiresAtTheDeadlineAndDisarms) {
    DeadlineTimer timer(strand);
    const TimePoint deadline = SteadyClock::now() + milliseconds(30);
    TimePoint armed_during_handler{};
    timer.arm(deadline, [&] {
        armed_during_handler = timer.armed();
        fired_a.push_back(SteadyClock::now());
    });
    EXPECT_EQ(timer.armed(), deadline);
    io.run();
    ASSERT_EQ(fired_a.size(), 1u);
    EXPECT_GE(fired_a[0], deadline);
    EXPECT_EQ(armed_during_handler, kNever);
    EXPECT_EQ(timer.armed(), kNever);
}

TEST_F(DeadlineTimerTest, PastDeadlineFiresOnTheNextRun) {
    DeadlineTimer timer(strand);
    timer.arm(SteadyClock::now() - milliseconds(5), record(fired_a));
    EXPECT_TRUE(fired_a.empty());
    io.run();
    EXPECT_EQ(fired_a.size(), 1u);
}

TEST_F(DeadlineTimerTest, HandlerMayArmTheNextDeadline) {
    DeadlineTimer timer(strand);
    const TimePoint first = SteadyClock::now() + milliseconds(5);
    const TimePoint second = first + milliseconds(20);
    timer.arm(first, [&] {
        fired_a.push_back(SteadyClock::now());
        timer.arm(second, record(fired_b));
    });
    io.run();
    ASSERT_EQ(fired_a.size(), 1u);
    ASSERT_EQ(fired_b.size(), 1u);
    EXPECT_GE(fired_b[0], second);
}

TEST_F(DeadlineTimerTest, SameDeadlineKeepsTheWaitAndItsHandler) {
    DeadlineTimer timer(strand);
    const TimePoint deadline = SteadyClock::now() + milliseconds(20);
    timer.arm(deadline, record(fired_a));
    timer.arm(deadline, record(fired_b));
    timer.arm(deadline, record(fired_b));
    io.run();
    ASSERT_EQ(fired_a.size(), 1u);
    EXPECT_GE(fired_a[0], deadline);
    EXPECT_TRUE(fired_b.empty());
}

TEST_F(DeadlineTimerTest, NeverCancels) {
    DeadlineTimer timer(strand);
    timer.arm(SteadyClock::now() + milliseconds(20), record(fired_a));
    timer.arm(kNever, record(fired_b));
    EXPECT_EQ(timer.armed(), kNever);
    io.run();
    EXPECT_TRUE(fired_a.empty());
    EXPECT_TRUE(fired_b.empty());
}

TEST_F(DeadlineTimerTest, CancelStops) {
    DeadlineTimer timer(strand);
    timer.arm(SteadyClock::now() + milliseconds(20), record(fired_a));
    timer.cancel();
    EXPECT_EQ(timer.armed(), kNever);
    io.run();
    EXPECT_TRUE(fired_a.empty());
}

TEST_F(DeadlineTimerTest, EarlierArmReplacesLater) {
    // The replaced deadline is far enough that firing before it says the earlier arm took effect, however
    // loaded the machine is.
    expect_second_arm_wins(std::chrono::seconds(30), milliseconds(20));
}

TEST_F(DeadlineTimerTest, LaterArmReplacesEarlier) {
    expect_second_arm_wins(milliseconds(10), milliseconds(40));
}

// Two deadlines already past complete in one pass of the reactor, earliest first: the first handler runs
// while the DeadlineTimer's completion is already queued as a success, which asio cannot take back.
class QueuedCompletionTest : public DeadlineTimerTest {
  protected:
    void before_timer_completes(std::function<void()> action) {
        const TimePoint now = SteadyClock::now();
        other.expires_at(now - milliseconds(10));
        other.async_wait([action = std::move(action)](const boost::system::error_code& ec) {
            if (!ec) {
                action();
            }
        });
        timer->arm(now - milliseconds(5), record(fired_a));
    }

    asio::steady_timer other{strand};
    std::unique_ptr<DeadlineTimer> timer = std::make_unique<DeadlineTimer>(strand);
};

TEST_F(QueuedCompletionTest, CancelDropsAQueuedCompletion) {
    before_timer_completes([this] { timer->cancel(); });
    io.run();
    EXPECT_TRUE(fired_a.empty());
}

TEST_F(QueuedCompletionTest, ReArmDropsAQueuedCompletion) {
    const TimePoint later = SteadyClock::now() + milliseconds(20);
    before_timer_completes([this, later] { timer->arm(later, record(fired_b)); });
    io.run();
    EXPECT_TRUE(fired_a.empty());
    ASSERT_EQ(fired_b.size(), 1u);
    EXPECT_GE(fired_b[0], later);
}

TEST_F(QueuedCompletionTest, DestroyingTheOwnerDropsAQueuedCompletion) {
    before_timer_completes([this] { timer.reset(); });
    io.run();
    EXPECT_TRUE(fired_a.empty());
}

TEST_F(DeadlineTimerTest, DestroyingTheOwnerCancelsThePendingWait) {
    auto timer = std::make_unique<DeadlineTimer>(strand);
    timer->arm(SteadyClock::now() + milliseconds(20), record(fired_a));
    timer.reset();
    io.run();
    EXPECT_TRUE(fired_a.empty());
}

}  // namespace
}  // namespace airseg

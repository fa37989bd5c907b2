// The log-flood limiter in simulated time: a burst per period passes, the rest is counted and summarised.
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>

#include "base/line_limiter.hpp"
#include "services/common/limited_log.hpp"

namespace airseg {
namespace {

TEST(LineLimiter, TheFirstBurstPassesThenLinesAreCountedUntilThePeriodEnds) {
    LineLimiter limiter({5, seconds(10)});
    const TimePoint t0{};
    unsigned passed = 0;
    for (int i = 0; i < 12'005; ++i) {
        const auto v = limiter.admit(t0 + milliseconds(i / 2));  // 2 lines per ms: 6 s of flood
        passed += v.pass ? 1 : 0;
        EXPECT_EQ(v.held, 0u);
    }
    EXPECT_EQ(passed, 5u);
    EXPECT_EQ(limiter.held_total(), 12'000u);

    // The first line of the next window passes and carries the count of the one before.
    const auto next = limiter.admit(t0 + seconds(10));
    EXPECT_TRUE(next.pass);
    EXPECT_EQ(next.held, 12'000u);
    EXPECT_FALSE(limiter.poll_held(t0 + seconds(30)));  // nothing held since
}

TEST(LineLimiter, AFloodOfAnHourCostsABurstAndASummaryPerPeriod) {
    LineLimiter limiter({5, seconds(10)});
    const TimePoint t0{};
    std::uint64_t passed = 0, summaries = 0, held = 0;
    for (std::int64_t ms = 0; ms < 3'600'000; ms += 1) {  // 1000 lines a second for an hour
        const auto v = limiter.admit(t0 + milliseconds(ms));
        passed += v.pass ? 1 : 0;
        summaries += v.held > 0 ? 1 : 0;
        held += v.held;
    }
    EXPECT_EQ(passed, 360u * 5);
    EXPECT_EQ(summaries, 359u);  // the last window's count is still to come
    EXPECT_EQ(held + *limiter.poll_held(t0 + seconds(3600)), 3'600'000u - 360 * 5);
}

TEST(LineLimiter, AKindThatFallsSilentIsSummarisedByTheTick) {
    LineLimiter limiter({2, seconds(10)});
    const TimePoint t0{};
    for (int i = 0; i < 7; ++i) {
        limiter.admit(t0 + seconds(1));
    }
    EXPECT_FALSE(limiter.poll_held(t0 + seconds(10))) << "the window (from the first line) is still open";
    EXPECT_EQ(limiter.poll_held(t0 + seconds(11)), 5u);
    EXPECT_FALSE(limiter.poll_held(t0 + seconds(12))) << "said once";
    // A quiet kind passes again at once.
    const auto v = limiter.admit(t0 + seconds(13));
    EXPECT_TRUE(v.pass);
    EXPECT_EQ(v.held, 0u);
}

TEST(LineLimiter, LinesSpreadOutBelowTheBurstAllPass) {
    LineLimiter limiter({5, seconds(10)});
    const TimePoint t0{};
    for (int i = 0; i < 1000; ++i) {
        EXPECT_TRUE(limiter.admit(t0 + seconds(2 * i)).pass);
    }
    EXPECT_EQ(limiter.held_total(), 0u);
}

class LimitedLogTest : public ::testing::Test {
  protected:
    LimitedLogTest() {
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_st>(out);
        sink->set_pattern("%l %v");
        previous = spdlog::default_logger();
        spdlog::set_default_logger(std::make_shared<spdlog::logger>("test", sink));
    }
    ~LimitedLogTest() override { spdlog::set_default_logger(previous); }

    std::vector<std::string> lines() const {
        std::vector<std::string> result;
        std::istringstream in(out.str());
        for (std::string line; std::getline(in, line);) {
            result.push_back(line);
        }
        return result;
    }

    std::ostringstream out;
    std::shared_ptr<spdlog::logger> previous;
};

TEST_F(LimitedLogTest, EachKindHasItsOwnBudgetAndTheSummaryNamesIt) {
    LimitedLog log({3, seconds(10)});
    const TimePoint t0{};
    const auto before = LimitedLog::held_everywhere();
    for (int i = 0; i < 12'003; ++i) {
        log.log("autopilot: autopilot rebooted", t0 + microseconds(i), spdlog::level::warn,
                "autopilot: autopilot rebooted ({})", i);
    }
    log.log("autopilot: unknown message", t0 + seconds(1), spdlog::level::info, "autopilot: unknown message");
    EXPECT_EQ(lines().size(), 4u) << out.str();
    log.log("autopilot: autopilot rebooted", t0 + seconds(10), spdlog::level::warn,
            "autopilot: autopilot rebooted (late)");
    const auto all = lines();
    ASSERT_EQ(all.size(), 6u) << out.str();
    EXPECT_EQ(all[4],
              "warning autopilot: autopilot rebooted … repeated 12,000 more times in 10 s (not logged)");
    EXPECT_EQ(all[5], "warning autopilot: autopilot rebooted (late)");
    EXPECT_EQ(log.held_total(), 12'000u);
    EXPECT_EQ(LimitedLog::held_everywhere() - before, 12'000u);
}

TEST_F(LimitedLogTest, FlushSaysHowManyWereHeldOnceTheFloodStopped) {
    LimitedLog log({1, seconds(10)});
    const TimePoint t0{};
    for (int i = 0; i < 4; ++i) {
        log.log("status: client", t0, spdlog::level::info, "status: client {}", i);
    }
    log.flush(t0 + seconds(5));
    EXPECT_EQ(lines().size(), 1u);
    log.flush(t0 + seconds(10));
    ASSERT_EQ(lines().size(), 2u);
    EXPECT_EQ(lines()[1], "info status: client … repeated 3 more times in 10 s (not logged)");
}

TEST(LimitedLogThousands, GroupsDigits) {
    EXPECT_EQ(LimitedLog::thousands(0), "0");
    EXPECT_EQ(LimitedLog::thousands(999), "999");
    EXPECT_EQ(LimitedLog::thousands(1000), "1,000");
    EXPECT_EQ(LimitedLog::thousands(12'000), "12,000");
    EXPECT_EQ(LimitedLog::thousands(1'234'567), "1,234,567");
}

}  // namespace
}  // namespace airseg

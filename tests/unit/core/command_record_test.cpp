// At most once: a command that changes something, sent again under its request id (its answer lost, a
// reconnect, the operator retrying), is answered from the vehicle's record and never run twice.
#include "services/common/command_record.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "services/common/command_dispatcher.hpp"

namespace airseg {
namespace {

class AtMostOnce : public ::testing::Test {
  protected:
    AtMostOnce() {
        dispatcher.add("plan.append", strand, Role::Control,
                       [&](const Json& req, CommandDispatcher::Reply r) {
                           ++appended;
                           if (hold) {
                               held.push_back(std::move(r));
                               return;
                           }
                           r(CommandResult::ok({{"elements", appended}, {"file", req.value("path", "")}}));
                       });
        dispatcher.add("status", strand, Role::Monitor, [&](const Json&, CommandDispatcher::Reply r) {
            ++statuses;
            r(CommandResult::ok({{"n", statuses}}));
        });
    }
    std::optional<CommandResult> call(const Json& request) {
        std::optional<CommandResult> got;
        dispatcher.dispatch(request, Role::Control, [&](CommandResult r) { got = std::move(r); });
        io.run();
        io.restart();
        return got;
    }
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    CommandDispatcher dispatcher;
    int appended = 0;
    int statuses = 0;
    bool hold = false;
    std::vector<CommandDispatcher::Reply> held;
};

TEST_F(AtMostOnce, ACommandSentAgainUnderItsIdIsAnsweredFromTheRecordNotRunAgain) {
    const Json append{{"cmd", "plan.append"}, {"path", "leg2.yaml"}, {"request_id", "a1b2c3"}};
    const auto first = call(append);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->status, CommandStatus::Ok);
    EXPECT_FALSE(first->replayed);
    EXPECT_FALSE(first->to_json().contains("replayed"));

    const auto again = call(append);
    ASSERT_TRUE(again);
    EXPECT_EQ(appended, 1) << "run twice";
    EXPECT_TRUE(again->replayed);
    EXPECT_EQ(again->result, first->result);
    EXPECT_EQ(again->to_json()["replayed"], true);

    // Without an id, or under another, it is a new command.
    (void)call({{"cmd", "plan.append"}, {"path", "leg2.yaml"}});
    (void)call({{"cmd", "plan.append"}, {"path", "leg2.yaml"}, {"request_id", 77}});
    EXPECT_EQ(appended, 3);
    const auto s = dispatcher.record_stats();
    EXPECT_EQ(s.recorded, 2u);
    EXPECT_EQ(s.replayed, 1u);
    EXPECT_EQ(s.entries, 2u);
}

TEST_F(AtMostOnce, ARetryWhileTheFirstStillRunsGetsTheFirstsAnswer) {
    hold = true;
    const Json append{{"cmd", "plan.append"}, {"path", "x.yaml"}, {"request_id", "slow-1"}};
    std::vector<CommandResult> answers;
    for (int i = 0; i < 3; ++i) {
        dispatcher.dispatch(append, Role::Control, [&](CommandResult r) { answers.push_back(std::move(r)); });
        io.run();
        io.restart();
    }
    EXPECT_EQ(appended, 1);
    EXPECT_TRUE(answers.empty()) << "answered before the command finished";
    ASSERT_EQ(held.size(), 1u);
    held.front()(CommandResult::ok({{"elements", 9}}));
    ASSERT_EQ(answers.size(), 3u);
    for (const auto& a : answers) {
        EXPECT_EQ(a.result["elements"], 9);
    }
    EXPECT_EQ(std::count_if(answers.begin(), answers.end(), [](const auto& a) { return a.replayed; }), 2);
    EXPECT_EQ(dispatcher.record_stats().joined, 2u);
}

TEST_F(AtMostOnce, AnIdReusedForAnotherCommandIsRefusedAndNamed) {
    (void)call({{"cmd", "plan.append"}, {"path", "a.yaml"}, {"request_id", "r1"}});
    const auto other = call({{"cmd", "plan.append"}, {"path", "b.yaml"}, {"request_id", "r1"}});
    ASSERT_TRUE(other);
    EXPECT_EQ(other->status, CommandStatus::BadRequest);
    EXPECT_NE(other->error.find("request_id 'r1'"), std::string::npos) << other->error;
    EXPECT_EQ(appended, 1);
    EXPECT_EQ(dispatcher.record_stats().conflicts, 1u);
}

TEST_F(AtMostOnce, ReadOnlyCommandsRunEveryTimeAndBadIdsAreRefused) {
    (void)call({{"cmd", "status"}, {"request_id", "s"}});
    const auto second = call({{"cmd", "status"}, {"request_id", "s"}});
    ASSERT_TRUE(second);
    EXPECT_EQ(statuses, 2);
    EXPECT_FALSE(second->replayed);

    for (const Json& bad :
         {Json(""), Json("has space"), Json(std::string(65, 'x')), Json(-1), Json(1.5), Json::array()}) {
        const auto r = call({{"cmd", "plan.append"}, {"path", "a.yaml"}, {"request_id", bad}});
        ASSERT_TRUE(r);
        EXPECT_EQ(r->status, CommandStatus::BadRequest) << bad.dump();
        EXPECT_NE(r->error.find("\"request_id\" must be"), std::string::npos) << r->error;
    }
    EXPECT_EQ(appended, 0);
}

TEST(CommandRecordBound, OldAnswersAreForgottenByAgeAndByCountButNeverARunningOne) {
    using namespace std::chrono_literals;
    CommandRecord record(3, 10min);
    const TimePoint t0{};
    std::vector<CommandResult> got;
    CommandRecord::Reply reply = [&](CommandResult r) { got.push_back(std::move(r)); };
    // "a" still runs; "b" and "c" are answered.
    EXPECT_EQ(record.admit("a", 1, t0, reply), CommandRecord::Admit::Run);
    for (const char* id : {"b", "c"}) {
        EXPECT_EQ(record.admit(id, 1, t0, reply), CommandRecord::Admit::Run);
        record.finish(id, 1, CommandResult::ok(), t0);
    }
    // A fourth goes in: the oldest answered one ("b") is dropped early, the running "a" stays.
    EXPECT_EQ(record.admit("d", 1, t0 + 1s, reply), CommandRecord::Admit::Run);
    EXPECT_EQ(record.stats().forgotten_early, 1u);
    EXPECT_EQ(record.admit("b", 1, t0 + 2s, reply), CommandRecord::Admit::Run) << "b was forgotten";
    EXPECT_EQ(record.admit("a", 1, t0 + 2s, reply), CommandRecord::Admit::Joined);
    // Full of running commands: a new one runs unrecorded.
    EXPECT_EQ(record.admit("e", 1, t0 + 2s, reply), CommandRecord::Admit::Run);
    EXPECT_EQ(record.stats().unrecorded, 1u);
    EXPECT_EQ(record.stats().entries, 3u);

    // Answered entries live 10 minutes from their answer.
    record.finish("a", 1, CommandResult::ok(), t0 + 3s);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_TRUE(got.front().replayed);
    EXPECT_EQ(record.admit("a", 1, t0 + 3s + 9min, reply), CommandRecord::Admit::Replayed);
    EXPECT_EQ(record.admit("a", 1, t0 + 3s + 10min, reply), CommandRecord::Admit::Run) << "kept too long";
}

}  // namespace
}  // namespace airseg

// Reply on a real io_context with strands and threads: where the completion runs, that it runs exactly once,
// the fallback when nobody answers, and silence once the requester's guard is gone.
#include "services/common/reply.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "services/common/bus.hpp"

namespace airseg {
namespace {

struct Answer {
    std::string text;
};

struct Request {
    Reply<Answer> reply;
};

class ReplyTest : public ::testing::Test {
  protected:
    asio::io_context io;
    Strand caller = asio::make_strand(io);
    Strand service = asio::make_strand(io);
    ReplyGuard guard;
    std::vector<std::string> answers;  // touched on `caller` only
    bool on_caller_strand = true;

    Reply<Answer> make_reply() {
        return Reply<Answer>(caller, guard, Answer{"fallback"}, [this](const Answer& a) {
            on_caller_strand = on_caller_strand && caller.running_in_this_thread();
            answers.push_back(a.text);
        });
    }

    // Runs the io_context on two threads, so the answering and the completing strands run concurrently.
    void run_two_threads() {
        std::thread other([this] { io.run(); });
        io.run();
        other.join();
    }
};

TEST_F(ReplyTest, CompletesOnTheCallersStrand) {
    Bus bus;
    auto sub = bus.subscribe<Request>(service, [this](const Request& r) {
        EXPECT_TRUE(service.running_in_this_thread());
        r.reply(Answer{"done"});
    });
    bus.publish(Request{make_reply()});
    run_two_threads();
    ASSERT_EQ(answers, std::vector<std::string>{"done"});
    EXPECT_TRUE(on_caller_strand);
}

TEST_F(ReplyTest, TwoCopiesAnsweredCompleteOnce) {
    Bus bus;
    auto first = bus.subscribe<Request>(service, [](const Request& r) { r.reply(Answer{"first"}); });
    auto other_strand = asio::make_strand(io);
    auto second = bus.subscribe<Request>(other_strand, [](const Request& r) { r.reply(Answer{"second"}); });
    for (int i = 0; i < 50; ++i) {
        bus.publish(Request{make_reply()});
    }
    run_two_threads();
    ASSERT_EQ(answers.size(), 50u);
    for (const auto& a : answers) {
        EXPECT_TRUE(a == "first" || a == "second") << a;
    }
    EXPECT_TRUE(on_caller_strand);
}

TEST_F(ReplyTest, FallbackWhenNobodySubscribes) {
    Bus bus;
    bus.publish(Request{make_reply()});
    io.run();
    EXPECT_EQ(answers, std::vector<std::string>{"fallback"});
}

TEST_F(ReplyTest, FallbackWhenEveryCopyIsDroppedUnanswered) {
    // A service keeps the request until it stops, then drops it on its own strand.
    Bus bus;
    std::vector<Reply<Answer>> kept;  // touched on `service` only
    auto sub = bus.subscribe<Request>(service, [&](const Request& r) {
        kept.push_back(r.reply);
        asio::post(service, [&] { kept.clear(); });
    });
    bus.publish(Request{make_reply()});
    run_two_threads();
    EXPECT_EQ(answers, std::vector<std::string>{"fallback"});
    EXPECT_TRUE(on_caller_strand);
}

TEST_F(ReplyTest, AnsweredThenDroppedDoesNotAddTheFallback) {
    auto reply = make_reply();
    auto copy = reply;
    copy(Answer{"done"});
    copy = Reply<Answer>();
    reply = Reply<Answer>();
    io.run();
    EXPECT_EQ(answers, std::vector<std::string>{"done"});
}

TEST_F(ReplyTest, AnEmptyReplyIgnoresAnswers) {
    Reply<Answer> empty;
    EXPECT_FALSE(empty);
    empty(Answer{"nobody"});
    EXPECT_TRUE(make_reply());
    io.run();
    EXPECT_EQ(answers, std::vector<std::string>{"fallback"});
}

TEST_F(ReplyTest, NoCompletionOnceTheGuardIsGone) {
    // A requester's guard goes away on its strand after one answer was posted and before another call is
    // dropped: neither completion may run.
    auto requester_guard = std::make_unique<ReplyGuard>();
    int calls = 0;  // touched on `caller` only
    auto answered =
        Reply<Answer>(caller, *requester_guard, Answer{"fallback"}, [&](const Answer&) { ++calls; });
    auto dropped =
        Reply<Answer>(caller, *requester_guard, Answer{"fallback"}, [&](const Answer&) { ++calls; });
    asio::post(caller, [&] {
        answered(Answer{"done"});  // posted to this strand, runs after the guard is gone
        requester_guard.reset();
        asio::post(service, [&] { dropped = Reply<Answer>(); });
    });
    run_two_threads();
    EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace airseg

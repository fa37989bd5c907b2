#include "services/common/command_dispatcher.hpp"

#include <gtest/gtest.h>

#include <optional>

namespace airseg {
namespace {

class DispatcherTest : public ::testing::Test {
  protected:
    std::optional<CommandResult> call(const Json& request, Role role) {
        std::optional<CommandResult> got;
        dispatcher.dispatch(request, role, [&](CommandResult r) { got = std::move(r); });
        io.run();
        io.restart();
        return got;
    }
    asio::io_context io;
    Strand strand = asio::make_strand(io);
    CommandDispatcher dispatcher;
};

TEST_F(DispatcherTest, RunsTheHandlerOnItsStrandAndRepliesOnce) {
    dispatcher.add("echo", strand, Role::Monitor, [&](const Json& req, CommandDispatcher::Reply reply) {
        EXPECT_TRUE(strand.running_in_this_thread());
        reply(CommandResult::ok({{"said", req.value("text", "")}}));
        reply(CommandResult::fail(CommandStatus::Failed, "second answer must be dropped"));
    });
    int replies = 0;
    std::optional<CommandResult> got;
    dispatcher.dispatch({{"cmd", "echo"}, {"text", "hi"}}, Role::Monitor, [&](CommandResult r) {
        ++replies;
        got = r;
    });
    io.run();
    EXPECT_EQ(replies, 1);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->status, CommandStatus::Ok);
    EXPECT_EQ(got->result["said"], "hi");
}

TEST_F(DispatcherTest, UnknownAndMalformedRequestsAreNamed) {
    auto unknown = call({{"cmd", "fly_to_moon"}}, Role::Control);
    ASSERT_TRUE(unknown);
    EXPECT_EQ(unknown->status, CommandStatus::UnknownCommand);
    EXPECT_NE(unknown->error.find("fly_to_moon"), std::string::npos);

    auto malformed = call(Json::array({1, 2}), Role::Control);
    ASSERT_TRUE(malformed);
    EXPECT_EQ(malformed->status, CommandStatus::BadRequest);
}

// The radio's CBOR carries any bytes in a text; a request holding one that is not UTF-8 is refused before any
// handler keeps it (a plan's source, an element's name), so no later JSON dump can throw on it.
TEST_F(DispatcherTest, ARequestWithTextThatIsNotUtf8IsRefusedBeforeItsHandler) {
    bool ran = false;
    dispatcher.add("plan.load", strand, Role::Control, [&](const Json&, CommandDispatcher::Reply reply) {
        ran = true;
        reply(CommandResult::ok());
    });
    for (const Json& request :
         {Json{{"cmd", "plan.load"}, {"text", "plan: x"}, {"source", "n\xff.yaml"}},
          Json{{"cmd", "plan.load"}, {"text", "plan: x"}, {"n\xe9", 1}},
          Json{{"cmd", "plan.load"}, {"list", {"ok", "bad \xc3"}}}, Json{{"cmd", "\xff"}}}) {
        auto r = call(request, Role::Control);
        ASSERT_TRUE(r);
        EXPECT_EQ(r->status, CommandStatus::BadRequest);
        EXPECT_NE(r->error.find("not valid UTF-8"), std::string::npos) << r->error;
        EXPECT_NO_THROW((void)r->to_json().dump()) << "the refusal itself must be valid JSON text";
    }
    EXPECT_FALSE(ran);
    EXPECT_EQ(call({{"cmd", "plan.load"}, {"source", "caf\xc3\xa9.yaml"}}, Role::Control)->status,
              CommandStatus::Ok);
}

TEST_F(DispatcherTest, MonitorCannotRunControlCommands) {
    bool ran = false;
    dispatcher.add("state", strand, Role::Control, [&](const Json&, CommandDispatcher::Reply reply) {
        ran = true;
        reply(CommandResult::ok());
    });
    auto refused = call({{"cmd", "state"}}, Role::Monitor);
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, CommandStatus::Forbidden);
    EXPECT_FALSE(ran);
    auto allowed = call({{"cmd", "state"}}, Role::Control);
    EXPECT_EQ(allowed->status, CommandStatus::Ok);
    EXPECT_TRUE(ran);
}

TEST_F(DispatcherTest, AHandlerThatThrowsStillAnswers) {
    dispatcher.add("bad", strand, Role::Monitor,
                   [](const Json& req, CommandDispatcher::Reply) { (void)req.at("missing").get<int>(); });
    auto got = call({{"cmd", "bad"}}, Role::Monitor);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->status, CommandStatus::BadRequest);
    EXPECT_EQ(got->to_json()["ok"], false);
}

}  // namespace
}  // namespace airseg

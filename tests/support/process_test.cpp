// The child-process helper the integration and system tests stand on.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace airseg::test {
namespace {

TEST(Subprocess, ManyStartedAtOnceEachKeepTheirOwnOutput) {
    // Under qemu-user a spawned child opens its output files after posix_spawn has returned; the system
    // suite's flood case starts 43 clients at once, and two of them once wrote into the same file.
    TempDir dir;
    std::vector<std::unique_ptr<Subprocess>> children;
    for (int i = 0; i < 40; ++i) {
        const std::string n = std::to_string(i);
        children.push_back(std::make_unique<Subprocess>(
            std::vector<std::string>{"/bin/sh", "-c", "echo out-" + n + "; echo err-" + n + " >&2"},
            std::map<std::string, std::string>{}, dir.path()));
    }
    for (std::size_t i = 0; i < children.size(); ++i) {
        ASSERT_EQ(children[i]->wait_exit(std::chrono::seconds(60)), 0);
        EXPECT_EQ(children[i]->out(), "out-" + std::to_string(i) + "\n");
        EXPECT_EQ(children[i]->err(), "err-" + std::to_string(i) + "\n");
    }
}

// A child that does not exit in time is described where it waits, so that a slow exit can be told from a
// hung one in the failure message; one that has exited is not.
TEST(Subprocess, AWaitThatTimesOutSaysWhereTheProcessWas) {
    TempDir dir;
    Subprocess child({"/bin/sleep", "30"}, {}, dir.path());
    EXPECT_EQ(child.stuck(), "");
    EXPECT_EQ(child.wait_exit(std::chrono::milliseconds(200)), std::nullopt);
    EXPECT_TRUE(child.stuck().starts_with("still running 200 ms into a wait for its exit:\n  thread "))
        << child.stuck();
    EXPECT_NE(child.stuck().find(": state S, waits in "), std::string::npos) << child.stuck();
    child.signal(SIGTERM);
    ASSERT_TRUE(child.wait_exit(std::chrono::seconds(30)));
    EXPECT_EQ(child.where(), "");
}

}  // namespace
}  // namespace airseg::test

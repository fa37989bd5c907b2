// The child-process helper the integration and system tests stand on.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <memory>
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

}  // namespace
}  // namespace airseg::test

// PortKeeper on real pseudo-terminals: a device that is missing, appears, is unplugged and comes back.
#include "services/common/port_keeper.hpp"

#include <gtest/gtest.h>
#include <pty.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace airseg {
namespace {

struct Pty {
    Pty() {
        char name[256];
        if (::openpty(&master, &slave, name, nullptr, nullptr) != 0) {
            throw std::runtime_error("openpty failed");
        }
        path = name;
    }
    ~Pty() { close_all(); }
    void close_all() {
        if (slave >= 0) {
            ::close(slave);
            slave = -1;
        }
        if (master >= 0) {
            ::close(master);
            master = -1;
        }
    }
    int master = -1;
    int slave = -1;
    std::string path;
};

class PortKeeperTest : public ::testing::Test {
  protected:
    PortKeeperTest() {
        link =
            (std::filesystem::temp_directory_path() / ("airseg-pk-" + std::to_string(::getpid()))).string();
        std::filesystem::remove(link);
    }
    ~PortKeeperTest() override { std::filesystem::remove(link); }

    std::unique_ptr<PortKeeper> make_keeper() {
        PortKeeperConfig config;
        config.serial.path = link;
        config.serial.baud = 57600;
        config.reconnect_min = std::chrono::milliseconds(10);
        config.reconnect_max = std::chrono::milliseconds(40);
        return std::make_unique<PortKeeper>(strand, config,
                                            PortKeeper::Handlers{[this] { ++opens; },
                                                                 [this](std::span<const std::uint8_t> b) {
                                                                     received.append(b.begin(), b.end());
                                                                 },
                                                                 [this](const std::string& reason) {
                                                                     ++downs;
                                                                     last_reason = reason;
                                                                 }});
    }

    /// Runs the loop until `cond` holds, at most `limit` of wall time.
    bool run_until(const std::function<bool()>& cond, std::chrono::seconds limit = std::chrono::seconds(10)) {
        const auto deadline = std::chrono::steady_clock::now() + limit;
        while (!cond() && std::chrono::steady_clock::now() < deadline) {
            io.run_for(std::chrono::milliseconds(5));
            if (io.stopped()) {
                io.restart();
            }
        }
        return cond();
    }

    asio::io_context io;
    Strand strand = asio::make_strand(io);
    std::string link;
    int opens = 0;
    int downs = 0;
    std::string last_reason;
    std::string received;
};

TEST_F(PortKeeperTest, MissingDeviceIsReportedAndRetriedUntilItAppears) {
    auto keeper = make_keeper();
    keeper->start();
    ASSERT_TRUE(run_until([&] { return downs >= 1; }));
    EXPECT_EQ(last_reason, "no " + link);
    EXPECT_FALSE(keeper->is_open());
    ASSERT_TRUE(run_until([&] { return downs >= 3; })) << "retries must continue with backoff";

    Pty pty;
    std::filesystem::create_symlink(pty.path, link);
    ASSERT_TRUE(run_until([&] { return opens == 1; }));
    EXPECT_TRUE(keeper->is_open());

    const std::string hello = "hello";
    ASSERT_EQ(::write(pty.master, hello.data(), hello.size()), ssize_t(hello.size()));
    ASSERT_TRUE(run_until([&] { return received == hello; }));
    keeper->stop();
}

TEST_F(PortKeeperTest, UnplugIsReportedAndTheReplacementDeviceIsReopened) {
    auto pty = std::make_unique<Pty>();
    std::filesystem::create_symlink(pty->path, link);
    auto keeper = make_keeper();
    keeper->start();
    ASSERT_TRUE(run_until([&] { return opens == 1; }));
    const int downs_before = downs;

    // Unplug: the device node goes away with its master.
    std::filesystem::remove(link);
    pty.reset();
    ASSERT_TRUE(run_until([&] { return downs > downs_before; }));
    EXPECT_FALSE(keeper->is_open());

    // Replug as a new device behind the same name.
    Pty replacement;
    std::filesystem::create_symlink(replacement.path, link);
    ASSERT_TRUE(run_until([&] { return opens == 2; }));
    EXPECT_EQ(keeper->reconnects(), 1u);
    keeper->stop();
}

TEST_F(PortKeeperTest, ReopenAtAnotherBaudIsNotAReconnect) {
    Pty pty;
    std::filesystem::create_symlink(pty.path, link);
    auto keeper = make_keeper();
    keeper->start();
    ASSERT_TRUE(run_until([&] { return opens == 1; }));
    const int downs_before = downs;

    keeper->reopen_at(115200);
    ASSERT_TRUE(run_until([&] { return opens == 2; }));
    EXPECT_TRUE(keeper->is_open());
    EXPECT_EQ(keeper->baud(), 115200u);
    EXPECT_EQ(keeper->reconnects(), 0u);
    EXPECT_EQ(downs, downs_before) << "a deliberate reopen is not the device going away";

    const std::string hello = "at 115200";
    ASSERT_EQ(::write(pty.master, hello.data(), hello.size()), ssize_t(hello.size()));
    ASSERT_TRUE(run_until([&] { return received == hello; }));
    keeper->stop();
}

}  // namespace
}  // namespace airseg

// The notify protocol as systemd reads it: datagrams on a real AF_UNIX socket, by path and in the abstract
// namespace, and WATCHDOG_USEC / WATCHDOG_PID read the way sd_watchdog_enabled(3) reads them.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "daemon/systemd_notifier.hpp"
#include "tests/support/process.hpp"

namespace airseg::daemon {
namespace {

using namespace std::chrono_literals;

/// Sets an environment variable for one test and puts the old value back.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) {
            old_ = old;
        }
        if (value != nullptr) {
            ::setenv(name, value, 1);
        } else {
            ::unsetenv(name);
        }
    }
    ~ScopedEnv() {
        if (old_) {
            ::setenv(name_, old_->c_str(), 1);
        } else {
            ::unsetenv(name_);
        }
    }

  private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(SystemdNotifier, SendsEachStateAsOneDatagramToTheSocketPath) {
    test::TempDir dir;
    test::NotifyListener systemd(dir.path() + "/notify");
    ScopedEnv socket("NOTIFY_SOCKET", systemd.path().c_str());
    SystemdNotifier notifier;
    notifier.ready();
    notifier.status("flying");
    notifier.watchdog();
    notifier.stopping();
    ASSERT_TRUE(systemd.wait_for("STOPPING=1", 5s));
    ASSERT_EQ(systemd.messages().size(), 4u);
    EXPECT_EQ(systemd.messages()[0].text, "READY=1");
    EXPECT_EQ(systemd.messages()[1].text, "STATUS=flying");
    EXPECT_EQ(systemd.messages()[2].text, "WATCHDOG=1");
}

TEST(SystemdNotifier, AFullSocketNeverBlocksAndTheStatesThatMustArriveArriveOnceItIsRead) {
    // A socket nobody reads holds net.unix.max_dgram_qlen datagrams (10 by default); a blocking send after
    // that would hold the daemon's signal and watchdog thread until systemd reads.
    test::TempDir dir;
    const std::string path = dir.path() + "/notify";
    const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    ASSERT_GE(fd, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0)
        << std::strerror(errno);
    ScopedEnv socket("NOTIFY_SOCKET", path.c_str());
    SystemdNotifier notifier;
    for (int i = 0; i < 2000; ++i) {  // returns at once every time, full or not
        notifier.watchdog();
    }
    notifier.stopping();  // finds the socket full: kept
    std::vector<std::string> read;
    char buffer[64];
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) {
        read.emplace_back(buffer, static_cast<std::size_t>(n));
    }
    ASSERT_FALSE(read.empty());
    EXPECT_LT(read.size(), 2000u) << "the socket should have filled";
    EXPECT_EQ(std::count(read.begin(), read.end(), "STOPPING=1"), 0);
    notifier.watchdog();  // the kept state goes first, then the ping
    read.clear();
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) {
        read.emplace_back(buffer, static_cast<std::size_t>(n));
    }
    ::close(fd);
    EXPECT_EQ(read, (std::vector<std::string>{"STOPPING=1", "WATCHDOG=1"}));
}

TEST(SystemdNotifier, ReachesASocketInTheAbstractNamespace) {
    const std::string name = "airseg-notify-test-" + std::to_string(::getpid());
    const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(fd, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::memcpy(address.sun_path + 1, name.data(), name.size());  // sun_path[0] == '\0': abstract
    const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name.size());
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), length), 0) << std::strerror(errno);
    timeval wait{5, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);

    ScopedEnv socket("NOTIFY_SOCKET", ("@" + name).c_str());
    SystemdNotifier notifier;
    notifier.ready();
    char buffer[64] = {};
    const auto n = ::recv(fd, buffer, sizeof buffer, 0);
    ::close(fd);
    ASSERT_GT(n, 0) << std::strerror(errno);
    EXPECT_EQ(std::string(buffer, static_cast<std::size_t>(n)), "READY=1");
}

TEST(SystemdNotifier, WithoutNotifySocketEveryCallIsANoOp) {
    ScopedEnv socket("NOTIFY_SOCKET", nullptr);
    SystemdNotifier notifier;
    notifier.ready();
    notifier.watchdog();
    EXPECT_FALSE(notifier.watchdog_period());
}

TEST(SystemdWatchdogPeriod, IsReadFromWatchdogUsecForThisProcess) {
    EXPECT_EQ(watchdog_period_from("3000000", nullptr, 42), std::chrono::microseconds(3'000'000));
    EXPECT_EQ(watchdog_period_from("3000000", "42", 42), std::chrono::microseconds(3'000'000));
}

TEST(SystemdWatchdogPeriod, IsEmptyWhenMeantForAnotherProcessOrMalformed) {
    EXPECT_FALSE(watchdog_period_from("3000000", "43", 42));
    EXPECT_FALSE(watchdog_period_from("3000000", "x", 42));
    EXPECT_FALSE(watchdog_period_from(nullptr, nullptr, 42));
    EXPECT_FALSE(watchdog_period_from("0", nullptr, 42));
    EXPECT_FALSE(watchdog_period_from("", nullptr, 42));
    EXPECT_FALSE(watchdog_period_from("12s", nullptr, 42));
    EXPECT_FALSE(watchdog_period_from("-5", nullptr, 42));
}

TEST(SystemdWatchdogPeriod, TheNotifierTakesItFromTheEnvironment) {
    ScopedEnv usec("WATCHDOG_USEC", "2500000");
    ScopedEnv pid("WATCHDOG_PID", std::to_string(::getpid()).c_str());
    SystemdNotifier notifier;
    EXPECT_EQ(notifier.watchdog_period(), std::chrono::microseconds(2'500'000));
}

}  // namespace
}  // namespace airseg::daemon

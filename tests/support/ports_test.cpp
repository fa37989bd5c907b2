// Ports reserved for the programs a test starts: never one another test process on the machine holds, never
// one the kernel hands out by itself.
#include "tests/support/ports.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <set>

namespace airseg::test {
namespace {

TEST(ReservedPort, LiesOutsideTheKernelsEphemeralRange) {
    // A port the kernel picks for a bind to port 0 comes from this range, and so can be picked again for
    // the next process that asks it: a reserved one never lies in it.
    std::ifstream in("/proc/sys/net/ipv4/ip_local_port_range");
    int low = 0;
    int high = 0;
    ASSERT_TRUE(in >> low >> high);
    for (int i = 0; i < 5; ++i) {
        const int port = reserve_loopback_port();
        EXPECT_TRUE(port < low || port > high) << port << " in " << low << "-" << high;
        EXPECT_GT(port, 0);
    }
}

TEST(ReservedPort, IsHeldAgainstEveryOtherProcessUntilThisOneEnds) {
    const int port = free_udp_port();
    // Another open file description (as another process has) cannot take the port's lock.
    const int fd = ::open(port_lock_path(port).c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0) << port_lock_path(port);
    EXPECT_NE(::flock(fd, LOCK_EX | LOCK_NB), 0) << "port " << port << " is not held";
    ::close(fd);

    // A second test process reserving ports meanwhile never gets this one (nor any other this process holds).
    std::set<int> mine{port};
    for (int i = 0; i < 20; ++i) {
        mine.insert(free_tcp_port());
    }
    EXPECT_EQ(mine.size(), 21U);
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        ::close(pipe_fds[0]);
        for (int i = 0; i < 40; ++i) {
            const int theirs = reserve_loopback_port();
            (void)!::write(pipe_fds[1], &theirs, sizeof theirs);
        }
        ::_exit(0);
    }
    ::close(pipe_fds[1]);
    int theirs = 0;
    int count = 0;
    while (::read(pipe_fds[0], &theirs, sizeof theirs) == static_cast<ssize_t>(sizeof theirs)) {
        ++count;
        EXPECT_EQ(mine.count(theirs), 0U) << "port " << theirs << " given to two processes";
    }
    ::close(pipe_fds[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_EQ(count, 40);

    // Once that process has ended, its ports are free for others again.
    const int again = ::open(port_lock_path(theirs).c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(again, 0);
    EXPECT_EQ(::flock(again, LOCK_EX | LOCK_NB), 0)
        << "port " << theirs << " still held after its process ended";
    ::close(again);
}

}  // namespace
}  // namespace airseg::test

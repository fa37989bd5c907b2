#include "tests/support/ports.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace airseg::test {
namespace {

// Below Linux's default ephemeral range (32768-60999); ports inside the machine's own range are skipped.
constexpr int kFirstPort = 20000;
constexpr int kPortCount = 12000;

std::string lock_dir() {
    const char* dir = std::getenv("AIRSEG_TEST_PORT_DIR");
    return dir != nullptr && *dir != '\0' ? dir : "/tmp/airseg-test-ports";
}

std::pair<int, int> ephemeral_range() {
    std::ifstream in("/proc/sys/net/ipv4/ip_local_port_range");
    int low = 32768;
    int high = 60999;
    in >> low >> high;
    return {low, high};
}

bool bindable(int type, int port) {
    const int fd = ::socket(AF_INET, type | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        return false;
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    ::close(fd);
    return ok;
}

// The lock files' descriptors, open (and locked) until the process ends.
std::mutex held_mutex;
std::vector<int> held;

}  // namespace

std::string port_lock_path(int port) {
    return lock_dir() + "/" + std::to_string(port) + ".lock";
}

int reserve_loopback_port() {
    const std::string dir = lock_dir();
    // Every user's tests share the directory (sticky, like /tmp); an existing one is used as it is.
    if (::mkdir(dir.c_str(), 01777) == 0) {
        ::chmod(dir.c_str(), 01777);
    }
    const auto [ephemeral_low, ephemeral_high] = ephemeral_range();
    // Start where this process's id points, so concurrent processes seldom try the same lock first.
    const int start = static_cast<int>(static_cast<unsigned>(::getpid()) * 7919U % kPortCount);
    std::lock_guard lock(held_mutex);
    for (int i = 0; i < kPortCount; ++i) {
        const int port = kFirstPort + (start + i) % kPortCount;
        if (port >= ephemeral_low && port <= ephemeral_high) {
            continue;
        }
        const int fd = ::open(port_lock_path(port).c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0) {
            throw std::runtime_error("cannot open " + port_lock_path(port) + ": " + std::strerror(errno));
        }
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            ::close(fd);  // another test process holds it
            continue;
        }
        // Held by nobody who asks here, but maybe bound by a program that does not ask (or by a test
        // process's child that outlived it): checked for both protocols.
        if (!bindable(SOCK_DGRAM, port) || !bindable(SOCK_STREAM, port)) {
            ::close(fd);
            continue;
        }
        held.push_back(fd);
        return port;
    }
    throw std::runtime_error("no free loopback port left in " + std::to_string(kFirstPort) + "-" +
                             std::to_string(kFirstPort + kPortCount - 1) + " (locks in " + dir + ")");
}

}  // namespace airseg::test

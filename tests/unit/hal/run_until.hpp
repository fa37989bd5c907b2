#pragma once
// Helpers for HAL tests: drive an io_context until a condition holds, and a raw pty pair made by the test.
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hal/asio.hpp"

namespace airseg::hal::test {

inline constexpr std::chrono::seconds kGenerousTimeout{5};

/// Runs handlers until `done()` is true or `timeout` passes; returns done().
inline bool run_until(boost::asio::io_context& io, const std::function<bool()>& done,
                      std::chrono::steady_clock::duration timeout = kGenerousTimeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done() && std::chrono::steady_clock::now() < deadline) {
        if (io.stopped()) {
            io.restart();
        }
        io.run_one_for(std::chrono::milliseconds(5));
    }
    return done();
}

/// Runs every handler that is ready or becomes ready, returning as soon as the io_context has no work left
/// (or after `limit`, a bound against a bug, not a wait).
inline void run_until_idle(boost::asio::io_context& io,
                           std::chrono::steady_clock::duration limit = std::chrono::seconds(2)) {
    io.restart();
    io.run_for(limit);
}

/// Reads whatever is available on a non-blocking fd, appending to `out`. Returns the read() result that ended
/// the drain (0 or -1), so tests can look at hangups.
inline ssize_t drain(int fd, std::vector<std::uint8_t>& out) {
    std::uint8_t buf[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n <= 0) {
            return n;
        }
        out.insert(out.end(), buf, buf + n);
    }
}

/// Writes all of `bytes` to a possibly non-blocking fd; when the fd is full, waits in poll() for room
/// (another thread must be draining it) up to the generous timeout.
inline bool write_all(int fd, const std::vector<std::uint8_t>& bytes) {
    const auto deadline = std::chrono::steady_clock::now() + kGenerousTimeout;
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n > 0) {
            done += static_cast<std::size_t>(n);
            continue;
        }
        if (n < 0 && errno == EAGAIN && std::chrono::steady_clock::now() < deadline) {
            pollfd p{fd, POLLOUT, 0};
            ::poll(&p, 1, 10);
            continue;
        }
        return false;
    }
    return true;
}

/// A pseudo-terminal made by the test, standing in for the far end of a serial cable: the test holds the
/// master, the code under test opens slave_path.
class TestPty {
  public:
    TestPty() {
        termios raw{};
        ::cfmakeraw(&raw);
        int slave = -1;
        char name[128] = {};
        if (::openpty(&master_, &slave, name, &raw, nullptr) == 0) {
            slave_path_ = name;
            ::close(slave);
            ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
        }
    }
    ~TestPty() { close_master(); }
    TestPty(const TestPty&) = delete;
    TestPty& operator=(const TestPty&) = delete;

    bool ok() const { return master_ >= 0 && !slave_path_.empty(); }
    int master() const { return master_; }
    const std::string& slave_path() const { return slave_path_; }
    void close_master() {
        if (master_ >= 0) {
            ::close(master_);
            master_ = -1;
        }
    }

  private:
    int master_ = -1;
    std::string slave_path_;
};

inline std::vector<std::uint8_t> pattern_bytes(std::size_t n, std::uint32_t seed) {
    std::vector<std::uint8_t> out(n);
    std::uint32_t x = seed;
    for (auto& b : out) {
        x = x * 1664525u + 1013904223u;  // LCG: deterministic, covers all byte values
        b = static_cast<std::uint8_t>(x >> 24);
    }
    return out;
}

}  // namespace airseg::hal::test

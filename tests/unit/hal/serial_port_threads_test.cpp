// The daemon runs one io_context on several threads; a SerialPort lives on its own strand there.
#include <gtest/gtest.h>
#include <poll.h>

#include <atomic>
#include <future>
#include <optional>
#include <thread>

#include "hal/serial_port.hpp"
#include "tests/unit/hal/run_until.hpp"

namespace airseg::hal {
namespace {

using test::drain;
using test::pattern_bytes;
using test::TestPty;

// Reads from `fd` until `want` bytes arrived or `timeout` passed, waiting in poll() rather than sleeping.
std::vector<std::uint8_t> read_exactly(int fd, std::size_t want, std::chrono::milliseconds timeout) {
    std::vector<std::uint8_t> out;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (out.size() < want && std::chrono::steady_clock::now() < deadline) {
        pollfd p{fd, POLLIN, 0};
        ::poll(&p, 1, 10);
        drain(fd, out);
    }
    return out;
}

TEST(HalSerialPortThreadsTest, WorksOnAStrandOfAThreadPool) {
    TestPty pty;
    ASSERT_TRUE(pty.ok());
    boost::asio::io_context io;
    std::optional work(
        boost::asio::require(io.get_executor(), boost::asio::execution::outstanding_work.tracked));
    auto strand = boost::asio::make_strand(io);
    std::vector<std::thread> pool;
    for (int i = 0; i < 3; ++i) {
        pool.emplace_back([&io] { io.run(); });
    }

    auto port = std::make_unique<SerialPort>(strand);
    std::mutex mutex;
    std::vector<std::uint8_t> received;
    std::atomic<std::size_t> received_count{0};
    std::promise<OpenResult> opened;
    // Whatever way the test ends, the pool stops and joins before the objects it uses go away.
    struct Joiner {
        boost::asio::io_context& io;
        std::vector<std::thread>& pool;
        ~Joiner() {
            io.stop();
            for (auto& t : pool) {
                if (t.joinable()) {
                    t.join();
                }
            }
        }
    } joiner{io, pool};
    boost::asio::post(strand, [&] {
        SerialConfig c;
        c.path = pty.slave_path();
        // qemu-user 7.2 (the ARM test runs) translates termios rates up to 460800 only; a pty ignores it.
        c.baud = 460800;
        auto r = port->open(c);
        port->start_reading(
            [&](std::span<const std::uint8_t> b) {
                std::lock_guard lock(mutex);
                received.insert(received.end(), b.begin(), b.end());
                received_count = received.size();
            },
            [](std::error_code, const std::string&) {});
        opened.set_value(r);
    });
    auto open_future = opened.get_future();
    ASSERT_EQ(open_future.wait_for(test::kGenerousTimeout), std::future_status::ready);
    ASSERT_TRUE(open_future.get().ok());

    // Writes posted from a foreign thread, many small ones, must arrive whole and in order.
    std::vector<std::uint8_t> expected;
    for (std::uint32_t i = 0; i < 200; ++i) {
        auto chunk = pattern_bytes(97 + i % 13, i);
        expected.insert(expected.end(), chunk.begin(), chunk.end());
        boost::asio::post(strand,
                          [&port, chunk = std::move(chunk)]() mutable { port->write(std::move(chunk)); });
    }
    EXPECT_EQ(read_exactly(pty.master(), expected.size(), std::chrono::milliseconds(5000)), expected);

    const auto down = pattern_bytes(20000, 99);
    ASSERT_TRUE(test::write_all(pty.master(), down));
    const auto deadline = std::chrono::steady_clock::now() + test::kGenerousTimeout;
    while (received_count < down.size() && std::chrono::steady_clock::now() < deadline) {
        pollfd none{-1, 0, 0};
        ::poll(&none, 1, 5);  // yields to the pool; the loop exits on the condition, not on time
    }
    {
        std::lock_guard lock(mutex);
        EXPECT_EQ(received, down);
    }

    std::promise<void> closed;
    boost::asio::post(strand, [&] {
        port.reset();
        closed.set_value();
    });
    EXPECT_EQ(closed.get_future().wait_for(test::kGenerousTimeout), std::future_status::ready);
    work.reset();
    for (auto& t : pool) {
        t.join();
    }
    EXPECT_TRUE(io.stopped()) << "the pool ran out of work once the port was gone";
}

}  // namespace
}  // namespace airseg::hal

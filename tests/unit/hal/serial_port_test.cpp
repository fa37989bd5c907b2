#include "hal/serial_port.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "tests/unit/hal/run_until.hpp"

namespace airseg::hal {
namespace {

using test::drain;
using test::pattern_bytes;
using test::run_until;
using test::run_until_idle;
using test::TestPty;

struct Received {
    std::vector<std::uint8_t> bytes;
    std::vector<std::pair<std::error_code, std::string>> errors;
};

class HalSerialPortTest : public ::testing::Test {
  protected:
    void SetUp() override { ASSERT_TRUE(pty_.ok()) << "openpty failed"; }

    SerialConfig config_for(const TestPty& pty, unsigned baud = 115200) {
        SerialConfig c;
        c.path = pty.slave_path();
        c.baud = baud;
        return c;
    }

    void open_and_read(SerialPort& port, const SerialConfig& config) {
        auto result = port.open(config);
        ASSERT_TRUE(result.ok()) << result.message;
        port.start_reading(
            [this](std::span<const std::uint8_t> b) {
                received_.bytes.insert(received_.bytes.end(), b.begin(), b.end());
            },
            [this](std::error_code ec, const std::string& what) { received_.errors.emplace_back(ec, what); });
    }

    boost::asio::io_context io_;
    TestPty pty_;
    Received received_;
};

TEST(HalSerialConfigTest, RejectsNonStandardBaudNamingIt) {
    SerialConfig c;
    c.path = "/dev/ttyS9";
    c.baud = 12345;
    const auto errors = SerialConfig::validate(c);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].find("12345"), std::string::npos) << errors[0];
    EXPECT_NE(errors[0].find("/dev/ttyS9"), std::string::npos) << errors[0];
    EXPECT_NE(errors[0].find("921600"), std::string::npos)
        << "should list the supported rates: " << errors[0];
}

TEST(HalSerialConfigTest, AcceptsEveryStandardBaud) {
    for (unsigned baud : {9600u, 19200u, 38400u, 57600u, 115200u, 230400u, 460800u, 500000u, 921600u}) {
        SerialConfig c;
        c.path = "/dev/ttyS0";
        c.baud = baud;
        EXPECT_TRUE(SerialConfig::validate(c).empty()) << baud;
    }
}

TEST(HalSerialConfigTest, RejectsEmptyPathAndHandDrivenRtsUnderFlowControl) {
    SerialConfig c;
    c.rtscts = true;
    c.rts_on_open = true;
    EXPECT_EQ(SerialConfig::validate(c).size(), 2u);
}

TEST_F(HalSerialPortTest, InvalidBaudIsRejectedWithMessage) {
    SerialPort port(io_.get_executor());
    auto c = config_for(pty_);
    c.baud = 14400;
    const auto result = port.open(c);
    EXPECT_EQ(result.error, make_error_code(HalError::InvalidConfig));
    EXPECT_NE(result.message.find("14400"), std::string::npos) << result.message;
    EXPECT_FALSE(port.is_open());
}

TEST_F(HalSerialPortTest, NonexistentPathErrorNamesThePath) {
    SerialPort port(io_.get_executor());
    SerialConfig c;
    c.path = "/nonexistent/ttyAIRSEG0";
    const auto result = port.open(c);
    EXPECT_EQ(result.error, std::error_code(ENOENT, std::system_category()));
    EXPECT_NE(result.message.find("/nonexistent/ttyAIRSEG0"), std::string::npos) << result.message;
    EXPECT_FALSE(port.is_open());
}

// A second opener would steal part of the bytes; the port takes the line for itself (TIOCEXCL). Root ignores
// exclusive mode, so under root the second open is tried as the unprivileged user `nobody`.
TEST_F(HalSerialPortTest, SecondOpenOfTheLineIsRefusedWhileThePortHoldsIt) {
    SerialPort port(io_.get_executor());
    ASSERT_TRUE(port.open(config_for(pty_)).ok());
    const std::string path = pty_.slave_path();
    int second_open_errno = 0;
    if (::geteuid() != 0) {
        const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
        second_open_errno = fd < 0 ? errno : 0;
        if (fd >= 0) {
            ::close(fd);
        }
    } else {
        ASSERT_EQ(::chmod(path.c_str(), 0666), 0);
        const pid_t child = ::fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            if (::setgid(65534) != 0 || ::setuid(65534) != 0) {
                ::_exit(100);
            }
            const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
            ::_exit(fd < 0 ? (errno & 0x7f) : 0);
        }
        int status = 0;
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        ASSERT_TRUE(WIFEXITED(status));
        ASSERT_NE(WEXITSTATUS(status), 100) << "cannot become nobody";
        second_open_errno = WEXITSTATUS(status);
    }
    EXPECT_EQ(second_open_errno, EBUSY) << std::strerror(second_open_errno);
}

TEST_F(HalSerialPortTest, RegularFileIsNotATerminal) {
    char name[] = "/tmp/airseg-hal-notatty-XXXXXX";
    const int fd = ::mkstemp(name);
    ASSERT_GE(fd, 0);
    ::close(fd);
    SerialPort port(io_.get_executor());
    SerialConfig c;
    c.path = name;
    const auto result = port.open(c);
    ::unlink(name);
    EXPECT_EQ(result.error, make_error_code(HalError::NotATerminal)) << result.message;
    EXPECT_NE(result.message.find(name), std::string::npos) << result.message;
}

class HalSerialPortBaudTest : public HalSerialPortTest, public ::testing::WithParamInterface<unsigned> {};

TEST_P(HalSerialPortBaudTest, BytesFlowBothWays) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_, GetParam()));

    const auto down = pattern_bytes(300, 1);
    ASSERT_TRUE(test::write_all(pty_.master(), down));
    ASSERT_TRUE(run_until(io_, [&] { return received_.bytes.size() >= down.size(); }));
    EXPECT_EQ(received_.bytes, down);

    const auto up = pattern_bytes(500, 2);
    EXPECT_EQ(port.write(up), WriteResult::Queued);
    std::vector<std::uint8_t> at_master;
    ASSERT_TRUE(run_until(io_, [&] {
        drain(pty_.master(), at_master);
        return at_master.size() >= up.size();
    }));
    EXPECT_EQ(at_master, up);
    EXPECT_TRUE(received_.errors.empty());
}

INSTANTIATE_TEST_SUITE_P(HalStandardRates, HalSerialPortBaudTest, ::testing::Values(57600u, 115200u));

// What a reader judging the peer's silence asks first: how much the kernel holds that it has not read.
TEST_F(HalSerialPortTest, BytesWaitingCountsWhatTheKernelHoldsUnread) {
    SerialPort port(io_.get_executor());
    EXPECT_EQ(port.bytes_waiting(), 0u) << "closed";
    auto result = port.open(config_for(pty_));
    ASSERT_TRUE(result.ok()) << result.message;
    EXPECT_EQ(port.bytes_waiting(), 0u);
    const auto down = pattern_bytes(300, 3);
    ASSERT_TRUE(test::write_all(pty_.master(), down));
    // The pty hands written bytes to the slave's line discipline asynchronously.
    ASSERT_TRUE(run_until(io_, [&] { return port.bytes_waiting() == down.size(); })) << port.bytes_waiting();

    port.start_reading(
        [this](std::span<const std::uint8_t> b) {
            received_.bytes.insert(received_.bytes.end(), b.begin(), b.end());
        },
        [this](std::error_code ec, const std::string& what) { received_.errors.emplace_back(ec, what); });
    ASSERT_TRUE(run_until(io_, [&] { return received_.bytes.size() >= down.size(); }));
    EXPECT_EQ(received_.bytes, down);
    EXPECT_EQ(port.bytes_waiting(), 0u) << "read out";
    port.close();
    EXPECT_EQ(port.bytes_waiting(), 0u);
}

TEST_F(HalSerialPortTest, LargeWritesArriveInOrder) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));

    // Far more than a pty buffers, so most writes wait in the queue while the test drains the master.
    std::vector<std::uint8_t> expected;
    for (std::uint32_t i = 0; i < 64; ++i) {
        auto chunk = pattern_bytes(4096 + i, i);
        expected.insert(expected.end(), chunk.begin(), chunk.end());
        ASSERT_EQ(port.write(std::move(chunk)), WriteResult::Queued);
    }
    EXPECT_GT(port.queued_bytes(), 0u);
    std::vector<std::uint8_t> at_master;
    ASSERT_TRUE(run_until(io_,
                          [&] {
                              drain(pty_.master(), at_master);
                              return at_master.size() >= expected.size() && port.queued_bytes() == 0;
                          }))
        << "received " << at_master.size() << " of " << expected.size();
    EXPECT_EQ(at_master, expected);
}

TEST_F(HalSerialPortTest, FramesQueuedInOneTurnLeaveTogetherInOneWrite) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));
    const auto mode = pattern_bytes(41, 1);
    const auto slot = pattern_bytes(14, 2);
    const auto third = pattern_bytes(30, 3);
    ASSERT_EQ(port.write(mode), WriteResult::Queued);
    ASSERT_EQ(port.write(slot), WriteResult::Queued);
    ASSERT_EQ(port.write(third), WriteResult::Queued);
    std::vector<std::uint8_t> at_master;
    drain(pty_.master(), at_master);
    EXPECT_TRUE(at_master.empty()) << "written before the turn ended";
    // One handler: the deferred write. Written one after another, the second frame would wait for the
    // first one's completion handler and the third for the second's.
    ASSERT_EQ(io_.poll_one(), 1u);
    drain(pty_.master(), at_master);
    std::vector<std::uint8_t> expected = mode;
    expected.insert(expected.end(), slot.begin(), slot.end());
    expected.insert(expected.end(), third.begin(), third.end());
    EXPECT_EQ(at_master, expected);
}

TEST_F(HalSerialPortTest, WriteQueueIsBounded) {
    SerialPort port(io_.get_executor());
    auto c = config_for(pty_);
    c.max_queued_bytes = 1000;
    open_and_read(port, c);
    EXPECT_EQ(port.write(std::vector<std::uint8_t>(800, 0x55)), WriteResult::Queued);
    EXPECT_EQ(port.write(std::vector<std::uint8_t>(300, 0x55)), WriteResult::QueueFull);
    EXPECT_EQ(port.queued_bytes(), 800u);
    ASSERT_TRUE(run_until(io_, [&] { return port.queued_bytes() == 0; }));
    EXPECT_EQ(port.write(std::vector<std::uint8_t>(300, 0x55)), WriteResult::Queued);
}

TEST_F(HalSerialPortTest, WriteOnClosedPortIsRefused) {
    SerialPort port(io_.get_executor());
    EXPECT_EQ(port.write({1, 2, 3}), WriteResult::NotOpen);
}

TEST_F(HalSerialPortTest, ModemLinesOnPtyWarnButOpen) {
    SerialPort port(io_.get_executor());
    auto c = config_for(pty_);
    c.dtr_on_open = true;
    c.low_latency = true;
    const auto result = port.open(c);
    ASSERT_TRUE(result.ok()) << result.message;
    ASSERT_EQ(result.warnings.size(), 2u);
    EXPECT_NE(result.warnings[0].find("DTR"), std::string::npos) << result.warnings[0];
    EXPECT_NE(result.warnings[1].find("low-latency"), std::string::npos) << result.warnings[1];
    EXPECT_TRUE(port.set_dtr(false)) << "a pty has no modem lines";
    EXPECT_TRUE(port.is_open());
}

TEST_F(HalSerialPortTest, PeerCloseIsReportedOnceAsUnplugged) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));
    pty_.close_master();
    ASSERT_TRUE(run_until(io_, [&] { return !received_.errors.empty(); }));
    run_until_idle(io_);
    ASSERT_EQ(received_.errors.size(), 1u);
    EXPECT_EQ(received_.errors[0].first, make_error_code(HalError::Unplugged));
    EXPECT_NE(received_.errors[0].second.find(pty_.slave_path()), std::string::npos)
        << received_.errors[0].second;
    EXPECT_FALSE(port.is_open());
}

TEST_F(HalSerialPortTest, UnplugWithWritesPendingIsStillReportedOnce) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));
    for (int i = 0; i < 16; ++i) {
        ASSERT_EQ(port.write(pattern_bytes(16384, static_cast<std::uint32_t>(i))), WriteResult::Queued);
    }
    ASSERT_GT(port.queued_bytes(), 0u) << "256 KiB cannot all fit in a pty buffer";
    pty_.close_master();
    ASSERT_TRUE(run_until(io_, [&] { return !received_.errors.empty(); }));
    run_until_idle(io_);
    ASSERT_EQ(received_.errors.size(), 1u);
    EXPECT_EQ(received_.errors[0].first, make_error_code(HalError::Unplugged));
    EXPECT_EQ(port.queued_bytes(), 0u);
}

TEST_F(HalSerialPortTest, ReopenAfterUnplugWorks) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));
    pty_.close_master();
    ASSERT_TRUE(run_until(io_, [&] { return !received_.errors.empty(); }));

    TestPty replugged;
    ASSERT_TRUE(replugged.ok());
    open_and_read(port, config_for(replugged));
    const auto down = pattern_bytes(100, 7);
    ASSERT_TRUE(test::write_all(replugged.master(), down));
    ASSERT_TRUE(run_until(io_, [&] { return received_.bytes.size() >= down.size(); }));
    EXPECT_EQ(received_.bytes, down);
    EXPECT_EQ(port.write({0xFE, 0x01}), WriteResult::Queued);
    std::vector<std::uint8_t> at_master;
    ASSERT_TRUE(run_until(io_, [&] {
        drain(replugged.master(), at_master);
        return at_master.size() >= 2;
    }));
    EXPECT_EQ(at_master, (std::vector<std::uint8_t>{0xFE, 0x01}));
    EXPECT_EQ(received_.errors.size(), 1u);
}

TEST_F(HalSerialPortTest, CloseIsNotAnErrorEvent) {
    SerialPort port(io_.get_executor());
    open_and_read(port, config_for(pty_));
    EXPECT_EQ(port.write(pattern_bytes(100000, 3)), WriteResult::Queued);
    port.close();
    run_until_idle(io_);
    EXPECT_TRUE(received_.errors.empty());
    EXPECT_FALSE(port.is_open());
    EXPECT_EQ(port.queued_bytes(), 0u);
}

TEST_F(HalSerialPortTest, DestroyingThePortWithOperationsPendingIsSafe) {
    {
        SerialPort port(io_.get_executor());
        open_and_read(port, config_for(pty_));
        EXPECT_EQ(port.write(pattern_bytes(100000, 4)), WriteResult::Queued);
    }
    run_until_idle(io_);
    EXPECT_TRUE(received_.errors.empty());
}

}  // namespace
}  // namespace airseg::hal

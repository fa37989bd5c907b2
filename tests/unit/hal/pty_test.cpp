#include "hal/pty.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>

#include "hal/serial_port.hpp"
#include "tests/unit/hal/run_until.hpp"

namespace airseg::hal {
namespace {

using test::drain;
using test::pattern_bytes;
using test::run_until;
using test::run_until_idle;

class TempDir {
  public:
    TempDir() {
        char name[] = "/tmp/airseg-hal-pty-XXXXXX";
        if (::mkdtemp(name) != nullptr) {
            path_ = name;
        }
    }
    ~TempDir() {
        if (!path_.empty()) {
            // Only files this test created live here; remove them one by one, then the directory.
            for (const char* leaf : {"/ttyTEST", "/ttyTEST.new"}) {
                ::unlink((path_ + leaf).c_str());
            }
            ::rmdir(path_.c_str());
        }
    }
    const std::string& path() const { return path_; }

  private:
    std::string path_;
};

class PeerFd {
  public:
    explicit PeerFd(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK)) {}
    ~PeerFd() { close(); }
    PeerFd(const PeerFd&) = delete;
    PeerFd& operator=(const PeerFd&) = delete;
    int get() const { return fd_; }
    void close() {
        if (fd_ >= 0) {
            ::close(fd_);
            fd_ = -1;
        }
    }

  private:
    int fd_;
};

class HalPtyTest : public ::testing::Test {
  protected:
    void SetUp() override {
        ASSERT_FALSE(dir_.path().empty());
        pty_.on_peer_open([this] { ++opens_; });
        pty_.on_peer_close([this] { ++closes_; });
    }

    std::string link() const { return dir_.path() + "/ttyTEST"; }

    void open_pty() {
        const auto result = pty_.open();
        ASSERT_TRUE(result.ok()) << result.message;
    }

    boost::asio::io_context io_;
    TempDir dir_;
    Pty pty_{io_.get_executor(), PtyConfig{dir_.path() + "/ttyTEST", milliseconds(5)}};
    int opens_ = 0;
    int closes_ = 0;
    std::vector<std::uint8_t> received_;
};

std::string read_link(const std::string& path) {
    char buf[256] = {};
    const ssize_t n = ::readlink(path.c_str(), buf, sizeof buf - 1);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

TEST(HalPtyConfigTest, RejectsEmptyPathAndZeroPeriod) {
    PtyConfig c;
    c.peer_check_period = Duration::zero();
    EXPECT_EQ(PtyConfig::validate(c).size(), 2u);
}

TEST_F(HalPtyTest, PublishesSlaveAtTheLinkPath) {
    open_pty();
    EXPECT_EQ(read_link(link()), pty_.slave_path());
    EXPECT_EQ(pty_.slave_path().rfind("/dev/pts/", 0), 0u) << pty_.slave_path();
    EXPECT_FALSE(pty_.peer_connected());
}

class HalPtyPeerTest : public HalPtyTest, public ::testing::WithParamInterface<bool> {};

// With reading on, a peer close surfaces as EIO on the master; with it off, only the periodic poll sees it.
TEST_P(HalPtyPeerTest, DetectsPeerOpenAndClose) {
    const bool reading = GetParam();
    open_pty();
    if (reading) {
        pty_.start_reading([](std::span<const std::uint8_t>) {});
    }
    for (int round = 1; round <= 2; ++round) {
        PeerFd peer(link());
        ASSERT_GE(peer.get(), 0);
        ASSERT_TRUE(run_until(io_, [&] { return opens_ == round; })) << "round " << round;
        EXPECT_TRUE(pty_.peer_connected());
        peer.close();
        ASSERT_TRUE(run_until(io_, [&] { return closes_ == round; })) << "round " << round;
        EXPECT_FALSE(pty_.peer_connected());
    }
    EXPECT_EQ(opens_, 2);
    EXPECT_EQ(closes_, 2);
}

INSTANTIATE_TEST_SUITE_P(HalReadingOnOff, HalPtyPeerTest, ::testing::Bool());

TEST_F(HalPtyTest, DataFlowsBothWays) {
    open_pty();
    pty_.start_reading(
        [this](std::span<const std::uint8_t> b) { received_.insert(received_.end(), b.begin(), b.end()); });
    PeerFd peer(link());
    ASSERT_GE(peer.get(), 0);
    ASSERT_TRUE(run_until(io_, [&] { return pty_.peer_connected(); }));

    const auto up = pattern_bytes(10000, 11);
    ASSERT_TRUE(test::write_all(peer.get(), up));
    ASSERT_TRUE(run_until(io_, [&] { return received_.size() >= up.size(); }));
    EXPECT_EQ(received_, up);

    const auto down = pattern_bytes(3000, 12);
    ASSERT_EQ(pty_.write(down), WriteResult::Queued);
    std::vector<std::uint8_t> at_peer;
    ASSERT_TRUE(run_until(io_, [&] {
        drain(peer.get(), at_peer);
        return at_peer.size() >= down.size();
    }));
    EXPECT_EQ(at_peer, down);
}

TEST_F(HalPtyTest, WritesWithoutPeerAreDropped) {
    EXPECT_EQ(pty_.write({1}), WriteResult::NotOpen);
    open_pty();
    EXPECT_EQ(pty_.write({1, 2, 3}), WriteResult::NoPeer);
    EXPECT_EQ(pty_.queued_bytes(), 0u);
}

TEST_F(HalPtyTest, UnplugMakesThePeerFailAndRemovesTheLink) {
    open_pty();
    PeerFd peer(link());
    ASSERT_GE(peer.get(), 0);
    ASSERT_TRUE(run_until(io_, [&] { return pty_.peer_connected(); }));

    pty_.unplug();
    EXPECT_FALSE(pty_.is_open());
    EXPECT_FALSE(pty_.peer_connected());
    struct stat st {};
    EXPECT_NE(::lstat(link().c_str(), &st), 0) << "symlink should be gone";

    std::uint8_t byte = 0;
    const ssize_t r = ::read(peer.get(), &byte, 1);
    EXPECT_TRUE(r == 0 || (r < 0 && errno == EIO)) << "read returned " << r << " errno " << errno;
    const ssize_t w = ::write(peer.get(), &byte, 1);
    EXPECT_LT(w, 0);
    EXPECT_EQ(errno, EIO);
}

TEST_F(HalPtyTest, ReplugServesTheSamePathAgain) {
    open_pty();
    pty_.start_reading(
        [this](std::span<const std::uint8_t> b) { received_.insert(received_.end(), b.begin(), b.end()); });
    pty_.unplug();
    const auto result = pty_.replug();
    ASSERT_TRUE(result.ok()) << result.message;
    EXPECT_EQ(read_link(link()), pty_.slave_path());

    PeerFd peer(link());
    ASSERT_GE(peer.get(), 0);
    ASSERT_TRUE(run_until(io_, [&] { return opens_ == 1; }));
    ASSERT_TRUE(test::write_all(peer.get(), {0xAA, 0x55}));
    ASSERT_TRUE(run_until(io_, [&] { return received_.size() >= 2; }));
    EXPECT_EQ(received_, (std::vector<std::uint8_t>{0xAA, 0x55}));
}

TEST_F(HalPtyTest, ReplacesAStaleSymlink) {
    ASSERT_EQ(::symlink("/dev/pts/does-not-exist", link().c_str()), 0);
    open_pty();
    EXPECT_EQ(read_link(link()), pty_.slave_path());
}

TEST_F(HalPtyTest, RefusesToReplaceARegularFile) {
    { std::ofstream(link()) << "precious"; }
    const auto result = pty_.open();
    EXPECT_EQ(result.error, make_error_code(HalError::PathOccupied));
    EXPECT_NE(result.message.find(link()), std::string::npos) << result.message;
    std::ifstream in(link());
    std::string content;
    in >> content;
    EXPECT_EQ(content, "precious");
}

TEST_F(HalPtyTest, DestructionRemovesTheLink) {
    {
        Pty scoped(io_.get_executor(), PtyConfig{link()});
        ASSERT_TRUE(scoped.open().ok());
        EXPECT_FALSE(read_link(link()).empty());
    }
    run_until_idle(io_);
    struct stat st {};
    EXPECT_NE(::lstat(link().c_str(), &st), 0);
}

// The way the simulators use it: airsegd's SerialPort opens the link, the simulator pulls the cable.
TEST_F(HalPtyTest, SerialPortAsPeerSeesOneUnplugAndCanReopenAfterReplug) {
    open_pty();
    pty_.start_reading(
        [this](std::span<const std::uint8_t> b) { received_.insert(received_.end(), b.begin(), b.end()); });
    SerialPort port(io_.get_executor());
    std::vector<std::uint8_t> at_port;
    std::vector<std::error_code> errors;
    auto open_port = [&] {
        SerialConfig c;
        c.path = link();
        c.baud = 115200;
        const auto r = port.open(c);
        ASSERT_TRUE(r.ok()) << r.message;
        port.start_reading(
            [&](std::span<const std::uint8_t> b) { at_port.insert(at_port.end(), b.begin(), b.end()); },
            [&](std::error_code ec, const std::string&) { errors.push_back(ec); });
    };
    open_port();
    ASSERT_TRUE(run_until(io_, [&] { return opens_ == 1; }));
    ASSERT_EQ(pty_.write({1, 2, 3}), WriteResult::Queued);
    ASSERT_EQ(port.write({4, 5}), WriteResult::Queued);
    ASSERT_TRUE(run_until(io_, [&] { return at_port.size() == 3 && received_.size() == 2; }));

    pty_.unplug();
    ASSERT_TRUE(run_until(io_, [&] { return !errors.empty(); }));
    run_until_idle(io_);  // both sides are closed now, so this returns once every pending handler has run
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors[0], make_error_code(HalError::Unplugged));

    ASSERT_TRUE(pty_.replug().ok());
    open_port();
    ASSERT_TRUE(run_until(io_, [&] { return opens_ == 2; }));
    ASSERT_EQ(port.write({6}), WriteResult::Queued);
    ASSERT_TRUE(run_until(io_, [&] { return received_.size() == 3; }));
    EXPECT_EQ(received_, (std::vector<std::uint8_t>{4, 5, 6}));
    port.close();
    ASSERT_TRUE(run_until(io_, [&] { return closes_ == 1; }));
}

}  // namespace
}  // namespace airseg::hal

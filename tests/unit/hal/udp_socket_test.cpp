#include "hal/udp_socket.hpp"

#include <gtest/gtest.h>

#include "tests/unit/hal/run_until.hpp"

namespace airseg::hal {
namespace {

using test::pattern_bytes;
using test::run_until;

struct Inbox {
    std::vector<std::vector<std::uint8_t>> datagrams;
    std::vector<UdpSocket::Endpoint> senders;
    std::vector<std::string> errors;

    void attach(UdpSocket& socket) {
        socket.start_receiving(
            [this](std::span<const std::uint8_t> d, const UdpSocket::Endpoint& from) {
                datagrams.emplace_back(d.begin(), d.end());
                senders.push_back(from);
            },
            [this](std::error_code, const std::string& what) { errors.push_back(what); });
    }
};

UdpConfig loopback(std::uint16_t remote_port = 0) {
    UdpConfig c;
    c.bind_address = "127.0.0.1";
    if (remote_port != 0) {
        c.remote_address = "127.0.0.1";
        c.remote_port = remote_port;
    }
    return c;
}

class HalUdpSocketTest : public ::testing::Test {
  protected:
    void SetUp() override {
        ASSERT_TRUE(ground_.open(loopback()).ok());
        const auto r = air_.open(loopback(ground_.local_endpoint().port()));
        ASSERT_TRUE(r.ok()) << r.message;
        ground_inbox_.attach(ground_);
        air_inbox_.attach(air_);
    }

    boost::asio::io_context io_;
    UdpSocket ground_{io_.get_executor()};
    UdpSocket air_{io_.get_executor()};
    Inbox ground_inbox_;
    Inbox air_inbox_;
};

TEST(HalUdpConfigTest, NamesBadAddressesAndMissingPorts) {
    UdpConfig c;
    c.bind_address = "not-an-ip";
    c.remote_address = "10.0.0.300";
    const auto errors = UdpConfig::validate(c);
    ASSERT_EQ(errors.size(), 3u);
    EXPECT_NE(errors[0].find("not-an-ip"), std::string::npos);
    EXPECT_NE(errors[1].find("10.0.0.300"), std::string::npos);
    EXPECT_NE(errors[2].find("remote_port"), std::string::npos);
}

TEST_F(HalUdpSocketTest, DatagramsFlowAndTheReplyGoesToTheLastSender) {
    EXPECT_FALSE(ground_.remote().has_value());
    EXPECT_EQ(ground_.send({1}), WriteResult::NoPeer);

    const auto hello = pattern_bytes(UdpSocket::kMaxDatagram, 5);
    ASSERT_EQ(air_.send(hello), WriteResult::Queued);
    ASSERT_TRUE(run_until(io_, [&] { return !ground_inbox_.datagrams.empty(); }));
    EXPECT_EQ(ground_inbox_.datagrams[0], hello)
        << "a datagram of exactly the maximum size is delivered whole";
    EXPECT_EQ(ground_inbox_.senders[0], air_.local_endpoint());
    ASSERT_TRUE(ground_.remote().has_value());

    ASSERT_EQ(ground_.send({9, 8, 7}), WriteResult::Queued);
    ASSERT_TRUE(run_until(io_, [&] { return !air_inbox_.datagrams.empty(); }));
    EXPECT_EQ(air_inbox_.datagrams[0], (std::vector<std::uint8_t>{9, 8, 7}));
}

// A burst sent from one handler, as the autopilot service forwards a whole read of frames to a ground
// station: far more datagrams than kMaxSendsInFlight, every one delivered, in order, while the kernel has
// room.
TEST_F(HalUdpSocketTest, ABurstFromOneHandlerIsSentWholeInOrder) {
    // Three times the bound, and within what the receiver's default buffer holds of such small datagrams (256).
    constexpr std::size_t kBurst = 3 * UdpSocket::kMaxSendsInFlight;
    std::size_t queued = 0;
    for (std::size_t i = 0; i < kBurst; ++i) {
        const std::vector<std::uint8_t> d{static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8), 1,
                                          2};
        queued += air_.send(d) == WriteResult::Queued ? 1 : 0;
    }
    EXPECT_EQ(queued, kBurst);
    ASSERT_TRUE(run_until(io_, [&] { return ground_inbox_.datagrams.size() == kBurst; }))
        << ground_inbox_.datagrams.size() << " of " << kBurst << " arrived";
    for (std::size_t i = 0; i < kBurst; ++i) {
        ASSERT_EQ(ground_inbox_.datagrams[i][0] | (ground_inbox_.datagrams[i][1] << 8),
                  static_cast<int>(i & 0xffff));
    }
    EXPECT_EQ(air_.send_errors(), 0u);
}

TEST_F(HalUdpSocketTest, OversizeDatagramsAreDroppedWholeAndCounted) {
    EXPECT_EQ(air_.send(std::vector<std::uint8_t>(UdpSocket::kMaxDatagram + 1, 0)), WriteResult::TooLarge);

    // A foreign sender that ignores the limit.
    boost::asio::ip::udp::socket raw(
        io_, boost::asio::ip::udp::endpoint(boost::asio::ip::make_address("127.0.0.1"), 0));
    const std::vector<std::uint8_t> big(3000, 0xAB);
    raw.send_to(boost::asio::buffer(big), ground_.local_endpoint());
    const std::vector<std::uint8_t> small{1, 2};
    raw.send_to(boost::asio::buffer(small), ground_.local_endpoint());

    ASSERT_TRUE(run_until(io_, [&] { return !ground_inbox_.datagrams.empty(); }));
    EXPECT_EQ(ground_.oversize_dropped(), 1u);
    ASSERT_EQ(ground_inbox_.datagrams.size(), 1u);
    EXPECT_EQ(ground_inbox_.datagrams[0], small);
}

TEST_F(HalUdpSocketTest, BindingAPortInUseFailsWithTheAddressNamed) {
    UdpSocket other(io_.get_executor());
    UdpConfig c = loopback();
    c.bind_port = ground_.local_endpoint().port();
    const auto r = other.open(c);
    EXPECT_EQ(r.error, std::errc::address_in_use);
    EXPECT_NE(r.message.find("127.0.0.1:" + std::to_string(c.bind_port)), std::string::npos) << r.message;
}

TEST_F(HalUdpSocketTest, ClosedSocketRefusesToSendAndReportsNothing) {
    air_.close();
    EXPECT_EQ(air_.send({1}), WriteResult::NotOpen);
    test::run_until_idle(io_, std::chrono::milliseconds(50));
    EXPECT_TRUE(air_inbox_.errors.empty());
}

}  // namespace
}  // namespace airseg::hal

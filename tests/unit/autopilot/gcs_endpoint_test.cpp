// GcsEndpoint on real sockets (loopback, ports the kernel picks): ground stations' frames in over UDP and
// TCP, checked and passed on whole; the vehicle's frames out to every UDP peer and TCP client.
#include "services/autopilot/gcs_endpoint.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <memory>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::autopilot {
namespace {

namespace mav = airseg::mavlink;
using asio::ip::tcp;
using asio::ip::udp;

struct Rig {
    Rig() : Rig(GcsEndpointConfig{"127.0.0.1:0", "127.0.0.1:0", ""}) {}
    explicit Rig(GcsEndpointConfig config)
        : strand(asio::make_strand(io)),
          endpoint(strand, std::move(config),
                   [this](std::vector<std::uint8_t> f) { to_vehicle.push_back(f); }) {
        EXPECT_EQ(endpoint.start(), "");
    }
    ~Rig() { endpoint.stop(); }

    /// Runs the loop until `done` or two seconds have passed.
    bool run_until(const std::function<bool()>& done) {
        const auto limit = std::chrono::steady_clock::now() + std::chrono::seconds(2);
        while (!done()) {
            if (std::chrono::steady_clock::now() > limit) {
                return false;
            }
            io.run_for(std::chrono::milliseconds(5));
        }
        return true;
    }

    asio::io_context io;
    asio::strand<asio::io_context::executor_type> strand;
    std::vector<std::vector<std::uint8_t>> to_vehicle;
    GcsEndpoint endpoint;
    mav::Encoder gcs{254, 190};
    mav::Encoder vehicle{1, 1};
};

std::vector<std::uint8_t> concat(std::initializer_list<std::vector<std::uint8_t>> parts) {
    std::vector<std::uint8_t> out;
    for (const auto& p : parts) {
        out.insert(out.end(), p.begin(), p.end());
    }
    return out;
}

TEST(GcsEndpoint, UdpPeersSendValidFramesAndGetTheVehiclesFrames) {
    Rig rig;
    ASSERT_NE(rig.endpoint.udp_port(), 0);
    udp::socket a(rig.io, udp::endpoint(udp::v4(), 0)), b(rig.io, udp::endpoint(udp::v4(), 0));
    const udp::endpoint to(asio::ip::make_address("127.0.0.1"), rig.endpoint.udp_port());

    mav::Heartbeat hb;
    const auto good = rig.gcs.encode(hb);
    auto damaged = rig.gcs.encode(hb);
    damaged.back() ^= 0x5a;
    // One datagram: a damaged frame, noise, a good one: only the good one goes on.
    a.send_to(asio::buffer(concat({damaged, {1, 2, 3}, good})), to);
    b.send_to(asio::buffer(good), to);
    ASSERT_TRUE(rig.run_until([&] { return rig.to_vehicle.size() == 2; }));
    EXPECT_EQ(rig.to_vehicle[0], good);
    EXPECT_EQ(rig.to_vehicle[1], good);
    EXPECT_EQ(rig.endpoint.stats().frames_in, 2u);
    EXPECT_GE(rig.endpoint.stats().invalid_in, 1u);
    EXPECT_EQ(rig.endpoint.stats().udp_peers, 2u);

    mav::Attitude att;
    const auto out = rig.vehicle.encode(att);
    rig.endpoint.from_vehicle(out);
    for (auto* s : {&a, &b}) {
        std::array<std::uint8_t, 512> buf{};
        std::size_t n = 0;
        s->async_receive(asio::buffer(buf), [&](boost::system::error_code ec, std::size_t got) {
            ASSERT_FALSE(ec);
            n = got;
        });
        ASSERT_TRUE(rig.run_until([&] { return n > 0; }));
        EXPECT_EQ(std::vector<std::uint8_t>(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), out);
    }
}

TEST(GcsEndpoint, TcpClientsSendFramesInPiecesAndEachGetsTheVehiclesFrames) {
    Rig rig;
    ASSERT_NE(rig.endpoint.tcp_port(), 0);
    const tcp::endpoint at(asio::ip::make_address("127.0.0.1"), rig.endpoint.tcp_port());
    tcp::socket a(rig.io), b(rig.io);
    a.connect(at);
    b.connect(at);
    ASSERT_TRUE(rig.run_until([&] { return rig.endpoint.stats().tcp_clients == 2; }));

    mav::ParamRequestList list;
    list.target_system = 1;
    const auto frame = rig.gcs.encode(list);
    // A frame cut across two writes still arrives whole, once.
    asio::write(a, asio::buffer(frame.data(), 3));
    rig.io.run_for(std::chrono::milliseconds(20));
    EXPECT_TRUE(rig.to_vehicle.empty());
    asio::write(a, asio::buffer(frame.data() + 3, frame.size() - 3));
    ASSERT_TRUE(rig.run_until([&] { return rig.to_vehicle.size() == 1; }));
    EXPECT_EQ(rig.to_vehicle[0], frame);

    mav::Statustext text;
    mav::set_text(text.text, "hello");
    const auto out = rig.vehicle.encode(text);
    rig.endpoint.from_vehicle(out);
    for (auto* s : {&a, &b}) {
        std::vector<std::uint8_t> got(out.size());
        bool done = false;
        asio::async_read(*s, asio::buffer(got), [&](boost::system::error_code ec, std::size_t) {
            ASSERT_FALSE(ec);
            done = true;
        });
        ASSERT_TRUE(rig.run_until([&] { return done; }));
        EXPECT_EQ(got, out);
    }
    // A client that leaves is forgotten; the other keeps getting frames.
    a.close();
    ASSERT_TRUE(rig.run_until([&] { return rig.endpoint.stats().tcp_clients == 1; }));
}

TEST(GcsEndpoint, UdpPeersPastTheBoundMakeTheStalestBeForgotten) {
    Rig rig;
    const udp::endpoint to(asio::ip::make_address("127.0.0.1"), rig.endpoint.udp_port());
    const auto good = rig.gcs.encode(mav::Heartbeat{});
    std::vector<std::unique_ptr<udp::socket>> peers;
    for (std::size_t i = 0; i < GcsEndpoint::kMaxUdpPeers + 4; ++i) {
        peers.push_back(std::make_unique<udp::socket>(rig.io, udp::endpoint(udp::v4(), 0)));
        peers.back()->send_to(asio::buffer(good), to);
        // One at a time, so "least recently heard" is the order they were sent in.
        ASSERT_TRUE(rig.run_until([&] { return rig.to_vehicle.size() == i + 1; }));
    }
    EXPECT_EQ(rig.endpoint.stats().udp_peers, GcsEndpoint::kMaxUdpPeers);
    EXPECT_EQ(rig.endpoint.stats().udp_peers_evicted, 4u);
    EXPECT_EQ(rig.to_vehicle.size(), GcsEndpoint::kMaxUdpPeers + 4) << "every peer's frames still went on";
}

TEST(GcsEndpoint, TcpClientsPastTheBoundAreClosedAtOnce) {
    Rig rig;
    const tcp::endpoint at(asio::ip::make_address("127.0.0.1"), rig.endpoint.tcp_port());
    std::vector<std::unique_ptr<tcp::socket>> clients;
    for (std::size_t i = 0; i < GcsEndpoint::kMaxTcpClients; ++i) {
        clients.push_back(std::make_unique<tcp::socket>(rig.io));
        clients.back()->connect(at);
    }
    ASSERT_TRUE(
        rig.run_until([&] { return rig.endpoint.stats().tcp_clients == GcsEndpoint::kMaxTcpClients; }));
    tcp::socket extra(rig.io);
    extra.connect(at);
    std::array<std::uint8_t, 16> buf{};
    boost::system::error_code result;
    bool done = false;
    extra.async_read_some(asio::buffer(buf), [&](boost::system::error_code ec, std::size_t) {
        result = ec;
        done = true;
    });
    ASSERT_TRUE(rig.run_until([&] { return done; }));
    EXPECT_EQ(result, asio::error::eof);
    EXPECT_EQ(rig.endpoint.stats().tcp_refused, 1u);
    EXPECT_EQ(rig.endpoint.stats().tcp_clients, GcsEndpoint::kMaxTcpClients);
}

// A ground station that connects and never reads: once the kernel's buffers are full, the endpoint keeps at
// most kMaxTcpBacklog bytes for it and drops (and counts) the rest, instead of queueing the vehicle's whole
// stream.
TEST(GcsEndpoint, ATcpClientThatNeverReadsCostsAtMostTheBacklogAndItsDropsAreCounted) {
    Rig rig;
    tcp::socket silent(rig.io);
    silent.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), rig.endpoint.tcp_port()));
    silent.set_option(asio::socket_base::receive_buffer_size(4096));
    ASSERT_TRUE(rig.run_until([&] { return rig.endpoint.stats().tcp_clients == 1; }));
    const std::vector<std::uint8_t> frames(1000, 0xfd);  // what the endpoint sends is not parsed here
    constexpr std::size_t kSends = 20'000;               // 20 MB: far past any socket buffer
    for (std::size_t i = 0; i < kSends; ++i) {
        rig.endpoint.from_vehicle(frames);
        rig.io.poll();
    }
    const auto s = rig.endpoint.stats();
    EXPECT_GT(s.dropped_out, 0u);
    EXPECT_EQ(s.bytes_out + s.dropped_out * frames.size(), kSends * frames.size());
    // Taken into the queue: what the socket took plus at most the backlog (the kernel's buffers on loopback
    // hold a few MB at most).
    EXPECT_LT(s.bytes_out, 16u * 1024 * 1024) << s.dropped_out << " dropped";
}

TEST(GcsEndpoint, AFixedUdpDestinationGetsFramesWithoutSendingFirst) {
    asio::io_context listener_io;
    udp::socket listener(listener_io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    Rig rig(GcsEndpointConfig{"127.0.0.1:0", "",
                              "127.0.0.1:" + std::to_string(listener.local_endpoint().port())});
    EXPECT_EQ(rig.endpoint.tcp_port(), 0);
    mav::Heartbeat hb;
    const auto out = rig.vehicle.encode(hb);
    rig.endpoint.from_vehicle(out);
    ASSERT_TRUE(rig.run_until([&] { return listener.available() > 0; }));
    std::array<std::uint8_t, 512> buf{};
    const auto n = listener.receive(asio::buffer(buf));
    EXPECT_EQ(std::vector<std::uint8_t>(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), out);
}

TEST(GcsEndpointConfig, NamesBadAddresses) {
    EXPECT_TRUE((GcsEndpointConfig{}).validate().empty());
    EXPECT_TRUE((GcsEndpointConfig{"", "", ""}).validate().empty());
    EXPECT_EQ((GcsEndpointConfig{"nowhere", "0.0.0.0:70000", ""}).validate().size(), 2u);
    EXPECT_EQ((GcsEndpointConfig{"", "", "127.0.0.1:0"}).validate().size(), 2u);
    asio::io_context io;
    GcsEndpoint bad(asio::make_strand(io), GcsEndpointConfig{"x", "", ""}, {});
    EXPECT_NE(bad.start(), "");
}

}  // namespace
}  // namespace airseg::autopilot

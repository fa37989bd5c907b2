// The hub's endpoint for ground stations on loopback sockets: two stations at once (one on UDP, one on TCP,
// on different component ids) get what is addressed to them and the broadcasts, never each other's answers
// nor airsegd's own.
#include "ground/station_endpoint.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/strand.hpp>
#include <map>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::ground {
namespace {

namespace mav = airseg::mavlink;
using Udp = asio::ip::udp;
using Tcp = asio::ip::tcp;
using namespace std::chrono_literals;

/// What one station received: COMMAND_ACKs by the command they answer, and heartbeats.
struct Received {
    std::map<std::uint16_t, int> acks;  // command -> count
    int heartbeats = 0;
    int params = 0;
    mav::Parser parser;
    void push(std::span<const std::uint8_t> bytes) {
        parser.push(bytes, [&](const mav::Frame& f) {
            if (auto ack = mav::decode<mav::CommandAck>(f)) {
                ++acks[ack->command];
            } else if (f.msgid == mav::Heartbeat::kId) {
                ++heartbeats;
            } else if (f.msgid == mav::ParamValue::kId) {
                ++params;
            }
        });
    }
};

class StationEndpointTest : public ::testing::Test {
  protected:
    StationEndpointTest()
        : strand(asio::make_strand(io)),
          endpoint(strand, config(),
                   [this](StationId station, std::vector<StationFrame> frames) {
                       for (auto& f : frames) {
                           heard.emplace_back(station, f.frame.compid);
                       }
                   }),
          udp_station(io),
          tcp_station(io) {}

    static autopilot::GcsEndpointConfig config() {
        autopilot::GcsEndpointConfig c;
        c.udp = "127.0.0.1:0";
        c.tcp = "127.0.0.1:0";
        return c;
    }

    /// Runs the endpoint until `done` or a generous timeout; reads both stations meanwhile.
    template <class Done>
    bool run_until(Done done) {
        const auto deadline = std::chrono::steady_clock::now() + 10s;
        while (!done()) {
            if (std::chrono::steady_clock::now() > deadline) {
                return false;
            }
            io.run_for(5ms);
            io.restart();
            drain();
        }
        return true;
    }
    void drain() {
        std::array<std::uint8_t, 65536> buf{};
        boost::system::error_code ec;
        while (udp_station.available(ec) > 0) {
            const auto n = udp_station.receive(asio::buffer(buf), 0, ec);
            if (!ec) {
                udp_rx.push(std::span(buf).first(n));
            }
        }
        while (tcp_station.available(ec) > 0) {
            const auto n = tcp_station.read_some(asio::buffer(buf), ec);
            if (!ec) {
                tcp_rx.push(std::span(buf).first(n));
            }
        }
    }

    void SetUp() override {
        ASSERT_EQ(endpoint.start(), "");
        udp_station.open(Udp::v4());
        udp_station.bind(Udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
        tcp_station.connect(Tcp::endpoint(asio::ip::make_address("127.0.0.1"), endpoint.tcp_port()));
        // Each station introduces itself with a heartbeat, as ground stations do once a second.
        mav::Heartbeat hb;
        hb.type = 6;  // MAV_TYPE_GCS
        udp_station.send_to(asio::buffer(qgc.encode(hb)),
                            Udp::endpoint(asio::ip::make_address("127.0.0.1"), endpoint.udp_port()));
        asio::write(tcp_station, asio::buffer(second.encode(hb)));
        ASSERT_TRUE(run_until([&] { return heard.size() == 2; }));
    }

    VehicleFrame ack(std::uint16_t command, std::uint8_t system, std::uint8_t component) {
        mav::CommandAck a;
        a.command = command;
        a.target_system = system;
        a.target_component = component;
        return VehicleFrame{FrameTarget{system, component}, autopilot.encode(a)};
    }

    asio::io_context io;
    asio::any_io_executor strand;
    std::vector<std::pair<StationId, std::uint8_t>> heard;
    StationEndpoint endpoint;
    Udp::socket udp_station;
    Tcp::socket tcp_station;
    mav::Encoder qgc{255, 190};
    mav::Encoder second{255, 200};
    mav::Encoder autopilot{1, 1};
    Received udp_rx;
    Received tcp_rx;
};

TEST_F(StationEndpointTest, EachStationGetsWhatIsAddressedToItAndTheBroadcasts) {
    std::vector<VehicleFrame> frames;
    for (int i = 0; i < 50; ++i) {
        frames.push_back(ack(400, 255, 190));  // to QGroundControl on UDP
        frames.push_back(ack(176, 255, 200));  // to the station on TCP
        frames.push_back(ack(511, 255, 191));  // to airsegd itself
        frames.push_back(ack(520, 7, 1));      // to a system no station is
    }
    mav::Heartbeat hb;
    frames.push_back(VehicleFrame{std::nullopt, autopilot.encode(hb)});
    endpoint.from_vehicle(frames);
    ASSERT_TRUE(run_until([&] { return udp_rx.heartbeats == 1 && tcp_rx.heartbeats == 1; }));
    // Anything still on its way would have come before the heartbeat behind it (one datagram stream, one
    // TCP stream, in order).
    EXPECT_EQ(udp_rx.acks, (std::map<std::uint16_t, int>{{400, 50}}));
    EXPECT_EQ(tcp_rx.acks, (std::map<std::uint16_t, int>{{176, 50}}));
    const auto stats = endpoint.stats();
    EXPECT_EQ(stats.routing.to_airsegd, 50u);
    EXPECT_EQ(stats.routing.unrouted, 50u);
    EXPECT_EQ(stats.routing.routed, 100u);
    EXPECT_EQ(stats.routing.broadcast, 1u);
}

TEST_F(StationEndpointTest, AnAnswerOfTheHubGoesToTheOneStationInWholeDatagrams) {
    const StationId udp_id = heard[0].second == 190 ? heard[0].first : heard[1].first;
    std::vector<std::uint8_t> list;
    for (std::uint16_t i = 0; i < 280; ++i) {
        mav::ParamValue v;
        v.param_count = 280;
        v.param_index = i;
        mav::set_text(v.param_id, "PARAM_" + std::to_string(i));
        const auto f = autopilot.encode(v);
        list.insert(list.end(), f.begin(), f.end());
    }
    endpoint.to_station(udp_id, list);
    mav::Heartbeat hb;
    endpoint.from_vehicle({VehicleFrame{std::nullopt, autopilot.encode(hb)}});
    ASSERT_TRUE(run_until([&] { return udp_rx.params == 280 && tcp_rx.heartbeats == 1; }));
    EXPECT_EQ(tcp_rx.params, 0);
    EXPECT_EQ(udp_rx.parser.stats().bad_checksum + udp_rx.parser.stats().truncated, 0u);
}

}  // namespace
}  // namespace airseg::ground

// A standard ground station on airseg-ground's MAVLink UDP endpoint, played here with the project's codec:
// its COMMAND_INT, TIMESYNC and MAVFTP cross the hub, the simulated 57600-baud radio and airsegd's gate to
// airseg-apmsim on its pty, and the answers come back the same way. The gate keeps MAVFTP writes of the
// mission out and answers them itself.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <deque>
#include <functional>
#include <iostream>
#include <limits>
#include <limits>
#include <optional>

#include "services/autopilot/mavftp.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/support/ground_chain.hpp"
#include "tests/support/ports.hpp"
#include "tests/support/process.hpp"
#include "tools/apmsim/param_pack.hpp"
#include "tools/apmsim/param_table.hpp"
#include "tools/apmsim/vehicle_model.hpp"

namespace airseg::test {
namespace {

namespace mav = airseg::mavlink;
namespace ftp = airseg::autopilot::mavftp;
using Clock = std::chrono::steady_clock;
constexpr auto kGenerous = 60s;

/// A ground station on UDP: it listens where the hub sends the vehicle's frames and answers to the address
/// they came from, as QGroundControl does on 14550.
class UdpStation {
  public:
    explicit UdpStation(int port) {
        fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_in at{};
        at.sin_family = AF_INET;
        at.sin_port = htons(static_cast<std::uint16_t>(port));
        at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&at), sizeof at) == 0;
    }
    ~UdpStation() { ::close(fd_); }
    UdpStation(const UdpStation&) = delete;
    UdpStation& operator=(const UdpStation&) = delete;
    bool bound() const { return bound_; }
    bool has_peer() const { return have_peer_; }

    template <mav::Message M>
    void send(const M& m) {
        const auto bytes = encoder_.encode(m);
        ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_);
    }

    /// The next frame of M matching `pred` within `timeout` (frames before it are passed over).
    template <mav::Message M>
    std::optional<M> wait(const std::function<bool(const M&)>& pred, std::chrono::milliseconds timeout) {
        const auto deadline = Clock::now() + timeout;
        while (true) {
            while (!frames_.empty()) {
                const auto f = frames_.front();
                frames_.pop_front();
                if (auto m = mav::decode<M>(f); m && pred(*m)) {
                    return m;
                }
            }
            if (Clock::now() >= deadline) {
                return std::nullopt;
            }
            receive(50);
        }
    }
    /// Waits until the hub has sent something (so the station knows where to answer).
    bool wait_for_peer(std::chrono::milliseconds timeout) {
        return wait_until(
            [&] {
                receive(50);
                return have_peer_;
            },
            timeout, 1ms);
    }
    void drain() {
        receive(0);
        frames_.clear();
    }

  private:
    void receive(int wait_ms) {
        pollfd p{fd_, POLLIN, 0};
        while (::poll(&p, 1, wait_ms) > 0) {
            std::uint8_t buf[65536];
            sockaddr_in from{};
            socklen_t len = sizeof from;
            const auto n = ::recvfrom(fd_, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&from), &len);
            if (n <= 0) {
                return;
            }
            peer_ = from;
            have_peer_ = true;
            parser_.push(std::span(buf, static_cast<std::size_t>(n)), [&](const mav::Frame& f) {
                if (f.checksum_verified && frames_.size() < 100000) {
                    frames_.push_back(f);
                }
            });
            wait_ms = 0;
        }
    }

    int fd_ = -1;
    bool bound_ = false;
    bool have_peer_ = false;
    sockaddr_in peer_{};
    mav::Parser parser_;
    mav::Encoder encoder_{255, 190};
    std::deque<mav::Frame> frames_;
};

class GcsPassageE2e : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        shared_dir = new TempDir;
        shared_port = free_udp_port();
        // Ports of the test's own (or none): the defaults may be taken by a demo or another suite.
        shared_chain = new GroundChain(
            shared_dir->path(), {"--map", "off", "--mavlink-udp", "127.0.0.1:" + std::to_string(shared_port),
                                 "--mavlink-udp-listen", "127.0.0.1:0", "--mavlink-tcp", "off"});
        setup_error = shared_chain->start();
    }
    static void TearDownTestSuite() {
        delete shared_chain;
        delete shared_dir;
        shared_chain = nullptr;
        shared_dir = nullptr;
    }
    void SetUp() override {
        ASSERT_EQ(setup_error, "");
        station_ = std::make_unique<UdpStation>(shared_port);
        ASSERT_TRUE(station_->bound());
        ASSERT_TRUE(station_->wait_for_peer(kGenerous)) << "the hub sends the vehicle's MAVLink";
    }
    std::string logs() const {
        return "\nhub:\n" + shared_chain->hub->err() + "\ndaemon:\n" + shared_chain->daemon->err();
    }

    /// One MAVFTP request, sent again (same sequence number) until an answer to it comes.
    std::optional<ftp::Packet> ftp_request(ftp::Packet p, int tries = 6) {
        p.seq = ftp_seq_;
        mav::FileTransferProtocol m;
        m.target_system = 1;
        m.target_component = 1;
        m.payload = ftp::encode(p);
        for (int i = 0; i < tries; ++i) {
            station_->send(m);
            const auto reply = station_->wait<mav::FileTransferProtocol>(
                [&](const mav::FileTransferProtocol& r) {
                    const auto got = ftp::decode(r.payload);
                    return r.target_system == 255 && got.seq == static_cast<std::uint16_t>(p.seq + 1) &&
                           got.req_opcode == p.opcode;
                },
                5s);
            if (reply) {
                ftp_seq_ = static_cast<std::uint16_t>(p.seq + 2);
                return ftp::decode(reply->payload);
            }
        }
        return std::nullopt;
    }
    static ftp::Packet op(ftp::Opcode o, std::string_view path = {}, std::uint32_t offset = 0) {
        return ftp::request(o, path, offset);
    }

    std::optional<mav::CommandAck> command(mav::CommandLong c) {
        c.target_system = 1;
        c.target_component = 1;
        for (int i = 0; i < 5; ++i) {
            station_->send(c);
            if (auto ack = station_->wait<mav::CommandAck>(
                    [&](const mav::CommandAck& a) {
                        return a.command == c.command && a.target_system == 255;
                    },
                    5s)) {
                return ack;
            }
        }
        return std::nullopt;
    }

    static inline TempDir* shared_dir = nullptr;
    static inline GroundChain* shared_chain = nullptr;
    static inline std::string setup_error;
    static inline int shared_port = 0;
    std::unique_ptr<UdpStation> station_;
    std::uint16_t ftp_seq_ = 100;
};

TEST_F(GcsPassageE2e, TimesyncIsAnsweredByTheAutopilot) {
    mav::Timesync request;
    request.ts1 = 1'234'567'890'123;
    std::optional<mav::Timesync> reply;
    for (int i = 0; i < 5 && !reply; ++i) {
        station_->send(request);
        reply = station_->wait<mav::Timesync>(
            [&](const mav::Timesync& t) { return t.ts1 == request.ts1 && t.tc1 != 0; }, 5s);
    }
    ASSERT_TRUE(reply.has_value()) << logs();
    EXPECT_EQ(reply->target_system, 255);
    EXPECT_EQ(reply->target_component, 190);
    EXPECT_GT(reply->tc1, 0);
}

TEST_F(GcsPassageE2e, CommandIntRepositionDrivesTheRoverTowardThePoint) {
    mav::CommandLong arm;
    arm.command = mav::kCmdComponentArmDisarm;
    arm.param1 = 1;
    const auto armed = command(arm);
    ASSERT_TRUE(armed.has_value()) << logs();
    ASSERT_EQ(armed->result, mav::kResultAccepted);

    const apmsim::GeoPoint home{GroundChain::kHomeLat, GroundChain::kHomeLon};
    const apmsim::GeoPoint point{GroundChain::kHomeLat + 0.0006, GroundChain::kHomeLon + 0.0006};
    mav::CommandInt c;
    c.target_system = 1;
    c.target_component = 1;
    c.command = 192;  // MAV_CMD_DO_REPOSITION
    c.frame = mav::kFrameGlobalRelativeAltInt;
    c.param1 = -1;
    c.param2 = 1;  // MAV_DO_REPOSITION_FLAGS_CHANGE_MODE
    c.x = static_cast<std::int32_t>(point.lat * 1e7);
    c.y = static_cast<std::int32_t>(point.lon * 1e7);
    std::optional<mav::CommandAck> ack;
    for (int i = 0; i < 5 && !ack; ++i) {
        station_->send(c);
        ack = station_->wait<mav::CommandAck>(
            [&](const mav::CommandAck& a) { return a.command == 192 && a.target_system == 255; }, 5s);
    }
    ASSERT_TRUE(ack.has_value()) << logs();
    EXPECT_EQ(ack->result, mav::kResultAccepted);

    // The board reports GUIDED (custom mode 15) and its position closes on the point.
    const auto guided = station_->wait<mav::Heartbeat>(
        [](const mav::Heartbeat& h) { return h.custom_mode == 15 && h.type == mav::kMavTypeGroundRover; },
        kGenerous);
    EXPECT_TRUE(guided.has_value()) << logs();
    const double start = apmsim::distance_m(home, point);
    double closest = start;
    const auto began = Clock::now();
    station_->wait<mav::GlobalPositionInt>(
        [&](const mav::GlobalPositionInt& p) {
            closest = std::min(closest, apmsim::distance_m({p.lat / 1e7, p.lon / 1e7}, point));
            return closest < start / 2;
        },
        kGenerous);
    std::cout << "[ figures ] the rover closed from " << start << " m to " << closest << " m of the point in "
              << seconds_since(began) << " s\n";
    EXPECT_LT(closest, start / 2) << logs();

    // In GUIDED, SET_POSITION_TARGET_GLOBAL_INT (no answer: the position tells) turns it to another point.
    const apmsim::GeoPoint other{GroundChain::kHomeLat - 0.0006, GroundChain::kHomeLon + 0.0006};
    mav::SetPositionTargetGlobalInt target;
    target.target_system = 1;
    target.target_component = 1;
    target.coordinate_frame = mav::kFrameGlobalRelativeAltInt;
    target.type_mask = 0x0DFC;  // a position only
    target.lat_int = static_cast<std::int32_t>(other.lat * 1e7);
    target.lon_int = static_cast<std::int32_t>(other.lon * 1e7);
    double from_other = -1;
    double nearest_other = std::numeric_limits<double>::max();
    const auto turned = Clock::now();
    auto sent = turned;
    station_->send(target);
    station_->wait<mav::GlobalPositionInt>(
        [&](const mav::GlobalPositionInt& p) {
            const double d = apmsim::distance_m({p.lat / 1e7, p.lon / 1e7}, other);
            from_other = from_other < 0 ? d : from_other;
            nearest_other = std::min(nearest_other, d);
            if (Clock::now() - sent > 10s && nearest_other > from_other - 5) {
                sent = Clock::now();
                station_->send(target);  // lost on the way: sent again, as stations stream their targets
            }
            return nearest_other < from_other - 20;
        },
        kGenerous);
    std::cout << "[ figures ] toward the position target: from " << from_other << " m to " << nearest_other
              << " m in " << seconds_since(turned) << " s\n";
    EXPECT_LT(nearest_other, from_other - 20) << logs();
}

TEST_F(GcsPassageE2e, MavftpReadsTheParameterFileAndItsParametersAreTheBoards) {
    using Op = ftp::Opcode;
    ASSERT_TRUE(ftp_request(op(Op::ResetSessions)).has_value()) << logs();
    const auto opened = ftp_request(op(Op::OpenFileRO, "@PARAM/param.pck"));
    ASSERT_TRUE(opened.has_value()) << logs();
    ASSERT_EQ(opened->opcode, Op::Ack);
    const std::uint32_t size = std::uint32_t{opened->data[0]} | std::uint32_t{opened->data[1]} << 8 |
                               std::uint32_t{opened->data[2]} << 16 | std::uint32_t{opened->data[3]} << 24;
    const auto began = Clock::now();
    std::vector<std::uint8_t> file;
    while (file.size() < size) {
        auto read = op(Op::ReadFile, {}, static_cast<std::uint32_t>(file.size()));
        read.session = opened->session;
        read.size = ftp::kMaxData;
        const auto r = ftp_request(read);
        ASSERT_TRUE(r.has_value()) << "no answer at offset " << file.size() << logs();
        ASSERT_EQ(r->opcode, Op::Ack) << "at offset " << file.size();
        ASSERT_EQ(r->offset, file.size());
        file.insert(file.end(), r->bytes().begin(), r->bytes().end());
    }
    std::cout << "[ figures ] @PARAM/param.pck, " << file.size() << " bytes, read through the radio in "
              << seconds_since(began) << " s\n";
    auto terminate = op(Op::TerminateSession);
    terminate.session = opened->session;
    EXPECT_EQ(ftp_request(terminate)->opcode, Op::Ack);

    const auto unpacked = apmsim::unpack_params(file);
    ASSERT_TRUE(unpacked.has_value());
    const auto table = apmsim::ParamTable::for_profile(apmsim::FirmwareProfile::modern());
    ASSERT_EQ(unpacked->params.size(), table.size());
    EXPECT_EQ(unpacked->total, table.size());
    std::vector<std::size_t> changed;
    for (std::size_t i = 0; i < table.size(); ++i) {
        EXPECT_EQ(unpacked->params[i].name, table.at(i).name) << i;
        EXPECT_EQ(unpacked->params[i].type, table.at(i).type) << table.at(i).name;
        if (unpacked->params[i].value != table.at(i).value) {
            changed.push_back(i);
        }
    }
    // Values the daemon changed since the board booted (stream rates, say): the board's own answer agrees.
    EXPECT_LT(changed.size(), 20u);
    for (const auto i : changed) {
        mav::ParamRequestRead read;
        read.target_system = 1;
        read.target_component = 1;
        read.param_index = static_cast<std::int16_t>(i);
        std::optional<mav::ParamValue> value;
        for (int t = 0; t < 5 && !value; ++t) {
            station_->send(read);
            value = station_->wait<mav::ParamValue>(
                [&](const mav::ParamValue& v) { return v.param_index == i; }, 5s);
        }
        ASSERT_TRUE(value.has_value()) << table.at(i).name;
        EXPECT_FLOAT_EQ(value->param_value, unpacked->params[i].value) << table.at(i).name;
    }
}

TEST_F(GcsPassageE2e, AMavftpWriteOfTheMissionIsRefusedByTheGate) {
    const auto nak = ftp_request(op(ftp::Opcode::OpenFileWO, "@MISSION/mission.dat"));
    ASSERT_TRUE(nak.has_value()) << logs();
    EXPECT_EQ(nak->opcode, ftp::Opcode::Nak);
    ASSERT_EQ(nak->size, 1);
    EXPECT_EQ(nak->data[0], static_cast<std::uint8_t>(ftp::Error::FileProtected));
    const auto said = station_->wait<mav::Statustext>(
        [](const mav::Statustext& t) {
            return mav::text_of(t.text).find("mission write refused") != std::string_view::npos;
        },
        kGenerous);
    EXPECT_TRUE(said.has_value()) << logs();
    // The autopilot never saw it: its own answer to an open for writing would be UnknownCommand.
    EXPECT_NE(shared_chain->daemon->err().find("refused a mission write"), std::string::npos) << logs();
}

}  // namespace
}  // namespace airseg::test

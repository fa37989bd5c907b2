// AutopilotService on a real pseudo-terminal with the scripted Rover behind it, in real time: the port is
// opened, the driver reaches READY, requests over the bus are answered, status is published, and the
// flight recorder fills, and follows the flight on disk while the service runs.
#include "services/autopilot/autopilot_service.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include "hal/pty.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/autopilot/mavlink/target.hpp"
#include "tests/unit/autopilot/fake_rover.hpp"
#include "tools/mavdump/tlog_reader.hpp"

namespace airseg::autopilot {
namespace {

namespace fs = std::filesystem;

struct RoverOnPty {
    RoverOnPty(asio::io_context& io, const std::string& link)
        : strand(asio::make_strand(io)),
          pty(strand, hal::PtyConfig{link}),
          rover(options(), SteadyClock::now()),
          timer(strand) {}
    static testing::FakeRover::Options options() {
        testing::FakeRover::Options o;
        o.boot_delay = milliseconds(100);
        o.calibration = milliseconds(100);
        return o;
    }
    void start() {
        asio::dispatch(strand, [this] {
            EXPECT_TRUE(pty.open().ok());
            pty.start_reading([this](std::span<const std::uint8_t> b) {
                rover.handle_bytes(b, SteadyClock::now());
                flush();
            });
            tick();
        });
    }
    void tick() {
        rover.handle_timeout(SteadyClock::now());
        flush();
        timer.expires_after(milliseconds(10));
        timer.async_wait([this](const boost::system::error_code& ec) {
            if (!ec) {
                tick();
            }
        });
    }
    void flush() {
        while (auto f = rover.poll_transmit()) {
            pty.write(std::move(*f));
        }
    }
    void stop() {
        asio::dispatch(strand, [this] {
            timer.cancel();
            pty.unplug();
        });
    }
    Strand strand;
    hal::Pty pty;
    testing::FakeRover rover;
    asio::steady_timer timer;
};

/// A service on a pseudo-terminal with the scripted Rover behind it, in a directory of its own.
struct ServiceOnPty {
    explicit ServiceOnPty(const std::string& name)
        : dir(fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()))) {
        fs::create_directories(dir);
        rover = std::make_unique<RoverOnPty>(io, (dir / "ttyACM0").string());
        rover->start();
    }
    ~ServiceOnPty() { fs::remove_all(dir); }

    AutopilotServiceConfig config() const {
        AutopilotServiceConfig c;
        c.autopilot = AutopilotConfig::defaults_for(Board::Pixhawk);
        c.autopilot.bauds = {57600};
        c.port.serial.path = (dir / "ttyACM0").string();
        c.port.reconnect_min = milliseconds(20);
        return c;
    }
    std::unique_ptr<AutopilotService> make(const AutopilotServiceConfig& c) {
        auto service = std::make_unique<AutopilotService>(ctx, c, nullptr);
        health.add("autopilot", SteadyClock::now());
        return service;
    }
    bool run_until(const std::function<bool()>& cond) {
        const auto deadline = SteadyClock::now() + seconds(15);
        while (!cond() && SteadyClock::now() < deadline) {
            io.run_for(milliseconds(10));
            if (io.stopped()) {
                io.restart();
            }
        }
        return cond();
    }
    bool ready() const {
        const auto s = bus.latest<AutopilotStatus>();
        return s && s->ready;
    }
    void finish(std::unique_ptr<AutopilotService>& service) {
        service->stop();
        rover->stop();
        io.run_for(milliseconds(50));
        service.reset();
    }

    fs::path dir;
    asio::io_context io;
    Bus bus;
    HealthRegistry health;
    CommandDispatcher commands;
    ServiceContext ctx{io, bus, health, commands, milliseconds(100)};
    std::unique_ptr<RoverOnPty> rover;
};

TEST(AutopilotService, ReachesReadyOnAPtyAndAnswersBusRequests) {
    ServiceOnPty rig("airseg-ap");
    auto& bus = rig.bus;
    auto& health = rig.health;
    const auto& dir = rig.dir;
    auto config = rig.config();
    config.tlog.enabled = true;
    config.tlog.path = (dir / "autopilot.tlog").string();
    auto service = rig.make(config);

    Strand test_strand = asio::make_strand(rig.io);
    std::vector<Ready> ready;
    std::vector<RequestDone> done;
    auto s1 = bus.subscribe<Ready>(test_strand, [&](const Ready& r) { ready.push_back(r); });
    auto s2 = bus.subscribe<RequestDone>(test_strand, [&](const RequestDone& d) { done.push_back(d); });
    service->start();
    const auto run_until = [&](const std::function<bool()>& cond) { return rig.run_until(cond); };
    ASSERT_TRUE(run_until([&] { return !ready.empty(); }));
    EXPECT_LT(ready[0].seconds_from_open, 5.0);

    // Requests are answered through their Reply, on the requester's strand, never as a RequestDone event.
    ReplyGuard guard;
    std::vector<RequestDone> replied;
    bool on_test_strand = false;
    AutopilotRequest drive;
    drive.op = RequestStateChange{VehicleState::WaypointNavigation};
    drive.reply = Reply<RequestDone>(test_strand, guard, not_answered(), [&](const RequestDone& d) {
        on_test_strand = test_strand.running_in_this_thread();
        replied.push_back(d);
    });
    bus.publish(std::move(drive));
    ASSERT_TRUE(run_until([&] { return !replied.empty(); }));
    EXPECT_EQ(replied[0].kind, RequestKind::SetState);
    EXPECT_EQ(replied[0].result, RequestResult::Ok) << replied[0].detail;
    EXPECT_TRUE(on_test_strand);

    ASSERT_TRUE(run_until([&] {
        const auto s = bus.latest<AutopilotStatus>();
        return s && s->state == VehicleState::WaypointNavigation && s->ready;
    }));
    EXPECT_TRUE(run_until([&] {
        for (const auto& h : health.snapshot()) {
            if (h.name == "autopilot") {
                return h.health == Health::Up;
            }
        }
        return false;
    }));

    // A request nobody answers through (no Reply) still runs.
    AutopilotRequest park;
    park.op = RequestStateChange{VehicleState::Parking};
    bus.publish(std::move(park));
    EXPECT_TRUE(run_until([&] {
        const auto s = bus.latest<AutopilotStatus>();
        return s && s->state == VehicleState::Parking;
    }));
    EXPECT_EQ(replied.size(), 1u);
    EXPECT_TRUE(done.empty()) << "answers go through the Reply, not the bus";

    rig.finish(service);
    EXPECT_GT(fs::file_size(dir / "autopilot.tlog"), 1000u);
}

struct TlogOnDisk {
    std::uint64_t records = 0;
    std::uint64_t newest_us = 0;  // the newest record's stamp
    std::uint64_t skipped_bytes = 0;
};

TlogOnDisk read_tlog(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                          std::istreambuf_iterator<char>()};
    TlogOnDisk out;
    mavdump::TlogReader reader;
    reader.push(bytes, [&](std::uint64_t t, std::span<const std::uint8_t>) {
        ++out.records;
        out.newest_us = std::max(out.newest_us, t);
    });
    reader.finish();
    out.skipped_bytes = reader.skipped_bytes();
    return out;
}

std::uint64_t wall_us() {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<microseconds>(std::chrono::system_clock::now().time_since_epoch())
            .count());
}

// The recorder's 2 s flush deadline on the service's timer: frames reach the file during the flight, not only
// in 32 KiB blocks or at the stop (the traffic here is far below 32 KiB in the time allowed).
TEST(AutopilotService, TheTlogOnDiskFollowsTheLinkWhileTheServiceRuns) {
    ServiceOnPty rig("airseg-ap-tlog");
    auto config = rig.config();
    config.tlog.enabled = true;
    config.tlog.path = (rig.dir / "autopilot.tlog").string();
    auto service = rig.make(config);
    service->start();
    const auto run_until = [&](const std::function<bool()>& cond) { return rig.run_until(cond); };
    ASSERT_TRUE(run_until([&] { return rig.ready(); }));
    // Twice in a row, a frame exchanged from now on reaches the file while the service keeps running.
    std::uint64_t bytes_before = 0;
    for (int round = 0; round < 2; ++round) {
        const std::uint64_t since_us = wall_us();
        const auto t0 = SteadyClock::now();
        ASSERT_TRUE(run_until([&] { return read_tlog(config.tlog.path).newest_us >= since_us; }))
            << "round " << round << ": nothing newer on disk after 15 s; "
            << read_tlog(config.tlog.path).records << " records";
        const auto bytes = fs::file_size(config.tlog.path);
        std::cout << "[ figures ] round " << round << ": a frame from now on disk after "
                  << std::chrono::duration<double>(SteadyClock::now() - t0).count() << " s; file " << bytes
                  << " bytes\n";
        EXPECT_GT(bytes, bytes_before);
        EXPECT_LT(bytes, TlogWriter::kFlushAt * 2) << "the traffic stayed below the 32 KiB rule";
        bytes_before = bytes;
    }

    rig.finish(service);
    const auto end = read_tlog(config.tlog.path);
    EXPECT_EQ(end.skipped_bytes, 0u) << "whole records only";
    EXPECT_GT(end.records, 0u);
}

// Ground stations through airsegd: one on the endpoint (UDP), one through the ground link (the bus). Both
// get the autopilot's frames; a mission upload from either is answered DENIED by airsegd, not written.
TEST(AutopilotService, GroundStationsGetTheAutopilotsFramesAndMissionUploadsAreReceivedInItsName) {
    ServiceOnPty rig("airseg-ap-gcs");
    auto& io = rig.io;
    auto& bus = rig.bus;
    auto config = rig.config();
    config.forward_frames = true;
    config.gcs_endpoint = GcsEndpointConfig{"127.0.0.1:0", "", ""};
    auto service = rig.make(config);
    Strand test_strand = asio::make_strand(io);
    std::vector<ForwardedFrame> forwarded;
    auto sub =
        bus.subscribe<ForwardedFrame>(test_strand, [&](const ForwardedFrame& f) { forwarded.push_back(f); });
    service->start();
    const auto run_until = [&](const std::function<bool()>& cond) { return rig.run_until(cond); };
    ASSERT_TRUE(run_until([&] { return rig.ready(); }));
    ASSERT_NE(service->gcs_endpoint(), nullptr);
    // The autopilot's answers to airsegd's own reads (the mission download's MISSION_COUNT and items, to
    // 255/191) are kept from every station, and counted.
    const auto to_airsegd = [](const std::vector<std::uint8_t>& bytes) {
        const auto t = mavlink::frame_target(bytes);
        return t && t->system == 255 && t->component == 191;
    };
    ASSERT_TRUE(run_until([&] {
        const auto s = bus.latest<AutopilotStatus>();
        return s && s->gcs_to_airsegd_kept > 0;
    }));
    EXPECT_TRUE(std::none_of(forwarded.begin(), forwarded.end(),
                             [&](const ForwardedFrame& f) { return to_airsegd(f.bytes); }));
    const auto port = service->gcs_endpoint()->udp_port();
    ASSERT_NE(port, 0);

    // The ground station on the endpoint uploads a mission; the service receives it in the autopilot's name
    // and, with no flight plan manager to take it, refuses it.
    asio::ip::udp::socket gcs(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
    const asio::ip::udp::endpoint to_service(asio::ip::make_address("127.0.0.1"), port);
    mavlink::Encoder encoder(254, 190);
    mavlink::MissionCount count;
    count.target_system = 1;
    count.target_component = 1;
    count.count = 3;
    gcs.send_to(asio::buffer(encoder.encode(count)), to_service);
    std::vector<mavlink::Frame> heard;
    std::array<std::uint8_t, 2048> buf{};
    std::function<void()> receive = [&] {
        gcs.async_receive(asio::buffer(buf), [&](boost::system::error_code ec, std::size_t n) {
            if (ec) {
                return;
            }
            mavlink::Parser p;
            p.push(std::span(buf).first(n), [&](const mavlink::Frame& f) {
                heard.push_back(f);
                if (f.msgid == mavlink::MissionRequestInt::kId) {
                    const auto r = mavlink::decode_payload<mavlink::MissionRequestInt>(f.payload_view());
                    mavlink::MissionItemInt item;
                    item.target_system = 1;
                    item.target_component = 1;
                    item.seq = r.seq;
                    item.frame = mavlink::kFrameGlobalRelativeAltInt;
                    item.command = mavlink::kCmdNavWaypoint;
                    item.x = 412750000 + r.seq * 1000;
                    item.y = 19870000;
                    gcs.send_to(asio::buffer(encoder.encode(item)), to_service);
                }
            });
            receive();
        });
    };
    receive();
    const auto has = [&](std::uint32_t msgid) {
        return std::any_of(heard.begin(), heard.end(),
                           [&](const mavlink::Frame& f) { return f.msgid == msgid; });
    };
    ASSERT_TRUE(run_until([&] { return has(mavlink::MissionAck::kId) && has(mavlink::Heartbeat::kId); }));
    std::string said;
    for (const auto& f : heard) {
        if (f.msgid == mavlink::MissionAck::kId) {
            const auto ack = mavlink::decode_payload<mavlink::MissionAck>(f.payload_view());
            EXPECT_EQ(ack.target_system, 254);
            EXPECT_EQ(ack.type, mavlink::kMissionDenied);
        }
        if (f.msgid == mavlink::Statustext::kId) {
            said += std::string(
                mavlink::text_of(mavlink::decode_payload<mavlink::Statustext>(f.payload_view()).text));
        }
    }
    EXPECT_TRUE(has(mavlink::MissionRequestInt::kId));
    EXPECT_NE(said.find("no flight plan manager"), std::string::npos) << said;
    // The same answer went to the ground link's stations, reliably, with the autopilot's own frames.
    EXPECT_TRUE(run_until([&] {
        return std::any_of(forwarded.begin(), forwarded.end(), [](const ForwardedFrame& f) {
            return f.id == mavlink::MissionAck::kId && f.delivery == ForwardedFrame::Delivery::Reliable;
        });
    }));
    EXPECT_TRUE(std::any_of(forwarded.begin(), forwarded.end(), [](const ForwardedFrame& f) {
        return f.id == mavlink::Heartbeat::kId && f.delivery == ForwardedFrame::Delivery::Freshest;
    }));
    // A ground station on the ground link clears the mission (through the bus): refused as ever.
    const auto acks = [&] {
        return std::count_if(forwarded.begin(), forwarded.end(),
                             [](const ForwardedFrame& f) { return f.id == mavlink::MissionAck::kId; });
    };
    const auto before = acks();
    mavlink::MissionClearAll clear;
    clear.target_system = 1;
    bus.publish(GroundStationFrames{encoder.encode(clear)});
    EXPECT_TRUE(run_until([&] { return acks() > before; }));
    EXPECT_TRUE(service->driver().ready());
    rig.finish(service);
}

}  // namespace
}  // namespace airseg::autopilot

// AutopilotService on a real pseudo-terminal with the scripted Rover behind it, in real time: the port is
// opened, the driver reaches READY, requests over the bus are answered, status is published, and the
// flight recorder fills.
#include "services/autopilot/autopilot_service.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "hal/pty.hpp"
#include "tests/unit/autopilot/fake_rover.hpp"

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

TEST(AutopilotService, ReachesReadyOnAPtyAndAnswersBusRequests) {
    const fs::path dir = fs::temp_directory_path() / ("airseg-ap-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    asio::io_context io;
    Bus bus;
    HealthRegistry health;
    CommandDispatcher commands;
    ServiceContext ctx{io, bus, health, commands, milliseconds(100)};

    RoverOnPty rover(io, (dir / "ttyACM0").string());
    rover.start();

    AutopilotServiceConfig config;
    config.autopilot = AutopilotConfig::defaults_for(Board::Pixhawk);
    config.autopilot.bauds = {57600};
    config.port.serial.path = (dir / "ttyACM0").string();
    config.port.reconnect_min = milliseconds(20);
    config.tlog.enabled = true;
    config.tlog.path = (dir / "autopilot.tlog").string();
    auto service = std::make_unique<AutopilotService>(ctx, config, nullptr);
    health.add("autopilot", SteadyClock::now());

    Strand test_strand = asio::make_strand(io);
    std::vector<Ready> ready;
    std::vector<RequestDone> done;
    auto s1 = bus.subscribe<Ready>(test_strand, [&](const Ready& r) { ready.push_back(r); });
    auto s2 = bus.subscribe<RequestDone>(test_strand, [&](const RequestDone& d) { done.push_back(d); });
    service->start();

    const auto run_until = [&](const std::function<bool()>& cond) {
        const auto deadline = SteadyClock::now() + seconds(15);
        while (!cond() && SteadyClock::now() < deadline) {
            io.run_for(milliseconds(10));
            if (io.stopped()) {
                io.restart();
            }
        }
        return cond();
    };
    ASSERT_TRUE(run_until([&] { return !ready.empty(); }));
    EXPECT_LT(ready[0].seconds_from_open, 5.0);

    bus.publish(AutopilotRequest{77, RequestStateChange{VehicleState::WaypointNavigation}});
    ASSERT_TRUE(run_until([&] { return !done.empty(); }));
    EXPECT_EQ(done[0].id, 77u);
    EXPECT_EQ(done[0].result, RequestResult::Ok) << done[0].detail;

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

    service->stop();
    rover.stop();
    io.run_for(milliseconds(50));
    service.reset();
    EXPECT_GT(fs::file_size(dir / "autopilot.tlog"), 1000u);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace airseg::autopilot

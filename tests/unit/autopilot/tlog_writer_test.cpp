// The flight recorder: a recorded driver session decodes with airseg-mavdump --tlog; rotation; a full disk.
#include "services/autopilot/tlog_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/autopilot/ardupilot/driver.hpp"
#include "tests/unit/autopilot/fake_rover.hpp"
#include "tests/unit/autopilot/sim_harness.hpp"

namespace airseg::autopilot {
namespace {

namespace fs = std::filesystem;
using testing::FakeRover;
using testing::Harness;
using testing::Party;

struct TempDir {
    TempDir() {
        std::string tmpl = (fs::temp_directory_path() / "airseg-tlog-XXXXXX").string();
        path = ::mkdtemp(tmpl.data());
    }
    ~TempDir() { fs::remove_all(path); }
    fs::path path;
};

const TlogWriter::WallTime kWall = TlogWriter::WallTime{} + std::chrono::seconds(1'700'000'000);

std::string run(const std::string& command) {
    std::string out;
    FILE* p = ::popen(command.c_str(), "r");
    if (!p) {
        return out;
    }
    std::array<char, 4096> buf{};
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) {
        out.append(buf.data(), n);
    }
    ::pclose(p);
    return out;
}

TEST(TlogWriter, ARecordedSessionDecodesWithMavdump) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "autopilot.tlog").string();
    std::size_t frames = 0;
    {
        TlogWriter tlog(config);
        const TimePoint start = TimePoint{} + std::chrono::hours(4);
        ardupilot::Driver driver(AutopilotConfig::defaults_for(Board::Pixhawk));
        FakeRover rover({}, start);
        driver.set_frame_tap([&](bool, std::span<const std::uint8_t> f) {
            tlog.record(f, kWall + std::chrono::milliseconds(frames));
            ++frames;
        });
        Party ground{[&](std::span<const std::uint8_t> b, TimePoint now) { driver.handle_bytes(b, now); },
                     [&] { return driver.poll_transmit(); },
                     [&](TimePoint now) { driver.handle_timeout(now); },
                     [&] { return driver.poll_timeout(); }};
        Party vehicle{[&](std::span<const std::uint8_t> b, TimePoint now) { rover.handle_bytes(b, now); },
                      [&] { return rover.poll_transmit(); },
                      [&](TimePoint now) { rover.handle_timeout(now); },
                      [&] { return rover.poll_timeout(); }};
        Harness h(ground, vehicle, {}, {}, 1, start);
        driver.on_port_open(start);
        ASSERT_TRUE(h.run_until([&] { return driver.ready(); }, start + std::chrono::seconds(30)));
        h.run_for(std::chrono::seconds(3));
        tlog.flush();
        EXPECT_EQ(tlog.stats().frames, frames);
        EXPECT_EQ(tlog.stats().dropped_frames, 0u);
    }
    ASSERT_GT(frames, 50u);
    const std::string out = run(std::string(AIRSEG_MAVDUMP_EXE) + " --tlog " + config.path + " 2>/dev/null");
    std::istringstream lines(out);
    std::size_t decoded = 0, heartbeats = 0, params = 0;
    for (std::string line; std::getline(lines, line);) {
        ++decoded;
        EXPECT_EQ(line.rfind("{\"timestamp_us\":", 0), 0u) << line;
        heartbeats += line.find("\"HEARTBEAT\"") != std::string::npos;
        params += line.find("\"PARAM_VALUE\"") != std::string::npos;
    }
    EXPECT_EQ(decoded, frames);
    EXPECT_GT(heartbeats, 3u);  // both directions: the autopilot's and ours
    EXPECT_GT(params, 40u);
    EXPECT_NE(out.find("\"timestamp_us\":1700000000000000"), std::string::npos);
}

TEST(TlogWriter, RotatesAtTheSizeCapKeepingNFiles) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "a.tlog").string();
    config.max_bytes = 64 * 1024;
    config.keep = 2;
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(100, 0xFD);
    for (int i = 0; i < 3000; ++i) {  // 324 kB: five files' worth
        tlog.record(frame, kWall);
    }
    tlog.flush();
    EXPECT_EQ(tlog.stats().rotations, 4u);
    EXPECT_TRUE(fs::exists(config.path));
    EXPECT_TRUE(fs::exists(config.path + ".1"));
    EXPECT_TRUE(fs::exists(config.path + ".2"));
    EXPECT_FALSE(fs::exists(config.path + ".3"));
    EXPECT_LE(fs::file_size(config.path + ".1"), config.max_bytes);
    EXPECT_EQ(fs::file_size(config.path + ".1") % 108, 0u);  // whole records only
    EXPECT_EQ(tlog.stats().frames, 3000u);
}

TEST(TlogWriter, AFullDiskIsCountedNotFatal) {
    TlogConfig config;
    config.enabled = true;
    config.path = "/dev/full";  // every write fails with ENOSPC
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(200, 0x55);
    for (int i = 0; i < 1000; ++i) {
        tlog.record(frame, kWall + std::chrono::milliseconds(i * 100));
    }
    tlog.flush();
    EXPECT_EQ(tlog.stats().frames, 0u);
    EXPECT_EQ(tlog.stats().dropped_frames, 1000u);
    EXPECT_GE(tlog.stats().write_errors, 1u);
    EXPECT_NE(tlog.stats().last_error.find("No space left"), std::string::npos) << tlog.stats().last_error;
}

TEST(TlogWriter, MissingDirectoryIsReportedAndRetriedLater) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "later" / "a.tlog").string();
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(10, 1);
    tlog.record(frame, kWall);
    EXPECT_FALSE(tlog.is_open());
    EXPECT_NE(tlog.stats().last_error.find("open"), std::string::npos);
    fs::create_directory(dir.path / "later");
    tlog.record(frame, kWall + std::chrono::seconds(1));  // within reopen_interval: not yet
    EXPECT_FALSE(tlog.is_open());
    tlog.record(frame, kWall + std::chrono::seconds(6));
    EXPECT_TRUE(tlog.is_open());
    tlog.flush();
    EXPECT_EQ(tlog.stats().frames, 1u);
    EXPECT_EQ(tlog.stats().dropped_frames, 2u);
}

TEST(TlogWriter, ValidateNamesTheKeys) {
    TlogConfig c;
    c.enabled = true;
    c.max_bytes = 10;
    const auto problems = TlogConfig::validate(c);
    ASSERT_EQ(problems.size(), 2u);
    EXPECT_NE(problems[0].find("autopilot.tlog.path"), std::string::npos);
    EXPECT_NE(problems[1].find("autopilot.tlog.max_bytes"), std::string::npos);
}

}  // namespace
}  // namespace airseg::autopilot

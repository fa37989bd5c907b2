// The flight recorder: a recorded driver session decodes with airseg-mavdump --tlog; the 2 s flush deadline
// in simulated time; rotation; a full disk.
#include "services/autopilot/tlog_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/autopilot/ardupilot/driver.hpp"
#include "tests/support/tree_paths.hpp"
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
const TimePoint kT0 = TimePoint{} + std::chrono::hours(2);

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A .tlog record as the file holds it: the big-endian microsecond stamp, then the frame.
std::vector<std::uint8_t> tlog_record(TlogWriter::WallTime at, const std::vector<std::uint8_t>& frame) {
    const auto us = static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::microseconds>(at.time_since_epoch()).count());
    std::vector<std::uint8_t> out;
    for (int shift = 56; shift >= 0; shift -= 8) {
        out.push_back(static_cast<std::uint8_t>(us >> shift));
    }
    out.insert(out.end(), frame.begin(), frame.end());
    return out;
}

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
            tlog.record(f, kWall + std::chrono::milliseconds(frames), start);  // flushed at the end
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
    const std::string out = run(::airseg::test::binary_dir() + "/" AIRSEG_MAVDUMP_IN_BUILD " --tlog " +
                                config.path + " 2>/dev/null");
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

TEST(TlogWriter, BufferedFramesReachTheFileWhenTheFlushIntervalIsDue) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "a.tlog").string();
    TlogWriter tlog(config);
    EXPECT_EQ(tlog.poll_timeout(), kNever) << "nothing buffered, no deadline";

    std::vector<std::uint8_t> expected;
    for (int i = 0; i < 5; ++i) {  // 5 frames over 1 s, far below 32 KiB
        const std::vector<std::uint8_t> frame(30 + i, static_cast<std::uint8_t>(i));
        const auto at = std::chrono::milliseconds(250 * i);
        tlog.record(frame, kWall + at, kT0 + at);
        const auto rec = tlog_record(kWall + at, frame);
        expected.insert(expected.end(), rec.begin(), rec.end());
    }
    EXPECT_EQ(tlog.poll_timeout(), kT0 + std::chrono::seconds(2))
        << "due 2 s after the oldest buffered frame";
    ASSERT_TRUE(fs::exists(config.path));
    EXPECT_EQ(fs::file_size(config.path), 0u) << "batched: nothing written before the deadline";

    tlog.handle_timeout(kT0 + std::chrono::milliseconds(1999));  // early: nothing happens
    EXPECT_EQ(fs::file_size(config.path), 0u);
    EXPECT_EQ(tlog.stats().frames, 0u);

    tlog.handle_timeout(kT0 + std::chrono::seconds(2));
    EXPECT_EQ(read_bytes(config.path), expected);
    EXPECT_EQ(tlog.stats().frames, 5u);
    EXPECT_EQ(tlog.stats().bytes, expected.size());
    EXPECT_EQ(tlog.poll_timeout(), kNever);

    // The next frame starts a new interval from its own time.
    const std::vector<std::uint8_t> late(20, 0xAB);
    tlog.record(late, kWall + std::chrono::seconds(7), kT0 + std::chrono::seconds(7));
    EXPECT_EQ(tlog.poll_timeout(), kT0 + std::chrono::seconds(9));
    EXPECT_EQ(fs::file_size(config.path), expected.size());
    tlog.handle_timeout(kT0 + std::chrono::seconds(9));
    const auto rec = tlog_record(kWall + std::chrono::seconds(7), late);
    expected.insert(expected.end(), rec.begin(), rec.end());
    EXPECT_EQ(read_bytes(config.path), expected);
}

TEST(TlogWriter, AFiftyHertzStreamIsWrittenOncePerIntervalNotPerFrame) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "a.tlog").string();
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(40, 0xFD);
    // The service's loop in simulated time: a frame every 20 ms for 10 s, handle_timeout when it is due.
    std::uintmax_t size = 0;
    int size_changes = 0;
    TimePoint latest_on_disk{};
    for (int i = 0; i < 500; ++i) {
        const TimePoint now = kT0 + std::chrono::milliseconds(20 * i);
        if (tlog.poll_timeout() <= now) {
            tlog.handle_timeout(now);
        }
        tlog.record(frame, kWall, now);
        if (const auto s = fs::file_size(config.path); s != size) {
            size = s;
            ++size_changes;
            latest_on_disk = now;
        }
        // Every frame older than the interval (100 frames) is on disk.
        EXPECT_GE(size, static_cast<std::uintmax_t>(std::max(0, i - 100)) * 48u) << "at frame " << i;
    }
    EXPECT_EQ(size_changes, 4) << "one write per 2 s (10 s, 500 frames, 24 kB: never the 32 KiB rule)";
    EXPECT_EQ(latest_on_disk, kT0 + std::chrono::seconds(8));
    EXPECT_EQ(tlog.stats().frames, 400u);
    tlog.flush();
    EXPECT_EQ(fs::file_size(config.path), 500u * 48u);
}

TEST(TlogWriter, DestructionFlushesWhatIsBuffered) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "a.tlog").string();
    const std::vector<std::uint8_t> frame(17, 0x42);
    {
        TlogWriter tlog(config);
        tlog.record(frame, kWall, kT0);
        tlog.record(frame, kWall, kT0 + std::chrono::milliseconds(100));
        EXPECT_EQ(fs::file_size(config.path), 0u);
    }
    auto expected = tlog_record(kWall, frame);
    expected.insert(expected.end(), expected.begin(), expected.end());
    EXPECT_EQ(read_bytes(config.path), expected);
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
        tlog.record(frame, kWall, kT0);
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
        tlog.record(frame, kWall + std::chrono::milliseconds(i * 100),
                    kT0 + std::chrono::milliseconds(i * 100));
    }
    tlog.flush();
    EXPECT_EQ(tlog.stats().frames, 0u);
    EXPECT_EQ(tlog.stats().dropped_frames, 1000u);
    EXPECT_GE(tlog.stats().write_errors, 1u);
    EXPECT_NE(tlog.stats().last_error.find("No space left"), std::string::npos) << tlog.stats().last_error;
}

TEST(TlogWriter, AWriteErrorAtTheTimedFlushIsCounted) {
    TlogConfig config;
    config.enabled = true;
    config.path = "/dev/full";
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(20, 0x55);
    for (int i = 0; i < 3; ++i) {
        tlog.record(frame, kWall, kT0 + std::chrono::milliseconds(i * 100));
    }
    EXPECT_EQ(tlog.stats().write_errors, 0u) << "nothing written yet";
    tlog.handle_timeout(kT0 + std::chrono::seconds(2));
    EXPECT_EQ(tlog.stats().write_errors, 1u);
    EXPECT_EQ(tlog.stats().dropped_frames, 3u);
    EXPECT_EQ(tlog.stats().frames, 0u);
    EXPECT_NE(tlog.stats().last_error.find("write /dev/full: No space left"), std::string::npos)
        << tlog.stats().last_error;
    EXPECT_FALSE(tlog.is_open());
    EXPECT_EQ(tlog.poll_timeout(), kNever) << "the failed buffer is dropped, not retried";

    // Closed until reopen_interval (5 s) has passed since the last open: those frames are dropped too.
    tlog.record(frame, kWall, kT0 + std::chrono::seconds(3));
    EXPECT_EQ(tlog.stats().dropped_frames, 4u);
    EXPECT_EQ(tlog.poll_timeout(), kNever);
    tlog.record(frame, kWall, kT0 + std::chrono::seconds(5));
    EXPECT_TRUE(tlog.is_open());
    EXPECT_EQ(tlog.poll_timeout(), kT0 + std::chrono::seconds(7));
    tlog.handle_timeout(kT0 + std::chrono::seconds(7));
    EXPECT_EQ(tlog.stats().write_errors, 2u);
    EXPECT_EQ(tlog.stats().dropped_frames, 5u);
}

TEST(TlogWriter, MissingDirectoryIsReportedAndRetriedLater) {
    TempDir dir;
    TlogConfig config;
    config.enabled = true;
    config.path = (dir.path / "later" / "a.tlog").string();
    TlogWriter tlog(config);
    const std::vector<std::uint8_t> frame(10, 1);
    tlog.record(frame, kWall, kT0);
    EXPECT_FALSE(tlog.is_open());
    EXPECT_NE(tlog.stats().last_error.find("open"), std::string::npos);
    fs::create_directory(dir.path / "later");
    tlog.record(frame, kWall, kT0 + std::chrono::seconds(1));  // within reopen_interval: not yet
    EXPECT_FALSE(tlog.is_open());
    tlog.record(frame, kWall, kT0 + std::chrono::seconds(6));
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

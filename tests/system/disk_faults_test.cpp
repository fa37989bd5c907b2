// System fault injection on the disk: airsegd runs in a private mount namespace (unshare -rm) over a small
// tmpfs holding its state_dir and its .tlog; the test fills that tmpfs mid-plan (through /proc/PID/root) and
// frees it again.
#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "tests/system/system_checks.hpp"

namespace airseg::test::sys {
namespace {

/// Writes `path` (on from its end) until the file system is full; returns the bytes written and the errno
/// that stopped it.
std::pair<std::size_t, int> fill(const std::string& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
    if (fd < 0) {
        return {0, errno};
    }
    const std::string block(4096, 'F');
    std::size_t total = 0;
    int err = 0;
    for (;;) {
        const auto n = ::write(fd, block.data(), block.size());
        if (n <= 0) {
            err = n < 0 ? errno : ENOSPC;
            break;
        }
        total += static_cast<std::size_t>(n);
    }
    ::close(fd);
    return {total, err};
}

std::optional<std::uint64_t> free_blocks(const std::string& dir) {
    struct statvfs st {};
    if (::statvfs(dir.c_str(), &st) != 0) {
        return std::nullopt;
    }
    return st.f_bfree;
}

/// Opens every file of `dir` named `prefix`* for reading: while the test holds them, the daemon removing one
/// (the .tlog's rotation drops its oldest file) gives no space back.
std::vector<int> hold_open(const std::string& dir, const std::string& prefix) {
    std::vector<int> fds;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().filename().string().starts_with(prefix)) {
            const int fd = ::open(entry.path().c_str(), O_RDONLY | O_CLOEXEC);
            if (fd >= 0) {
                fds.push_back(fd);
            }
        }
    }
    return fds;
}

std::optional<unsigned long> next_index(const std::string& progress) {
    const auto at = progress.find("next_index ");
    if (at == std::string::npos || progress.find("\ncheck ") == std::string::npos) {
        return std::nullopt;
    }
    return std::stoul(progress.substr(at + 11));
}

TEST(SystemDisk, DiskFullWhileWritingTheTlogAndTheStateFileKeepsTheDaemonUpAndTheLastGoodState) {
    // A private mount namespace is how this case makes a disk fill up without privileges; without it the case
    // cannot run, and says so.
    const auto probe = run({"/bin/sh", "-c", "exec unshare -rm true"}, {}, std::chrono::seconds(20));
    ASSERT_EQ(probe.exit_code, 0)
        << "this test needs `unshare -rm` (util-linux, unprivileged user namespaces): " << probe.err;

    BenchOptions o;
    o.speedup = 10;
    o.sim_args = {"--param", "CRUISE_SPEED=4", "--param", "WP_RADIUS=1.5"};
    o.tmpfs_kb = 512;
    o.daemon_sets = {"autopilot.tlog.max_bytes=65536", "autopilot.tlog.keep=1"};
    SystemBench bench(o);
    ASSERT_TRUE(bench.wait_ready()) << bench.logs();
    const auto commands_at_start = ground_commands(bench);
    CommandTally tally;
    int serial = 0;
    send_unique(bench, serial++, tally);

    const auto plan_file = bench.dir().file("route.yaml");
    write_file(plan_file, line_plan("route", 30, 20));
    const auto expected = expected_positions(plan_file);
    const auto first = reached_total(bench.sim());
    ASSERT_EQ(bench.ctl_local({"plan", "load", plan_file}).exit_code, 0) << bench.logs();
    ASSERT_TRUE(
        wait_until([&] { return plan_section(bench).value("waypoints_reached", 0) >= 3; }, kGenerous, kPoll))
        << bench.logs();
    const std::string volume = "/proc/" + std::to_string(bench.daemon_pid()) + "/root" + bench.tmpfs_dir();
    ASSERT_TRUE(std::filesystem::exists(volume + "/autopilot.tlog")) << "the .tlog is recorded on the tmpfs";
    ASSERT_TRUE(next_index(read_file(bench.state_dir() + "/progress.state")));

    // The disk fills up. The .tlog's files are held open first, so that its rotation, which removes the
    // oldest, cannot give space back while the disk is meant to be full.
    const auto held = hold_open(volume, "autopilot.tlog");
    ASSERT_FALSE(held.empty()) << "the .tlog is open for the test";
    const auto [filled, why] = fill(volume + "/filler");
    ASSERT_EQ(why, ENOSPC) << std::strerror(why);
    const auto full_at = std::chrono::steady_clock::now();
    Json doc;
    ASSERT_TRUE(wait_until(
        [&] {
            doc = bench.status();
            const auto plan = section(doc, "plan");
            const auto plan_error =
                plan.value("error", Json()).is_string() ? plan["error"].get<std::string>() : std::string();
            return plan_error.find("No space left") != std::string::npos &&
                   counter(doc, "/autopilot/tlog/write_errors") > 0;
        },
        kGenerous, kPoll))
        << "both write errors are visible in status: plan " << doc["plan"].dump() << " autopilot "
        << doc["autopilot"].dump() << bench.logs();
    const double seen_s = seconds_since(full_at);
    EXPECT_NE(doc["autopilot"]["tlog"].value("error", "").find("No space left"), std::string::npos)
        << doc["autopilot"].dump();
    // A save under way as the disk filled holds a page with its temporary file, and its rename frees the
    // page of the file it replaces: the next save may take that page, and so on. The disk is topped up
    // until no save is under way and no page is free; from then on every save fails.
    ASSERT_TRUE(wait_until(
        [&] {
            fill(volume + "/filler");
            const auto none_free = [&] { return free_blocks(volume) == std::optional<std::uint64_t>(0); };
            return none_free() && !std::filesystem::exists(bench.state_dir() + "/progress.state.tmp") &&
                   none_free();
        },
        kGenerous, std::chrono::milliseconds(5)))
        << "the tmpfs has " << free_blocks(volume).value_or(0) << " blocks free";
    // The last good state file stays: complete, checksummed, behind the vehicle's progress; no leftover.
    const auto kept = read_file(bench.state_dir() + "/progress.state");
    const auto kept_next = next_index(kept);
    ASSERT_TRUE(kept_next) << kept;
    const auto plan_now = plan_section(bench);
    ASSERT_TRUE(plan_now["next_waypoint"].is_number()) << plan_now.dump();
    EXPECT_LE(*kept_next, plan_now["next_waypoint"].get<unsigned long>()) << kept;
    // No leftover: each failed save removes its temporary file, but the plan goes on and the next save may be
    // under way as this looks (under qemu-armel one was, once). A leftover stays; a save in progress goes.
    EXPECT_TRUE(
        wait_until([&] { return !std::filesystem::exists(bench.state_dir() + "/progress.state.tmp"); },
                   kGenerous, std::chrono::milliseconds(5)))
        << "progress.state.tmp left behind";
    EXPECT_TRUE(std::filesystem::exists(bench.state_dir() + "/plan.yaml"));
    // The daemon goes on: it answers, and the plan keeps being driven.
    send_unique(bench, serial++, tally);
    const auto reached_full = plan_section(bench).value("waypoints_reached", 0);
    ASSERT_TRUE(
        wait_until([&] { return plan_section(bench).value("waypoints_reached", 0) >= reached_full + 3; },
                   kGenerous, kPoll))
        << bench.logs();
    EXPECT_EQ(next_index(read_file(bench.state_dir() + "/progress.state")), kept_next)
        << "nothing was written while the disk was full";

    // Space again: progress is saved again.
    for (const int fd : held) {
        ::close(fd);
    }
    std::filesystem::remove(volume + "/filler");
    const auto freed_at = std::chrono::steady_clock::now();
    ASSERT_TRUE(wait_until(
        [&] {
            const auto n = next_index(read_file(bench.state_dir() + "/progress.state"));
            return n && *n > *kept_next;
        },
        kGenerous, kPoll))
        << bench.logs();
    const double saved_again_s = seconds_since(freed_at);

    ASSERT_TRUE(
        wait_until([&] { return plan_section(bench).value("state", "") == "done"; }, kGenerous, kPoll))
        << plan_section(bench).dump();
    expect_reached_in_order(plan_waypoints_of(reached_log(bench.sim(), first)), expected);
    send_unique(bench, serial++, tally);
    expect_each_answered_once(tally, commands_at_start, ground_commands(bench));
    expect_daemon_alive(bench);
    const auto end = bench.status();
    std::cout << "[ figures ] disk full (tmpfs 512 KiB, filler " << filled / 1024
              << " KiB): both write errors in "
              << "status after " << seen_s << " s; tlog write_errors "
              << counter(end, "/autopilot/tlog/write_errors") << ", dropped_frames "
              << counter(end, "/autopilot/tlog/dropped_frames") << "; state file kept at "
              << "next_index " << *kept_next << "; saved again " << saved_again_s
              << " s after space came back; " << expected.size() << " waypoints reached in order, once each; "
              << tally.answered << "/" << tally.sent << " radio commands answered\n";
}

}  // namespace
}  // namespace airseg::test::sys

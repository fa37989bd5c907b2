#include "tests/support/system_bench.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>

#include <gtest/gtest.h>

namespace airseg::test {
namespace {

bool exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

/// `name` found on PATH (Subprocess takes a path), or `name` itself.
std::string on_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/bin:/bin";
    for (std::size_t at = 0; at <= dirs.size();) {
        const auto end = std::min(dirs.find(':', at), dirs.size());
        const auto candidate = dirs.substr(at, end - at) + "/" + name;
        if (::access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
        at = end + 1;
    }
    return name;
}

}  // namespace

SystemBench::SystemBench(BenchOptions options) : options_(std::move(options)) {
    for (int pair = 0; pair < options_.radios; ++pair) {
        start_link(pair);
    }
    start_sim();
    if (options_.key) {
        key_file_ = dir_.file("ground.key");
        write_file(key_file_, std::string(64, 'c') + "\n");
        ::chmod(key_file_.c_str(), 0600);
    }
    start_daemon();
}

SystemBench::~SystemBench() {
    // The daemon goes before the radios: a daemon outliving its ports keeps reopening their paths, and a pty
    // number freed by an emulator is soon another test's line.
    if (daemon_ && daemon_->running()) {
        daemon_->signal(SIGTERM);
        daemon_->wait_exit(std::chrono::seconds(10));
    }
    daemon_.reset();
    sim_control_.reset();
    sim_.reset();
    link_control_.clear();
    links_.clear();
}

void SystemBench::start_link(int pair) {
    const std::string n = std::to_string(pair);
    const std::string air = dir_.file("air" + n), ground = ground_port(pair),
                      control = dir_.file("link" + n + ".ctl");
    std::vector<std::string> args{binary("tools/linksim/airseg-linksim"),
                                  "--a",
                                  air,
                                  "--b",
                                  ground,
                                  "--baud",
                                  "57600",
                                  "--seed",
                                  std::to_string(11 + pair),
                                  "--control",
                                  control};
    args.insert(args.end(), options_.link_args.begin(), options_.link_args.end());
    links_.push_back(std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir_.path()));
    EXPECT_TRUE(wait_until([&] { return exists(air) && exists(ground) && exists(control); }, 30s))
        << links_.back()->err();
    link_control_.push_back(std::make_unique<ControlClient>(dir_.file("me-link" + n + ".ctl"), control));
}

void SystemBench::start_sim() {
    std::vector<std::string> args{binary("tools/apmsim/airseg-apmsim"),
                                  "--link",
                                  dir_.file("ttyACM0"),
                                  "--control",
                                  dir_.file("sim.ctl"),
                                  "--home",
                                  std::to_string(kHomeLat) + "," + std::to_string(kHomeLon),
                                  "--speedup",
                                  std::to_string(options_.speedup),
                                  "--boot-delay",
                                  "0.5",
                                  "--calib-time",
                                  "0.5",
                                  "--quiet"};
    args.insert(args.end(), options_.sim_args.begin(), options_.sim_args.end());
    sim_ = std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir_.path());
    EXPECT_TRUE(wait_until([&] { return exists(dir_.file("ttyACM0")) && exists(dir_.file("sim.ctl")); }, 30s))
        << sim_->err();
    sim_control_ = std::make_unique<ControlClient>(dir_.file("me-sim.ctl"), dir_.file("sim.ctl"));
}

void SystemBench::start_daemon() {
    const bool boxed = options_.tmpfs_kb > 0;
    const std::string data = boxed ? tmpfs_dir() : dir_.path();
    std::vector<std::string> sets{"status.socket=" + dir_.file("status.sock"), "state_dir=" + data + "/state",
                                  "autopilot.port=" + dir_.file("ttyACM0"), "autopilot.reconnect_max=500ms",
                                  "flightplan.fsync=false"};
    std::string ports;
    for (int pair = 0; pair < options_.radios; ++pair) {
        ports += (pair ? "," : "") + dir_.file("air" + std::to_string(pair));
    }
    sets.push_back("groundlink.ports=[" + ports + "]");
    sets.push_back(std::string("groundlink.mode=") + (options_.radios == 2 ? "split" : "single"));
    if (options_.key) {
        sets.push_back("groundlink.key_file=" + key_file_);
    } else {
        sets.push_back("groundlink.key_file=");
        sets.push_back("groundlink.insecure=true");
    }
    if (boxed) {
        sets.push_back("autopilot.tlog.enabled=true");
        sets.push_back("autopilot.tlog.path=" + data + "/autopilot.tlog");
    }
    sets.insert(sets.end(), options_.daemon_sets.begin(), options_.daemon_sets.end());

    std::vector<std::string> argv;
    if (boxed) {
        ::mkdir(tmpfs_dir().c_str(), 0700);
        // A private mount namespace (unprivileged: a user namespace too) with a small tmpfs over `data`;
        // airsegd replaces the shell, so the process is the daemon.
        argv = {
            on_path("unshare"),
            "-rm",
            "sh",
            "-c",
            "mount -t tmpfs -o size=" + std::to_string(options_.tmpfs_kb) + "k tmpfs \"$0\" && exec \"$@\"",
            data};
    }
    argv.insert(argv.end(), {binary("daemon/airsegd"), "--config", source_path("config/airseg.yaml")});
    for (const auto& s : sets) {
        argv.insert(argv.end(), {"--set", s});
    }
    daemon_ = std::make_unique<Subprocess>(argv, std::map<std::string, std::string>{}, dir_.path());
}

void SystemBench::stop_daemon() {
    ASSERT_TRUE(daemon_);
    daemon_->signal(SIGTERM);
    EXPECT_EQ(daemon_->wait_exit(std::chrono::seconds(20)), 0) << daemon_->err() << daemon_->stuck();
}

void SystemBench::kill_daemon() {
    ASSERT_TRUE(daemon_);
    daemon_->signal(SIGKILL);
    EXPECT_EQ(daemon_->wait_exit(std::chrono::seconds(20)), 128 + SIGKILL);
}

std::string SystemBench::state_dir() const {
    if (options_.tmpfs_kb > 0) {
        return "/proc/" + std::to_string(daemon_pid()) + "/root" + tmpfs_dir() + "/state";
    }
    return dir_.file("state");
}

std::string SystemBench::ground_port(int pair) const {
    return dir_.file("ground" + std::to_string(pair));
}

std::string SystemBench::ground_link() const {
    std::string out;
    for (int pair = 0; pair < options_.radios; ++pair) {
        out += (pair ? "," : "") + ground_port(pair);
    }
    return out;
}

RunResult SystemBench::ctl(std::vector<std::string> args, long timeout_ms) {
    std::vector<std::string> argv{binary("client/airsegctl"), "--link", ground_link(), "--timeout",
                                  std::to_string(timeout_ms), "--json"};
    if (options_.radios == 2) {
        argv.insert(argv.end(), {"--mode", "split"});
    }
    if (options_.key) {
        argv.insert(argv.end(), {"--key", key_file_});
    }
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv, {}, std::chrono::milliseconds(timeout_ms + 60'000));
}

RunResult SystemBench::ctl_local(std::vector<std::string> args, long timeout_ms) {
    std::vector<std::string> argv{binary("client/airsegctl"), "--local", "--socket",
                                  dir_.file("status.sock"),   "--json",  "--timeout",
                                  std::to_string(timeout_ms)};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv, {}, std::chrono::milliseconds(timeout_ms + 30'000));
}

SystemBench::Json SystemBench::status() {
    const auto r = ctl_local({"status"}, 10'000);
    auto j = Json::parse(r.out, nullptr, false);
    return r.exit_code == 0 && j.is_object() ? j : Json::object();
}

bool SystemBench::wait_ready(std::chrono::milliseconds timeout) {
    return wait_until(
        [&] {
            const auto ap = status().value("autopilot", Json());
            return ap.is_object() && ap.value("ready", false);
        },
        timeout, 200ms);
}

std::string SystemBench::logs() const {
    std::string out = "\n--- airsegd:\n" + daemon_err();
    if (sim_) {
        out += "\n--- apmsim:\n" + sim_->err();
    }
    for (const auto& l : links_) {
        out += "\n--- linksim:\n" + l->err();
    }
    return out;
}

}  // namespace airseg::test

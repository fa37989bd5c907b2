#pragma once
// The whole vehicle on one machine, for the system fault-injection suite (tests/system/): the simulated
// autopilot (airseg-apmsim) ⇄ airsegd ⇄ one or two emulated radio pairs (airseg-linksim, 57600 baud) ⇄
// airsegctl. Every file, pty and socket lives in the bench's own temporary directory, so benches run side by
// side. Faults are injected through the simulators' control sockets (docs/simulators.md).
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/control_client.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {

struct BenchOptions {
    int speedup = 1;                       // apmsim --speedup
    std::vector<std::string> sim_args;     // more apmsim options
    int radios = 1;                        // 1: single pair; 2: split mode over two pairs
    std::vector<std::string> link_args;    // impairments of every radio pair (linksim options)
    std::vector<std::string> daemon_sets;  // more airsegd --set KEY=VALUE
    bool key = false;                      // an authenticated link (key file 0600, airsegctl --key)
    /// When > 0, airsegd runs in a private mount namespace with a tmpfs of this size at tmpfs_dir(), where
    /// its state_dir and .tlog then live (`unshare -rm`).
    int tmpfs_kb = 0;
};

class SystemBench {
  public:
    using Json = nlohmann::json;
    static constexpr double kHomeLat = 41.2756;
    static constexpr double kHomeLon = 1.9866;

    /// Starts the radios, the simulator and the daemon; does not wait for the autopilot.
    explicit SystemBench(BenchOptions options = {});
    ~SystemBench();
    SystemBench(const SystemBench&) = delete;
    SystemBench& operator=(const SystemBench&) = delete;

    // ---- the ground --------------------------------------------------------------------------------------
    /// airsegctl over the radio, --json.
    RunResult ctl(std::vector<std::string> args, long timeout_ms = 30'000);
    /// airsegctl on the local status socket, --json (not counted by the ground link).
    RunResult ctl_local(std::vector<std::string> args, long timeout_ms = 30'000);
    /// The status document from the local socket; {} when it does not answer.
    Json status();
    /// Waits until the autopilot is ready (status on the local socket).
    bool wait_ready(std::chrono::milliseconds timeout = std::chrono::seconds(90));
    /// The ground ends of the radio(s) as airsegctl --link takes them.
    std::string ground_link() const;
    std::string ground_port(int pair = 0) const;

    // ---- faults ------------------------------------------------------------------------------------------
    ControlClient& sim() { return *sim_control_; }
    ControlClient& link(int pair = 0) { return *link_control_.at(static_cast<std::size_t>(pair)); }

    // ---- the daemon --------------------------------------------------------------------------------------
    void start_daemon();
    void stop_daemon();  // SIGTERM, waits for exit 0
    void kill_daemon();  // SIGKILL
    bool daemon_running() { return daemon_ && daemon_->running(); }
    pid_t daemon_pid() const { return daemon_ ? daemon_->pid() : -1; }
    std::string daemon_err() const { return daemon_ ? daemon_->err() : std::string(); }
    /// The daemon's state_dir and (with tmpfs_kb) the tmpfs seen from this process (/proc/PID/root/...).
    std::string state_dir() const;
    std::string tmpfs_dir() const { return dir_.file("vol"); }

    /// Everything the processes said, for a failure message.
    std::string logs() const;
    TempDir& dir() { return dir_; }
    const BenchOptions& options() const { return options_; }

  private:
    void start_link(int pair);
    void start_sim();

    BenchOptions options_;
    TempDir dir_;
    std::vector<std::unique_ptr<Subprocess>> links_;
    std::vector<std::unique_ptr<ControlClient>> link_control_;
    std::unique_ptr<Subprocess> sim_;
    std::unique_ptr<ControlClient> sim_control_;
    std::unique_ptr<Subprocess> daemon_;
    std::string key_file_;
};

}  // namespace airseg::test

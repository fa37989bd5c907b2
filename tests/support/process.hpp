#pragma once
// Test support: run the real binaries as child processes and wait on conditions with generous timeouts.
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/ports.hpp"
#include "tests/support/tree_paths.hpp"

namespace airseg::test {

using namespace std::chrono_literals;

/// Polls `condition` until it holds or `timeout` passes; never a fixed sleep in a test.
bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 10s,
                std::chrono::milliseconds poll = 10ms);

/// Wall-clock seconds since `t`, for the figures tests print.
inline double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// A unique temporary directory, removed with everything in it.
class TempDir {
  public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::string& path() const { return path_; }
    std::string file(const std::string& name) const { return path_ + "/" + name; }

  private:
    std::string path_;
};

std::string read_file(const std::string& path);
void write_file(const std::string& path, const std::string& text);

/// Path of a binary built in this tree, e.g. binary("daemon/airsegd").
std::string binary(const std::string& relative);
std::string source_path(const std::string& relative);

/// airsegd's `--set`s for a ground link without a key: the shipped configuration names the installed key
/// (/etc/airseg/ground.key), which a test machine does not have, and a daemon without a key refuses every
/// command from the ground unless groundlink.insecure says otherwise.
inline std::vector<std::string> unkeyed_ground_link() {
    return {"--set", "groundlink.key_file=", "--set", "groundlink.insecure=true"};
}

class Subprocess {
  public:
    /// Starts argv[0] with argv; `env` entries are added to (or replace) the test's environment. stdout and
    /// stderr go to files in `log_dir` named after the program.
    Subprocess(std::vector<std::string> argv, std::map<std::string, std::string> env,
               const std::string& log_dir);
    ~Subprocess();  // SIGKILLs a process still running
    Subprocess(const Subprocess&) = delete;
    Subprocess& operator=(const Subprocess&) = delete;

    pid_t pid() const { return pid_; }
    void signal(int signo) const;
    /// Waits for exit; returns the exit code (128+signal when killed), or nullopt on timeout (and then
    /// records where the process was: stuck()).
    std::optional<int> wait_exit(std::chrono::milliseconds timeout);
    bool running();
    std::string out() const;
    std::string err() const;
    /// Where each thread of the running process is now: its state, the kernel function it waits in, and its
    /// kernel stack where /proc shows it (root). Empty once the process has exited.
    std::string where();
    /// where() as it was when a wait_exit() last timed out; empty when none did.
    const std::string& stuck() const { return stuck_; }

  private:
    pid_t pid_ = -1;
    std::optional<int> exit_code_;
    std::string stuck_;
    std::string out_path_;
    std::string err_path_;
};

/// Runs a command to completion and returns {exit code, stdout, stderr}.
struct RunResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};
RunResult run(std::vector<std::string> argv, std::map<std::string, std::string> env = {},
              std::chrono::milliseconds timeout = 30s);

/// A datagram socket standing in for systemd's NOTIFY_SOCKET: records every message sd_notify sends.
class NotifyListener {
  public:
    struct Message {
        std::chrono::steady_clock::time_point at;
        std::string text;
    };
    explicit NotifyListener(const std::string& path);
    ~NotifyListener();
    NotifyListener(const NotifyListener&) = delete;
    NotifyListener& operator=(const NotifyListener&) = delete;
    const std::string& path() const { return path_; }
    /// Waits until a message contains `needle`; returns its arrival time. Messages are read as they arrive,
    /// on a thread of the listener's own.
    std::optional<std::chrono::steady_clock::time_point> wait_for(const std::string& needle,
                                                                  std::chrono::milliseconds timeout,
                                                                  std::size_t from_index = 0);
    std::vector<Message> messages() const;
    std::size_t count(const std::string& needle, std::size_t from_index = 0) const;

  private:
    void read_until_stopped();

    std::string path_;
    int fd_ = -1;
    mutable std::mutex mutex_;
    std::vector<Message> messages_;
    std::atomic<bool> stop_{false};
    std::thread reader_;
};

}  // namespace airseg::test

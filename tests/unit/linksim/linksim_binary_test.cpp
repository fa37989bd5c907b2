// Runs the real airseg-linksim binary on real pseudo-terminals.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/process.hpp"

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;

const std::string kBinary = ::airseg::test::binary_dir() + "/tools/linksim/airseg-linksim";

using airseg::test::wait_until;

bool exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

std::string read_all(int fd) {
    std::string out;
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n <= 0) {
            return out;
        }
        out.append(buf, static_cast<std::size_t>(n));
    }
}

class TempDir {
  public:
    TempDir() {
        char name[] = "/tmp/airseg-linksim-test-XXXXXX";
        if (::mkdtemp(name) != nullptr) {
            path_ = name;
        }
    }
    ~TempDir() {
        for (const char* leaf : {"/a", "/b", "/ctl", "/client", "/a.new", "/b.new"}) {
            ::unlink((path_ + leaf).c_str());
        }
        ::rmdir(path_.c_str());
    }
    std::string operator/(const char* leaf) const { return path_ + "/" + leaf; }

  private:
    std::string path_;
};

// The emulator as a child process with its stdout and stderr captured.
class LinkSim {
  public:
    explicit LinkSim(const std::vector<std::string>& args) {
        int out[2];
        int err[2];
        if (::pipe(out) != 0 || ::pipe(err) != 0) {
            return;
        }
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
        posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
        posix_spawn_file_actions_addclose(&actions, out[0]);
        posix_spawn_file_actions_addclose(&actions, err[0]);
        std::vector<std::string> all{kBinary};
        all.insert(all.end(), args.begin(), args.end());
        std::vector<char*> argv;
        for (auto& a : all) {
            argv.push_back(a.data());
        }
        argv.push_back(nullptr);
        if (::posix_spawn(&pid_, kBinary.c_str(), &actions, nullptr, argv.data(), environ) != 0) {
            pid_ = -1;
        }
        posix_spawn_file_actions_destroy(&actions);
        ::close(out[1]);
        ::close(err[1]);
        stdout_ = out[0];
        stderr_ = err[0];
    }
    ~LinkSim() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        ::close(stdout_);
        ::close(stderr_);
    }
    LinkSim(const LinkSim&) = delete;
    LinkSim& operator=(const LinkSim&) = delete;

    bool started() const { return pid_ > 0; }

    /// Sends `sig` (none: just waits) and returns the exit status, or -1 if it does not exit in time.
    int finish(int sig) {
        if (sig != 0) {
            ::kill(pid_, sig);
        }
        int status = 0;
        const bool exited = wait_until([&] { return ::waitpid(pid_, &status, WNOHANG) == pid_; });
        if (!exited) {
            return -1;
        }
        pid_ = -1;
        out_ = read_all(stdout_);
        err_ = read_all(stderr_);
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    const std::string& out() const { return out_; }
    const std::string& err() const { return err_; }

  private:
    pid_t pid_ = -1;
    int stdout_ = -1;
    int stderr_ = -1;
    std::string out_;
    std::string err_;
};

class RawTty {
  public:
    explicit RawTty(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK)) {
        termios t{};
        if (fd_ >= 0 && ::tcgetattr(fd_, &t) == 0) {
            ::cfmakeraw(&t);
            ::tcsetattr(fd_, TCSANOW, &t);
        }
    }
    ~RawTty() {
        if (fd_ >= 0) {
            ::close(fd_);
        }
    }
    RawTty(const RawTty&) = delete;
    RawTty& operator=(const RawTty&) = delete;

    bool ok() const { return fd_ >= 0; }
    bool write_all(const std::vector<std::uint8_t>& bytes) const {
        std::size_t done = 0;
        return wait_until([&] {
            const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
            if (n > 0) {
                done += static_cast<std::size_t>(n);
            }
            return done == bytes.size();
        });
    }
    void drain_into(std::vector<std::uint8_t>& out) const {
        std::uint8_t buf[1024];
        for (ssize_t n; (n = ::read(fd_, buf, sizeof buf)) > 0;) {
            out.insert(out.end(), buf, buf + n);
        }
    }

  private:
    int fd_;
};

// A datagram client of the emulator's control socket.
class Control {
  public:
    Control(const std::string& server, const std::string& self) : server_(server), self_(self) {
        fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr = address(self_);
        ::unlink(self_.c_str());
        ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
    }
    ~Control() {
        ::close(fd_);
        ::unlink(self_.c_str());
    }
    Control(const Control&) = delete;
    Control& operator=(const Control&) = delete;

    std::string ask(const std::string& command) const {
        sockaddr_un to = address(server_);
        if (::sendto(fd_, command.data(), command.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to) <
            0) {
            return "send failed: " + std::string(std::strerror(errno));
        }
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 10'000) != 1) {
            return "no reply";
        }
        char buf[8192];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : "empty reply";
    }
    nlohmann::json stats() const { return nlohmann::json::parse(ask("stats"), nullptr, false); }

  private:
    static sockaddr_un address(const std::string& path) {
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
        return a;
    }
    int fd_ = -1;
    std::string server_;
    std::string self_;
};

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t salt) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>(i * 37 + salt);
    }
    return v;
}

bool peers_connected(const Control& control) {
    const auto s = control.stats();
    return s.is_object() && s["a"]["peer_connected"] == true && s["b"]["peer_connected"] == true;
}

TEST(LinkSimBinary, CarriesBytesBothWaysAtTheSerialRateAndReportsOnExit) {
    TempDir dir;
    LinkSim sim({"--a", dir / "a", "--b", dir / "b", "--baud", "9600", "--control", dir / "ctl", "--json"});
    ASSERT_TRUE(sim.started());
    ASSERT_TRUE(wait_until([&] { return exists(dir / "a") && exists(dir / "b") && exists(dir / "ctl"); }));
    RawTty a(dir / "a");
    RawTty b(dir / "b");
    ASSERT_TRUE(a.ok() && b.ok());
    Control control(dir / "ctl", dir / "client");
    ASSERT_TRUE(wait_until([&] { return peers_connected(control); }));

    const auto sent = pattern(480, 1);
    const auto start = Clock::now();
    ASSERT_TRUE(a.write_all(sent));
    std::vector<std::uint8_t> got;
    ASSERT_TRUE(wait_until([&] {
        b.drain_into(got);
        return got.size() >= sent.size();
    })) << "received "
        << got.size() << "; emulator: " << control.stats().dump();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    EXPECT_EQ(got, sent);
    // 480 bytes at 960 bytes/s cannot take less than half a second.
    EXPECT_GE(elapsed, 0.45);

    const auto back = pattern(100, 2);
    ASSERT_TRUE(b.write_all(back));
    std::vector<std::uint8_t> got_back;
    ASSERT_TRUE(wait_until([&] {
        a.drain_into(got_back);
        return got_back.size() >= back.size();
    }));
    EXPECT_EQ(got_back, back);

    ASSERT_EQ(sim.finish(SIGTERM), 0) << sim.err();
    const auto stats = nlohmann::json::parse(sim.out(), nullptr, false);
    ASSERT_TRUE(stats.is_object()) << sim.out();
    EXPECT_EQ(stats["ab"]["bytes_in"], 480);
    EXPECT_EQ(stats["ab"]["bytes_out"], 480);
    EXPECT_EQ(stats["ba"]["bytes_out"], 100);
    EXPECT_EQ(stats["ab"]["overflow_dropped"], 0);
    EXPECT_FALSE(exists(dir / "a")) << "the symlink outlived the emulator";
}

TEST(LinkSimBinary, ControlSocketInjectsFaultsAtRunTime) {
    TempDir dir;
    LinkSim sim({"--a", dir / "a", "--b", dir / "b", "--baud", "57600", "--control", dir / "ctl"});
    ASSERT_TRUE(sim.started());
    ASSERT_TRUE(wait_until([&] { return exists(dir / "a") && exists(dir / "b") && exists(dir / "ctl"); }));
    RawTty a(dir / "a");
    RawTty b(dir / "b");
    Control control(dir / "ctl", dir / "client");
    ASSERT_TRUE(wait_until([&] { return peers_connected(control); }));

    EXPECT_EQ(control.ask("loss 1 ab").rfind("ok", 0), 0u);
    EXPECT_EQ(control.ask("loss 2 ab").rfind("error", 0), 0u);
    EXPECT_EQ(control.ask("frobnicate").rfind("error", 0), 0u);
    ASSERT_TRUE(a.write_all(pattern(200, 3)));
    ASSERT_TRUE(wait_until([&] { return control.stats()["ab"]["bytes_lost"] == 200; }));
    std::vector<std::uint8_t> got;
    b.drain_into(got);
    EXPECT_TRUE(got.empty());

    EXPECT_EQ(control.ask("loss 0"), "ok loss 0\n");
    const auto sent = pattern(50, 4);
    ASSERT_TRUE(a.write_all(sent));
    ASSERT_TRUE(wait_until([&] {
        b.drain_into(got);
        return got.size() >= sent.size();
    }));
    EXPECT_EQ(got, sent);

    EXPECT_EQ(control.ask("down b").rfind("ok", 0), 0u);
    ASSERT_TRUE(a.write_all(pattern(30, 5)));
    ASSERT_TRUE(wait_until([&] { return control.stats()["ab"]["outage_packets_lost"] >= 1; }));

    ASSERT_EQ(sim.finish(SIGINT), 0) << sim.err();
    EXPECT_NE(sim.out().find("a->b"), std::string::npos) << sim.out();
}

TEST(LinkSimBinary, RejectsABadOptionNamingIt) {
    TempDir dir;
    LinkSim sim({"--a", dir / "a", "--b", dir / "b", "--frame-loss-ba", "1.5"});
    ASSERT_TRUE(sim.started());
    EXPECT_EQ(sim.finish(0), 2);
    EXPECT_NE(sim.err().find("--frame-loss-ba"), std::string::npos) << sim.err();
    EXPECT_FALSE(exists(dir / "a"));
}

}  // namespace

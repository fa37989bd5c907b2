// Security over the radio, with the real binaries: frames forged with the wrong key and frames recorded and
// replayed are rejected, counted in status, and never run a command. A relay between airsegctl and the
// radio's ground end records what the ground sent, as an attacker's receiver in range would.
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "tests/system/system_checks.hpp"

namespace airseg::test::sys {
namespace {

void make_raw(int fd) {
    termios t{};
    ASSERT_EQ(::tcgetattr(fd, &t), 0);
    ::cfmakeraw(&t);
    ::cfsetspeed(&t, B57600);
    ASSERT_EQ(::tcsetattr(fd, TCSANOW, &t), 0);
}

/// A pty for airsegctl whose bytes are relayed to and from the radio's ground end; what the ground sends is
/// recorded.
class RecordingRelay {
  public:
    explicit RecordingRelay(const std::string& radio_port) {
        radio_ = ::open(radio_port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
        EXPECT_GE(radio_, 0) << radio_port;
        make_raw(radio_);
        char name[256] = {};
        EXPECT_EQ(::openpty(&master_, &holder_, name, nullptr, nullptr), 0);
        client_path_ = name;
        make_raw(holder_);  // kept open, never read: the master never sees a hangup between clients
        ::fcntl(master_, F_SETFL, O_NONBLOCK);
        thread_ = std::thread([this] { run(); });
    }
    ~RecordingRelay() {
        stop_ = true;
        thread_.join();
        for (int fd : {radio_, master_, holder_}) {
            ::close(fd);
        }
    }
    const std::string& client_path() const { return client_path_; }
    std::vector<std::uint8_t> uplink() {
        std::lock_guard lock(mutex_);
        return uplink_;
    }
    /// Writes `bytes` into the radio as if the ground sent them again.
    void inject(const std::vector<std::uint8_t>& bytes) {
        std::lock_guard lock(mutex_);
        pending_.insert(pending_.end(), bytes.begin(), bytes.end());
    }

  private:
    void run() {
        std::uint8_t buf[4096];
        while (!stop_) {
            pollfd fds[2] = {{master_, POLLIN, 0}, {radio_, POLLIN, 0}};
            ::poll(fds, 2, 20);
            if (fds[0].revents & POLLIN) {
                const auto n = ::read(master_, buf, sizeof buf);
                if (n > 0) {
                    std::lock_guard lock(mutex_);
                    uplink_.insert(uplink_.end(), buf, buf + n);
                    pending_.insert(pending_.end(), buf, buf + n);
                }
            }
            if (fds[1].revents & POLLIN) {
                const auto n = ::read(radio_, buf, sizeof buf);
                if (n > 0) {
                    write_all(master_, buf, static_cast<std::size_t>(n));
                }
            }
            std::vector<std::uint8_t> out;
            {
                std::lock_guard lock(mutex_);
                out.swap(pending_);
            }
            write_all(radio_, out.data(), out.size());
        }
    }
    void write_all(int fd, const std::uint8_t* p, std::size_t n) {
        while (n > 0 && !stop_) {
            const auto w = ::write(fd, p, n);
            if (w > 0) {
                p += w;
                n -= static_cast<std::size_t>(w);
            } else {
                pollfd f{fd, POLLOUT, 0};
                ::poll(&f, 1, 20);
            }
        }
    }

    int radio_ = -1, master_ = -1, holder_ = -1;
    std::string client_path_;
    std::thread thread_;
    std::atomic<bool> stop_{false};
    std::mutex mutex_;
    std::vector<std::uint8_t> uplink_, pending_;
};

RunResult ctl_through(const std::string& port, const std::string& key, std::vector<std::string> args,
                      long timeout_ms) {
    std::vector<std::string> argv{binary("client/airsegctl"), "--link", port, "--key", key, "--timeout",
                                  std::to_string(timeout_ms), "--json"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv, {}, std::chrono::milliseconds(timeout_ms + 60'000));
}

Json ground(SystemBench& bench) {
    return section(bench.status(), "groundlink");
}

TEST(SystemSecurity, FramesForgedWithTheWrongKeyAreRejectedCountedAndRunNothing) {
    BenchOptions keyed;
    keyed.key = true;
    SystemBench bench(keyed);
    const auto wrong_key = bench.dir().file("wrong.key");
    write_file(wrong_key, std::string(64, 'd') + "\n");
    ASSERT_EQ(::chmod(wrong_key.c_str(), 0600), 0);
    ASSERT_TRUE(wait_until([&] { return !bench.status().empty(); }, kGenerous, kPoll)) << bench.logs();
    const auto before = ground(bench);
    {
        RecordingRelay relay(bench.ground_port());
        const auto r = ctl_through(relay.client_path(), wrong_key, {"rates", "vehicle=3.3"}, 8000);
        EXPECT_EQ(r.exit_code, 3) << "the vehicle must not answer a ground station with the wrong key: "
                                  << r.out << r.err;
        EXPECT_FALSE(relay.uplink().empty()) << "the forger sent nothing";
        ASSERT_TRUE(wait_until(
            [&] { return ground(bench).value("mac_failures", 0) > before.value("mac_failures", 0); },
            kGenerous, kPoll))
            << ground(bench).dump();
    }
    const auto after = ground(bench);
    EXPECT_EQ(after.value("commands", 0), before.value("commands", 0)) << "a forged command ran";
    std::cout << "[ figures ] forged: " << after.value("mac_failures", 0) - before.value("mac_failures", 0)
              << " frames rejected by their MAC, 0 commands run\n";

    // The rightful ground station still gets through.
    CommandTally tally;
    const auto commands_before = ground_commands(bench);
    send_unique(bench, 1, tally);
    expect_each_answered_once(tally, commands_before, ground_commands(bench));
    expect_daemon_alive(bench);
}

TEST(SystemSecurity, ReplayedFramesAreRejectedCountedAndRunNothingTwice) {
    BenchOptions keyed;
    keyed.key = true;
    SystemBench bench(keyed);
    ASSERT_TRUE(wait_until([&] { return !bench.status().empty(); }, kGenerous, kPoll)) << bench.logs();
    const auto key = bench.dir().file("ground.key");
    RecordingRelay relay(bench.ground_port());
    const auto r = ctl_through(relay.client_path(), key, {"rates", "vehicle=4.4"}, 30'000);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err << bench.logs();
    const auto recording = relay.uplink();
    ASSERT_FALSE(recording.empty());
    const auto before = ground(bench);
    ASSERT_EQ(before.value("commands", 0), 1) << before.dump();

    // The attacker plays the whole recording (hello, command, acknowledgements) back into the radio, twice.
    relay.inject(recording);
    relay.inject(recording);
    ASSERT_TRUE(wait_until([&] { return ground(bench).value("replays", 0) > before.value("replays", 0); },
                           kGenerous, kPoll))
        << ground(bench).dump();
    // Until the radio has carried it all (57600 baud): the counter stops moving.
    std::uint64_t last = 0;
    wait_until(
        [&] {
            const std::uint64_t now = ground(bench).value("replays", 0);
            const bool settled = now == last;
            last = now;
            return settled;
        },
        kGenerous, std::chrono::milliseconds(1500));
    const auto after = ground(bench);
    EXPECT_EQ(after.value("commands", 0), before.value("commands", 0)) << "a replayed command ran again";
    std::cout << "[ figures ] replayed " << 2 * recording.size()
              << " bytes: " << after.value("replays", 0) - before.value("replays", 0)
              << " frames rejected as replays, "
              << after.value("mac_failures", 0) - before.value("mac_failures", 0) << " by their MAC, "
              << after.value("commands", 0) - before.value("commands", 0) << " commands run\n";
    expect_daemon_alive(bench);
}

}  // namespace
}  // namespace airseg::test::sys

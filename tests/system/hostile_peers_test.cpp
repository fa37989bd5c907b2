// Hostile peers against the real airsegd, as systemd runs it (a real NOTIFY_SOCKET, a 1 s watchdog): local
// clients that connect and say nothing or never read, and an "autopilot" on a pty of the test's own that
// floods parameter names, reports a position off the globe and makes the daemon log on every frame. In each
// case the bound holds (counted in status), the daemon's memory comes back within 2 MB, status is answered
// within 1 s throughout, and the watchdog pings never stop.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "client/local_client.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

namespace mav = airseg::mavlink;
using Json = nlohmann::json;

#ifdef AIRSEG_SLOWED_BUILD
constexpr bool kMeasuredChecks = false;  // RSS and answer times are printed, not checked (CMakeLists.txt)
#else
constexpr bool kMeasuredChecks = true;
#endif
constexpr auto kWatchdogPeriod = 1000ms;
// The longest gap between pings the case accepts. On the board it is the period systemd enforces. Under an
// emulator on CI's loaded machine the daemon's threads have been seen unscheduled for 2.7 s (armel, a flood
// that takes 3.2 s and never gaps over 0.26 s on a quiet machine or beside two nice-19 compiles; the daemon
// does no disk I/O in it), so there the gap is printed and held only to a bound a hung service would still
// break: a stuck service stops the pings for good, which the "pings have stopped" check sees as well.
constexpr auto kLongestPingGap = kMeasuredChecks ? kWatchdogPeriod : 5 * kWatchdogPeriod;
constexpr auto kAnswerWithin = 1000ms;
constexpr long kRssSlackKb = 2048;

/// The autopilot end of a pty the daemon opens as its autopilot port: heartbeats at 2 Hz, whatever the test
/// queues, and everything the daemon sends read and dropped.
class FakeAutopilot {
  public:
    explicit FakeAutopilot(const std::string& link) {
        char name[256] = {};
        EXPECT_EQ(::openpty(&master_, &holder_, name, nullptr, nullptr), 0);
        termios t{};
        ::tcgetattr(holder_, &t);
        ::cfmakeraw(&t);
        ::tcsetattr(holder_, TCSANOW, &t);
        ::fcntl(master_, F_SETFL, O_NONBLOCK);
        std::filesystem::create_symlink(name, link);
        thread_ = std::thread([this] { run(); });
    }
    ~FakeAutopilot() {
        stop_ = true;
        thread_.join();
        ::close(master_);
        ::close(holder_);
    }
    void queue(std::vector<std::uint8_t> bytes) {
        std::lock_guard lock(mutex_);
        pending_.insert(pending_.end(), bytes.begin(), bytes.end());
    }
    template <class M>
    void send(const M& m) {
        std::lock_guard lock(mutex_);
        const auto bytes = encoder_.encode(m);
        pending_.insert(pending_.end(), bytes.begin(), bytes.end());
    }
    /// Everything queued has been written to the pty.
    bool drained() {
        std::lock_guard lock(mutex_);
        return pending_.empty();
    }
    void set_heartbeat_mode(std::uint32_t mode) { mode_ = mode; }

  private:
    void run() {
        auto next_heartbeat = std::chrono::steady_clock::now();
        std::uint8_t sink[4096];
        while (!stop_) {
            if (std::chrono::steady_clock::now() >= next_heartbeat) {
                mav::Heartbeat hb;
                hb.type = 10;      // ground rover
                hb.autopilot = 3;  // ArduPilot
                hb.base_mode = 1;
                hb.custom_mode = mode_;
                hb.system_status = 4;  // active
                hb.mavlink_version = 3;
                send(hb);
                next_heartbeat += 500ms;
            }
            while (::read(master_, sink, sizeof sink) > 0) {
            }
            std::vector<std::uint8_t> chunk;
            {
                std::lock_guard lock(mutex_);
                const std::size_t n = std::min<std::size_t>(pending_.size(), 65536);
                chunk.assign(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n));
            }
            std::size_t written = 0;
            if (!chunk.empty()) {
                const auto n = ::write(master_, chunk.data(), chunk.size());
                written = n > 0 ? static_cast<std::size_t>(n) : 0;
                std::lock_guard lock(mutex_);
                pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(written));
            }
            if (written == 0) {
                pollfd p{master_, static_cast<short>(chunk.empty() ? POLLIN : POLLIN | POLLOUT), 0};
                ::poll(&p, 1, 20);
            }
        }
    }

    int master_ = -1;
    int holder_ = -1;  // the slave kept open here too: the master never sees a hangup when the daemon reopens
    mav::Encoder encoder_{1, 1};  // under mutex_: the test's thread and the heartbeats share it
    std::mutex mutex_;
    std::deque<std::uint8_t> pending_;
    std::atomic<std::uint32_t> mode_{0};
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

/// One raw connection to the local socket.
class RawClient {
  public:
    explicit RawClient(const std::string& path) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    }
    ~RawClient() { ::close(fd_); }
    RawClient(const RawClient&) = delete;
    RawClient& operator=(const RawClient&) = delete;
    bool connected() const { return connected_; }
    /// Sends what the socket takes now; false once the daemon has closed it.
    bool send_some(const std::string& text, std::size_t& count) {
        for (;;) {
            const ssize_t n = ::send(fd_, text.data(), text.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
            if (n == static_cast<ssize_t>(text.size())) {
                ++count;
                continue;
            }
            return n >= 0 || errno == EAGAIN;
        }
    }

  private:
    int fd_ = -1;
    bool connected_ = false;
};

long rss_kb(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/status");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("VmRSS:", 0) == 0) {
            return std::stol(line.substr(6));
        }
    }
    return -1;
}

class HostilePeers : public ::testing::Test {
  protected:
    HostilePeers() : notify(dir.file("notify.sock")), autopilot(dir.file("ttyACM0")) {}
    ~HostilePeers() override { stop_watching(); }

    void start_daemon() {
        daemon = std::make_unique<Subprocess>(
            std::vector<std::string>{binary("daemon/airsegd"), "--config", source_path("config/airseg.yaml"),
                                     "--set", "status.socket=" + socket(), "--set",
                                     "state_dir=" + dir.file("state"), "--set",
                                     "autopilot.port=" + dir.file("ttyACM0"), "--set",
                                     "groundlink.ports=[" + dir.file("ttyUSB0") + "]", "--set",
                                     "groundlink.key_file=", "--set", "groundlink.insecure=true"},
            std::map<std::string, std::string>{
                {"NOTIFY_SOCKET", notify.path()},
                {"WATCHDOG_USEC", std::to_string(kWatchdogPeriod.count() * 1000)}},
            dir.path());
        ASSERT_TRUE(notify.wait_for("READY=1", 20s)) << daemon->err();
        ASSERT_TRUE(wait_until([&] { return status().contains("autopilot"); }, 20s)) << daemon->err();
        // The autopilot's heartbeats have been seen: its frames are being read.
        ASSERT_TRUE(wait_until([&] { return status()["autopilot"]["link"] == "up"; }, 20s)) << daemon->err();
        start_watching();
    }
    std::string socket() const { return dir.file("status.sock"); }

    Json status() {
        client::LocalClient c(socket(), 5s);
        auto a = c.request({{"cmd", "status"}});
        if (!a.answer || !a.answer->value("ok", false)) {
            return Json::object();
        }
        return (*a.answer)["result"];
    }

    /// From now on, status is asked for every 100 ms on a connection of its own (a watcher would keep
    /// one), each answer timed.
    void start_watching() {
        watching_ = true;
        watch_started_ = std::chrono::steady_clock::now();
        watcher_ = std::thread([this] {
            client::LocalClient c(socket(), 5s);
            while (watching_) {
                const auto asked = std::chrono::steady_clock::now();
                const auto a = c.request({{"cmd", "status"}});
                const auto took = std::chrono::steady_clock::now() - asked;
                {
                    std::lock_guard lock(watch_mutex_);
                    ++probes_;
                    slowest_ =
                        std::max(slowest_, std::chrono::duration_cast<std::chrono::milliseconds>(took));
                    if (!a.answer) {
                        failures_.push_back(a.error);
                    }
                }
                std::this_thread::sleep_for(100ms);
            }
        });
        // A watcher is one that has polled: the case's peers come after its first answer.
        ASSERT_TRUE(wait_until(
            [&] {
                std::lock_guard lock(watch_mutex_);
                return probes_ > 0;
            },
            20s));
    }
    void stop_watching() {
        watching_ = false;
        if (watcher_.joinable()) {
            watcher_.join();
        }
    }
    /// Status answered within 1 s every time, and no gap between watchdog pings longer than the period.
    void expect_answering_and_pinging() {
        // Watched over a few watchdog periods at least, however quick the case was.
        EXPECT_TRUE(wait_until(
            [&] {
                std::size_t pings = 0;
                for (const auto& m : notify.messages()) {
                    pings += m.at >= watch_started_ && m.text.find("WATCHDOG=1") != std::string::npos ? 1 : 0;
                }
                return pings >= 8;
            },
            20s))
            << "fewer than 8 watchdog pings since the case began";
        stop_watching();
        {
            std::lock_guard lock(watch_mutex_);
            EXPECT_GT(probes_, 0u);
            EXPECT_TRUE(failures_.empty())
                << failures_.size()
                << " status requests unanswered, first: " << (failures_.empty() ? "" : failures_.front());
            if (kMeasuredChecks) {
                EXPECT_LT(slowest_, kAnswerWithin) << "the slowest status answer";
            }
            std::cout << "[ figures ] status: " << probes_ << " answers, slowest " << slowest_.count()
                      << " ms\n";
        }
        std::chrono::steady_clock::time_point last{};
        std::chrono::milliseconds longest{0};
        for (const auto& m : notify.messages()) {
            if (m.text.find("WATCHDOG=1") == std::string::npos || m.at < watch_started_) {
                continue;
            }
            if (last != std::chrono::steady_clock::time_point{}) {
                longest =
                    std::max(longest, std::chrono::duration_cast<std::chrono::milliseconds>(m.at - last));
            }
            last = m.at;
        }
        EXPECT_NE(last, std::chrono::steady_clock::time_point{}) << "no watchdog ping at all";
        EXPECT_LT(std::chrono::steady_clock::now() - last, kWatchdogPeriod) << "the pings have stopped";
        EXPECT_LT(longest, kLongestPingGap) << "the longest gap between watchdog pings; the daemon's log:\n"
                                            << daemon->err();
        std::cout << "[ figures ] watchdog: longest gap between pings " << longest.count() << " ms (period "
                  << kWatchdogPeriod.count() << " ms, accepted below " << kLongestPingGap.count() << " ms)\n";
        EXPECT_TRUE(daemon->running()) << daemon->err();
    }
    /// RSS after the test's warm-up: what the daemon keeps once it has answered and run for a moment.
    long settled_rss() {
        for (int i = 0; i < 20; ++i) {
            (void)status();
        }
        std::this_thread::sleep_for(300ms);
        return rss_kb(daemon->pid());
    }
    std::size_t err_lines() const {
        const auto text = daemon->err();
        return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
    }

    TempDir dir;
    NotifyListener notify;
    FakeAutopilot autopilot;
    std::unique_ptr<Subprocess> daemon;

  private:
    std::atomic<bool> watching_{false};
    std::thread watcher_;
    std::mutex watch_mutex_;
    std::size_t probes_ = 0;
    std::chrono::milliseconds slowest_{0};
    std::vector<std::string> failures_;
    std::chrono::steady_clock::time_point watch_started_{};
};

TEST_F(HostilePeers, IdleLocalClientsCannotLockTheSocketAndAStatusIsAnsweredWithinOneSecond) {
    start_daemon();
    std::vector<std::unique_ptr<RawClient>> idle;
    for (int i = 0; i < 20; ++i) {
        idle.push_back(std::make_unique<RawClient>(socket()));
        ASSERT_TRUE(idle.back()->connected());
    }
    ASSERT_TRUE(wait_until([&] { return status()["status"]["local_socket"]["evicted"].get<int>() >= 4; }))
        << status().dump();
    const auto asked = std::chrono::steady_clock::now();
    client::LocalClient fresh(socket(), 10s);
    const auto a = fresh.request({{"cmd", "status"}});
    ASSERT_TRUE(a.answer) << a.error;
    if (kMeasuredChecks) {
        EXPECT_LT(std::chrono::steady_clock::now() - asked, kAnswerWithin);
    }
    const auto s = status()["status"]["local_socket"];
    EXPECT_LE(s["clients"].get<int>(), 16);
    EXPECT_EQ(s["refused"], 0);
    std::cout << "[ figures ] local socket: " << s.dump() << "\n";
    expect_answering_and_pinging();
}

TEST_F(HostilePeers, AClientThatPipelinesStatusAndNeverReadsIsClosedAndTheMemoryComesBack) {
    start_daemon();
    const long before = settled_rss();
    {
        RawClient greedy(socket());
        ASSERT_TRUE(greedy.connected());
        std::size_t sent = 0;
        const std::string request = "{\"cmd\":\"status\"}\n";
        bool open = true;
        ASSERT_TRUE(wait_until(
            [&] {
                open = open && greedy.send_some(request, sent);
                return !open || status()["status"]["local_socket"]["closed_slow"].get<int>() >= 1;
            },
            60s))
            << "sent " << sent << " requests";
        std::cout << "[ figures ] pipelining client closed after " << sent << " requests sent\n";
    }
    EXPECT_EQ(status()["status"]["local_socket"]["closed_slow"], 1);
    const long after = settled_rss();
    std::cout << "[ figures ] RSS " << before << " kB before, " << after << " kB after\n";
    if (kMeasuredChecks) {
        EXPECT_LT(after - before, kRssSlackKb);
    }
    expect_answering_and_pinging();
}

TEST_F(HostilePeers, AParamValueFloodWithNewNamesIsBoundedCountedAndCostsNoMemory) {
    start_daemon();
    const long before = settled_rss();
    constexpr int kNames = 100'000;
    constexpr std::uint16_t kAnnounced = 1000;
    for (int i = 0; i < kNames; ++i) {
        mav::ParamValue v;
        mav::set_text(v.param_id, "FLOOD" + std::to_string(i));
        v.param_count = kAnnounced;
        v.param_index = 65535;
        v.param_value = static_cast<float>(i);
        v.param_type = 9;
        autopilot.send(v);
    }
    ASSERT_TRUE(wait_until(
        [&] {
            const auto p = status()["autopilot"]["params"];
            return p.is_object() && p["cached"].get<int>() + p["dropped"].get<int>() >= kNames;
        },
        60s))
        << status()["autopilot"].dump();
    const auto p = status()["autopilot"]["params"];
    EXPECT_EQ(p["announced"], kAnnounced);
    EXPECT_LE(p["cached"].get<int>(), kAnnounced);
    EXPECT_GE(p["dropped"].get<int>(), kNames - kAnnounced);
    const long after = settled_rss();
    std::cout << "[ figures ] params " << p.dump() << "; RSS " << before << " kB before, " << after
              << " kB after\n";
    if (kMeasuredChecks) {
        EXPECT_LT(after - before, kRssSlackKb);
    }
    expect_answering_and_pinging();

    // Killed and started again after it, the daemon answers within 2 s.
    daemon->signal(SIGKILL);
    ASSERT_TRUE(daemon->wait_exit(5s));
    const auto restarted = std::chrono::steady_clock::now();
    daemon.reset();
    start_daemon();
    std::cout << "[ figures ] answering "
              << std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() -
                                                                       restarted)
                     .count()
              << " ms after the restart (heartbeats seen included)\n";
    if (kMeasuredChecks) {
        EXPECT_LT(std::chrono::steady_clock::now() - restarted, 2s);
    }
}

TEST_F(HostilePeers, APositionOffTheGlobeIsInvalidInStatusNeverAPlace) {
    start_daemon();
    auto position = [&](double lat, double lon) {
        mav::GlobalPositionInt g;
        g.time_boot_ms = 1000;
        g.lat = static_cast<std::int32_t>(std::lround(lat * 1e7));
        g.lon = static_cast<std::int32_t>(std::lround(lon * 1e7));
        g.alt = 12'000;
        g.hdg = 65535;
        autopilot.send(g);
    };
    position(41.2756, 1.9866);
    ASSERT_TRUE(wait_until([&] { return status()["autopilot"]["position"].is_object(); }));
    position(199.17, 1.9866);
    ASSERT_TRUE(wait_until([&] { return status()["autopilot"]["position"].is_null(); }))
        << status()["autopilot"];
    const auto a = status()["autopilot"];
    EXPECT_EQ(a["position_invalid"], "latitude 199.1700000 outside ±90");
    EXPECT_EQ(a["refused_values"]["count"], 1);
    EXPECT_EQ(a["refused_values"]["last"], "GLOBAL_POSITION_INT: latitude 199.1700000 outside ±90");
    std::cout << "[ figures ] autopilot.position " << a["position"] << ", position_invalid "
              << a["position_invalid"] << "\n";
    position(41.2757, 1.9867);
    ASSERT_TRUE(wait_until([&] { return status()["autopilot"]["position"].is_object(); }));
    EXPECT_TRUE(status()["autopilot"]["position_invalid"].is_null());
    expect_answering_and_pinging();
}

TEST_F(HostilePeers, ALogFloodFromTheAutopilotIsHeldToAFewLinesAndSummarised) {
    start_daemon();
    const std::size_t lines_before = err_lines();
    const auto flood_began = std::chrono::steady_clock::now();
    // Mode flips on every frame: each is a vehicle state change the daemon logs, 20,000 of them; and a
    // time_boot_ms that jumps between 2^32-1 and 0, which reads as a reboot on every jump.
    constexpr int kFlips = 20'000;
    for (int i = 0; i < kFlips; ++i) {
        mav::Heartbeat hb;
        hb.type = 10;
        hb.autopilot = 3;
        hb.base_mode = 1;
        hb.custom_mode = i % 2 == 0 ? 4 : 0;  // HOLD, MANUAL
        hb.system_status = 4;
        hb.mavlink_version = 3;
        autopilot.send(hb);
        mav::GlobalPositionInt g;
        g.time_boot_ms = i % 2 == 0 ? 0xFFFFFFFFu : 0u;
        g.lat = 412'756'000;
        g.lon = 19'866'000;
        g.hdg = 65535;
        autopilot.send(g);
    }
    ASSERT_TRUE(wait_until([&] { return autopilot.drained(); }, 60s));
    ASSERT_TRUE(
        wait_until([&] { return status()["status"]["log_lines_held"].get<long>() >= kFlips / 2; }, 60s))
        << status()["status"].dump() << "\n"
        << daemon->err().substr(daemon->err().size() > 4000 ? daemon->err().size() - 4000 : 0);
    const std::size_t flood_lines = err_lines() - lines_before;
    std::cout << "[ figures ] " << flood_lines << " log lines for " << 2 * kFlips << " frames; held back "
              << status()["status"]["log_lines_held"] << "\n";
    // At most a burst and a summary per kind and 10 s, for the few kinds this flood touches (mode changed,
    // rebooted, ready, request results): 8 kinds are allowed for. Without the limiter: 30,004 lines.
    const auto windows = static_cast<std::size_t>(seconds_since(flood_began) / 10.0) + 2;
    EXPECT_LE(flood_lines, 8 * 6 * windows) << daemon->err();
    // Once the kind's period is over, the flood is summarised in one line.
    EXPECT_TRUE(wait_until(
        [&] { return daemon->err().find("more times in 10 s (not logged)") != std::string::npos; }, 20s))
        << daemon->err();
    expect_answering_and_pinging();
}

}  // namespace
}  // namespace airseg::test

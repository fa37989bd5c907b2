// Hostile files and texts against the real airsegd: plan paths that are not regular files (/dev/zero, a
// FIFO), plans whose texts are not UTF-8, a stored plan that no longer loads, configuration files that are
// not files or not text (a device, a FIFO, a directory, random bytes, a second document, a NUL, a 10 MB
// value, 100,000 unknown keys), and SIGHUP with a FIFO drop-in. After each: the daemon answers status within
// 1 s, its resident memory stays within 2 MB of its level before, its watchdog pings go on, and a kill -9 and
// restart has it answering again within 2 s. Most cases need no device at all; one drives the simulated
// autopilot.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "services/flightplan/persistence.hpp"
#include "tests/system/system_checks.hpp"

namespace airseg::test::sys {
namespace {

namespace fs = std::filesystem;

/// The plan of the field report: a name of one byte 0xff.
const std::string kBadNamePlan =
    "plan:\n  name: \"\xff\"\n  elements:\n    - {waypoint: {lat: 41.2757, lon: 1.9867}}\n";
/// An invalid byte in a key.
const std::string kBadKeyPlan =
    "plan:\n  name: k\n  elem\xe9nts:\n    - {waypoint: {lat: 41.2757, lon: 1.9867}}\n";

struct Answer {
    Json json;
    double seconds = 0;
};

/// One request on airsegd's local socket, timed; nullopt without an answer within `timeout`.
std::optional<Answer> ask(const std::string& socket_path, const Json& request,
                          std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
    const auto started = std::chrono::steady_clock::now();
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        return std::nullopt;
    }
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, socket_path.c_str(), sizeof addr.sun_path - 1);
    const std::string line = request.dump() + "\n";
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::send(fd, line.data(), line.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(line.size())) {
        ::close(fd);
        return std::nullopt;
    }
    std::string in;
    char buffer[65536];
    while (in.find('\n') == std::string::npos) {
        const auto left = timeout - (std::chrono::steady_clock::now() - started);
        pollfd p{fd, POLLIN, 0};
        if (left <= std::chrono::milliseconds(0) ||
            ::poll(&p, 1,
                   static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(left).count()) +
                       1) <= 0) {
            break;
        }
        const auto n = ::read(fd, buffer, sizeof buffer);
        if (n <= 0) {
            break;
        }
        in.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(fd);
    const auto nl = in.find('\n');
    if (nl == std::string::npos) {
        return std::nullopt;
    }
    auto j = Json::parse(in.substr(0, nl), nullptr, false);
    if (j.is_discarded()) {
        return std::nullopt;
    }
    return Answer{std::move(j), seconds_since(started)};
}

long rss_kb(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("VmRSS:", 0) == 0) {
            return std::stol(line.substr(6));
        }
    }
    return -1;
}

/// airsegd as systemd runs it, without devices (neither the autopilot's nor the radio's port exists).
// Under a sanitizer or an emulator (AIRSEG_SLOWED_BUILD) the programs run several times slower, and beside
// other suites on CI slower still: the time figures are printed there and checked in the shipped build.
#ifdef AIRSEG_SLOWED_BUILD
constexpr bool kSlowed = true;
#else
constexpr bool kSlowed = false;
#endif

class HostileFiles : public ::testing::Test {
  public:
    HostileFiles() : notify(dir.file("notify.sock")) {}

    std::vector<std::string> args(const std::string& config) const {
        return {binary("daemon/airsegd"),
                "--config",
                config,
                "--set",
                "status.socket=" + socket(),
                "--set",
                "state_dir=" + dir.file("state"),
                "--set",
                "autopilot.port=" + dir.file("ttyACM0"),
                "--set",
                "groundlink.ports=[" + dir.file("ttyUSB0") + "]",
                "--set",
                "groundlink.key_file=",
                "--set",
                "groundlink.insecure=true",
                "--set",
                "flightplan.fsync=false"};
    }
    std::string socket() const { return dir.file("status.sock"); }

    /// Starts the daemon and waits until it answers status; returns the seconds that took.
    double start(const std::string& config = source_path("config/airseg.yaml")) {
        const auto started = std::chrono::steady_clock::now();
        const auto from = notify.messages().size();
        daemon = std::make_unique<Subprocess>(
            args(config),
            std::map<std::string, std::string>{{"NOTIFY_SOCKET", notify.path()}, {"WATCHDOG_USEC", "400000"}},
            dir.path());
        EXPECT_TRUE(notify.wait_for("READY=1", std::chrono::seconds(10), from)) << daemon->err();
        EXPECT_TRUE(wait_until(
            [&] {
                return ask(socket(), {{"cmd", "status"}}, 500ms).has_value();
            },
            10s))
            << daemon->err();
        return seconds_since(started);
    }

    /// The daemon answers status within 1 s.
    void expect_answering(const std::string& after) {
        const auto a = ask(socket(), {{"cmd", "status"}}, 5s);
        ASSERT_TRUE(a) << "no status answer after " << after << "\n" << daemon->err();
        EXPECT_TRUE(a->json.value("ok", false)) << a->json.dump();
        EXPECT_LT(a->seconds, 1.0) << "status took " << a->seconds << " s after " << after;
    }

    /// Watchdog pings still come: at least three more (a ping every 100 ms with WATCHDOG_USEC=400000).
    void expect_pinging(const std::string& after) {
        const auto from = notify.messages().size();
        EXPECT_TRUE(wait_until([&] { return notify.count("WATCHDOG=1", from) >= 3; }, 10s))
            << "the watchdog pings stopped after " << after;
    }

    /// kill -9, restart: up and answering within 2 s.
    void expect_restart_answers(const std::string& after) {
        daemon->signal(SIGKILL);
        ASSERT_TRUE(daemon->wait_exit(10s));
        const double took = start();
        if (!kSlowed) {
            EXPECT_LT(took, 2.0) << "answering " << took << " s after a restart following " << after;
        }
        expect_answering("the restart after " + after);
        std::cout << "[ figures ] " << after << ": answering " << took << " s after kill -9 and restart\n";
    }

    /// A control request on the local socket (answered within 5 s, or the test fails).
    Json request(const Json& r) {
        auto a = ask(socket(), r, 5s);
        EXPECT_TRUE(a) << r.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n" << daemon->err();
        return a ? a->json : Json::object();
    }

    TempDir dir;
    NotifyListener notify;
    std::unique_ptr<Subprocess> daemon;
};

// The field report: {"cmd":"plan.load","path":"/dev/zero"} spun the daemon at 100 % CPU forever (the read
// loop grew its buffer by 0); a FIFO blocked it until someone wrote.
TEST_F(HostileFiles, APlanPathThatIsDevZeroOrAFifoIsRefusedAtOnce) {
    start();
    expect_answering("the start");
    const long before = rss_kb(daemon->pid());
    ASSERT_EQ(::mkfifo(dir.file("plan.fifo").c_str(), 0600), 0);
    for (const auto& [path, why] : std::vector<std::pair<std::string, std::string>>{
             {"/dev/zero", "not a regular file (a character device)"},
             {dir.file("plan.fifo"), "not a regular file (a FIFO)"},
             {dir.path(), "not a regular file (a directory)"}}) {
        const auto started = std::chrono::steady_clock::now();
        const auto r = request({{"cmd", "plan.load"}, {"path", path}});
        EXPECT_LT(seconds_since(started), 1.0) << path;
        EXPECT_FALSE(r.value("ok", true)) << r.dump();
        EXPECT_EQ(r.value("error", ""), path + ": " + why);
        expect_answering("plan.load " + path);
    }
    const long after = rss_kb(daemon->pid());
    EXPECT_LT(after - before, 2048) << "resident memory " << before << " kB before, " << after << " kB after";
    std::cout << "[ figures ] resident memory " << before << " kB before, " << after << " kB after\n";
    expect_pinging("the refused paths");
    expect_restart_answers("a /dev/zero and a FIFO plan path");
}

// The field report: a plan named with the byte 0xff made every later status request go unanswered, and the
// plan, kept in state_dir, made the restarted daemon deaf again; airsegctl aborted on it (type_error.316).
TEST_F(HostileFiles, APlanWithTextThatIsNotUtf8IsRefusedWithItsPlace) {
    start();
    const long before = rss_kb(daemon->pid());
    write_file(dir.file("n.yaml"), kBadNamePlan);
    write_file(dir.file("k.yaml"), kBadKeyPlan);
    auto r = request({{"cmd", "plan.load"}, {"path", dir.file("n.yaml")}});
    EXPECT_FALSE(r.value("ok", true));
    EXPECT_NE(r.value("error", "").find(dir.file("n.yaml") + ":2:10: not valid UTF-8 (byte 0xff)"),
              std::string::npos)
        << r.dump();
    expect_answering("a plan named 0xff");
    r = request({{"cmd", "plan.load"}, {"path", dir.file("k.yaml")}});
    EXPECT_NE(r.value("error", "").find(dir.file("k.yaml") + ":3:7: not valid UTF-8 (byte 0xe9)"),
              std::string::npos)
        << r.dump();
    expect_answering("a plan with 0xe9 in a key");
    // The ground client says so and sends nothing; it never aborts.
    for (const auto* file : {"n.yaml", "k.yaml"}) {
        const auto ctl =
            run({binary("client/airsegctl"), "--socket", socket(), "plan", "load", dir.file(file)});
        EXPECT_EQ(ctl.exit_code, 1) << ctl.err;
        EXPECT_NE(ctl.err.find("not valid UTF-8"), std::string::npos) << ctl.err;
    }
    EXPECT_FALSE(fs::exists(dir.file("state/plan.yaml"))) << "a refused plan must not be kept";
    EXPECT_LT(rss_kb(daemon->pid()) - before, 2048);
    expect_pinging("the refused plans");
    expect_restart_answers("a plan with invalid UTF-8");
}

// A plan stored by an earlier version (its checksum right) that no longer loads: set aside at the start, the
// daemon up without it; never a restart loop, never a deaf daemon.
TEST_F(HostileFiles, AStoredPlanThatNoLongerLoadsIsSetAsideAtStart) {
    flightplan::StateStore store(dir.file("state"), flightplan::Durability::NoFsync);
    ASSERT_FALSE(store.save_plan(kBadNamePlan, dir.file("n.yaml")));
    flightplan::SavedProgress progress;
    progress.plan_digest = flightplan::hex64(flightplan::fnv1a64(kBadNamePlan));
    ASSERT_FALSE(store.save_progress(progress));
    const double took = start();
    if (!kSlowed) {
        EXPECT_LT(took, 2.0);
    }
    std::cout << "[ figures ] a start with a stored plan that no longer loads: answering " << took << " s\n";
    expect_answering("a start with a stored plan that no longer loads");
    EXPECT_TRUE(fs::exists(dir.file("state/plan.yaml.corrupt-1")));
    EXPECT_TRUE(fs::exists(dir.file("state/progress.state.corrupt-1")));
    EXPECT_FALSE(fs::exists(dir.file("state/plan.yaml")));
    EXPECT_NE(daemon->err().find("stored plan no longer loads"), std::string::npos) << daemon->err();
    const auto plan = request({{"cmd", "plan.show"}});
    EXPECT_TRUE(plan.value("ok", false)) << plan.dump();
    expect_restart_answers("a stored plan that no longer loads");
}

std::string config_with(const std::string& extra) {
    return read_file(source_path("config/airseg.yaml")) + extra;
}

/// `airsegd --check-config` and a start, each on `config`: exit 78 at once, `expected` in the error, and an
/// error of bounded size (never the whole file echoed, never a line per key beyond the first 50).
void expect_config_refused(const std::string& config, const std::string& expected) {
    for (const bool check : {true, false}) {
        std::vector<std::string> argv{binary("daemon/airsegd"), "--config", config};
        if (check) {
            argv.push_back("--check-config");
        }
        const auto started = std::chrono::steady_clock::now();
        const auto r = run(argv, {}, kSlowed ? 120s : 20s);
        const double seconds = seconds_since(started);
        EXPECT_EQ(r.exit_code, 78) << config << (check ? " --check-config" : "") << "\n"
                                   << r.err.substr(0, 2000);
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err.substr(0, 2000);
        EXPECT_LT(r.err.size(), 16'384u) << config;
        EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 52) << config;
        if (!kSlowed) {
            EXPECT_LT(seconds, 10.0) << config;  // printed below in every build, checked where it ships
        }
        std::cout << "[ figures ] " << fs::path(config).filename().string()
                  << (check ? " --check-config" : " start") << ": exit " << r.exit_code << " in " << seconds
                  << " s, " << r.err.size() << " bytes of error\n";
    }
}

TEST_F(HostileFiles, AConfigurationThatIsNotARegularFileIsRefusedAtOnce) {
    ASSERT_EQ(::mkfifo(dir.file("fifo.yaml").c_str(), 0600), 0);
    expect_config_refused(
        "/dev/zero",
        "/dev/zero: cannot read the configuration file: not a regular file (a character device)");
    expect_config_refused(dir.file("fifo.yaml"), "not a regular file (a FIFO)");
    fs::create_directory(dir.file("conf"));
    expect_config_refused(dir.file("conf"), "not a regular file (a directory)");
    // A drop-in linked to /dev/zero (it ended in std::bad_alloc at 2 GB).
    fs::create_directories(dir.file("etc/conf.d"));
    write_file(dir.file("etc/airseg.yaml"), read_file(source_path("config/airseg.yaml")));
    fs::create_symlink("/dev/zero", dir.file("etc/conf.d/50-zero.yaml"));
    expect_config_refused(dir.file("etc/airseg.yaml"),
                          "50-zero.yaml: cannot read the configuration file: not a regular file");
}

TEST_F(HostileFiles, AConfigurationThatIsNotOneDocumentOfTextIsRefused) {
    std::mt19937 random(35);
    std::string bytes(4096, '\0');
    for (auto& c : bytes) {
        c = static_cast<char>(random() & 0xff);
    }
    write_file(dir.file("random.yaml"), bytes);
    expect_config_refused(dir.file("random.yaml"),
                          "a configuration file is UTF-8 text without control characters");
    write_file(dir.file("second.yaml"), config_with("---\nlog_level: debug\n"));
    expect_config_refused(dir.file("second.yaml"), "a second YAML document");
    write_file(dir.file("nul.yaml"), config_with(std::string("threads: 1\0\n", 12)));
    expect_config_refused(dir.file("nul.yaml"), "a control character (0x00)");
    write_file(dir.file("value.yaml"), config_with("log_level: " + std::string(10'000'000, 'x') + "\n"));
    expect_config_refused(dir.file("value.yaml"), "larger than the 1 MiB allowed");
    write_file(dir.file("long.yaml"), "log_level: " + std::string(1'000'000, 'x') + "\n");
    expect_config_refused(dir.file("long.yaml"), "… (1000000 bytes)");
    // The field report's 100,000 keys; a fifth of them where every instruction is several times slower.
    const int key_count = kSlowed ? 20'000 : 100'000;
    std::string keys;
    for (int i = 0; i < key_count; ++i) {
        keys += "k" + std::to_string(i) + ": 1\n";
    }
    write_file(dir.file("keys.yaml"), keys);
    expect_config_refused(dir.file("keys.yaml"),
                          "... and " + std::to_string(key_count - 50) + " more errors");
}

// The field report: on SIGHUP a FIFO drop-in stopped the watchdog pings and SIGTERM; a directory was read as
// an empty file and the defaults applied.
TEST_F(HostileFiles, SighupWithAFifoDropInKeepsTheRunningConfiguration) {
    fs::create_directories(dir.file("etc/conf.d"));
    write_file(dir.file("etc/airseg.yaml"), read_file(source_path("config/airseg.yaml")));
    write_file(dir.file("etc/conf.d/10-level.yaml"), "log_level: warn\n");
    start(dir.file("etc/airseg.yaml"));
    ASSERT_EQ(::mkfifo(dir.file("etc/conf.d/50-fifo.yaml").c_str(), 0600), 0);
    fs::create_directory(dir.file("etc/conf.d/60-dir.yaml"));
    write_file(dir.file("etc/conf.d/10-level.yaml"), "log_level: debug\n");  // not to be applied
    daemon->signal(SIGHUP);
    EXPECT_TRUE(wait_until([&] {
        return daemon->err().find("keeping the running configuration") != std::string::npos;
    })) << daemon->err();
    EXPECT_NE(
        daemon->err().find("50-fifo.yaml: cannot read the configuration file: not a regular file (a FIFO)"),
        std::string::npos);
    EXPECT_NE(daemon->err().find(
                  "60-dir.yaml: cannot read the configuration file: not a regular file (a directory)"),
              std::string::npos);
    EXPECT_EQ(daemon->err().find("(applied)"), std::string::npos) << "nothing may change:\n" << daemon->err();
    expect_answering("SIGHUP with a FIFO drop-in");
    expect_pinging("SIGHUP with a FIFO drop-in");
    const auto stopping = notify.messages().size();
    daemon->signal(SIGTERM);
    const auto code = daemon->wait_exit(5s);
    ASSERT_TRUE(code) << "SIGTERM did not stop the daemon\n" << daemon->err();
    EXPECT_EQ(*code, 0);
    EXPECT_TRUE(notify.wait_for("STOPPING=1", 1s, stopping));
}

// With the autopilot ready, the plan named 0xff aborted the daemon outright. Now it is refused, and the plan
// that runs is untouched.
TEST(HostileFilesWithAutopilot, APlanNamedWithAnInvalidByteIsRefusedWhileTheAutopilotIsReady) {
    SystemBench bench;
    ASSERT_TRUE(bench.wait_ready()) << bench.logs();
    write_file(bench.dir().file("ok.yaml"), line_plan("ok", 5, 20));
    ASSERT_EQ(bench.ctl_local({"plan", "load", bench.dir().file("ok.yaml")}).exit_code, 0) << bench.logs();
    write_file(bench.dir().file("n.yaml"), kBadNamePlan);
    const auto local =
        ask(bench.dir().file("status.sock"), {{"cmd", "plan.load"}, {"path", bench.dir().file("n.yaml")}});
    ASSERT_TRUE(local) << bench.logs();
    EXPECT_NE(local->json.value("error", "").find("not valid UTF-8 (byte 0xff)"), std::string::npos)
        << local->json.dump();
    // Over the radio the ground client finds it first, says where, and sends nothing.
    const auto radio = bench.ctl({"plan", "load", bench.dir().file("n.yaml")});
    EXPECT_EQ(radio.exit_code, 1) << radio.err;
    EXPECT_NE(radio.err.find("n.yaml:2:10: not valid UTF-8 (byte 0xff)"), std::string::npos) << radio.err;
    const auto status = ask(bench.dir().file("status.sock"), {{"cmd", "status"}});
    ASSERT_TRUE(status) << bench.logs();
    EXPECT_LT(status->seconds, 1.0);
    EXPECT_EQ(status->json["result"]["plan"].value("name", ""), "ok") << status->json.dump();
    EXPECT_TRUE(bench.daemon_running()) << bench.logs();
}

}  // namespace
}  // namespace airseg::test::sys

// End to end on real ptys: airsegd ⇄ airseg-linksim (57600 baud radio pair) ⇄ airsegctl.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

class GroundlinkEndToEnd : public ::testing::Test {
  protected:
    GroundlinkEndToEnd() : notify(dir.file("notify.sock")) {}

    void start_link(std::vector<std::string> impairments) {
        std::vector<std::string> args{binary("tools/linksim/airseg-linksim"),
                                      "--a",
                                      air(),
                                      "--b",
                                      ground(),
                                      "--baud",
                                      "57600",
                                      "--seed",
                                      "7",
                                      "--control",
                                      control()};
        args.insert(args.end(), impairments.begin(), impairments.end());
        linksim = std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir.path());
        ASSERT_TRUE(wait_until([&] {
            return std::filesystem::exists(air()) && std::filesystem::exists(ground());
        })) << linksim->err();
    }

    void start_daemon(std::vector<std::string> link = {}) {
        if (link.empty()) {
            link = {"--set", "groundlink.ports=[" + air() + "]"};
        }
        std::vector<std::string> args{binary("daemon/airsegd"),
                                      "--config",
                                      source_path("config/airseg.yaml"),
                                      "--set",
                                      "status.socket=" + dir.file("status.sock"),
                                      "--set",
                                      "state_dir=" + dir.file("state"),
                                      "--set",
                                      "autopilot.port=" + dir.file("ttyACM0")};
        const auto unkeyed = unkeyed_ground_link();
        args.insert(args.end(), unkeyed.begin(), unkeyed.end());
        args.insert(args.end(), link.begin(), link.end());
        daemon = std::make_unique<Subprocess>(
            args, std::map<std::string, std::string>{{"NOTIFY_SOCKET", notify.path()}}, dir.path());
        ASSERT_TRUE(notify.wait_for("READY=1", 10s, notify.messages().size())) << daemon->err();
    }

    RunResult status(long timeout_ms) {
        return run({binary("client/airsegctl"), "--link", ground(), "--baud", "57600", "--timeout",
                    std::to_string(timeout_ms), "status", "--json"},
                   {}, std::chrono::milliseconds(timeout_ms + 10'000));
    }

    void control_command(const std::string& text) {
        const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, control().c_str(), sizeof(addr.sun_path) - 1);
        ASSERT_EQ(::sendto(fd, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&addr), sizeof addr),
                  static_cast<ssize_t>(text.size()));
        ::close(fd);
    }

    std::string air() const { return dir.file("air"); }
    std::string ground() const { return dir.file("ground"); }
    std::string control() const { return dir.file("linksim.ctl"); }

    TempDir dir;
    NotifyListener notify;
    std::unique_ptr<Subprocess> linksim;
    std::unique_ptr<Subprocess> daemon;
};

TEST_F(GroundlinkEndToEnd, StatusOverTheRadioWithTenPercentFrameLoss) {
    start_link({"--frame-loss", "0.1"});
    start_daemon();
    for (int i = 0; i < 3; ++i) {
        auto r = status(30'000);
        ASSERT_EQ(r.exit_code, 0) << "call " << i << ": " << r.err << "\ndaemon:\n" << daemon->err();
        auto doc = nlohmann::json::parse(r.out);
        EXPECT_EQ(doc["services"]["autopilot"]["health"], "down");
        // The first request may come in the session's first frame (a slow client, e.g. under qemu, packs its
        // hello and the request together), answered before link_up_frames (2) valid frames mark the link up.
        if (i > 0) {
            EXPECT_EQ(doc["groundlink"]["link"], "up") << "call " << i;
        }
        EXPECT_EQ(doc["groundlink"]["mode"], "single");
        EXPECT_GE(doc["groundlink"]["frames_received"].get<int>(), 1);
    }
}

TEST_F(GroundlinkEndToEnd, ASessionSurvivesASixtySecondOutageAndADaemonRestart) {
    start_link({});
    start_daemon();
    auto before = status(20'000);
    ASSERT_EQ(before.exit_code, 0) << before.err;

    // The request is sent into a 60 s outage; the same client session gets its answer once the air clears.
    control_command("outage 60");
    const auto sent = std::chrono::steady_clock::now();
    auto during = status(120'000);
    const auto waited = std::chrono::steady_clock::now() - sent;
    ASSERT_EQ(during.exit_code, 0) << during.err;
    EXPECT_GT(waited, 55s) << "the answer cannot have crossed the outage";
    EXPECT_LT(waited, 75s) << "the link must recover within seconds of the outage's end";

    // The vehicle end restarts (kill -9): a new session is set up without stuck sequence state.
    daemon->signal(SIGKILL);
    ASSERT_TRUE(daemon->wait_exit(5s));
    start_daemon();
    auto after = status(30'000);
    ASSERT_EQ(after.exit_code, 0) << after.err << "\ndaemon:\n" << daemon->err();
    EXPECT_TRUE(nlohmann::json::parse(after.out).contains("services"));
    // The first answer may beat the link-up hysteresis (two frames); the next one sees an established link.
    auto again = status(30'000);
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(nlohmann::json::parse(again.out)["groundlink"]["link"], "up");
}

TEST_F(GroundlinkEndToEnd, SplitModeOverTwoRadioPairsKeepsWorkingWhenOnePairDies) {
    // Pair A carries air→ground, pair B ground→air; each is its own airseg-linksim.
    start_link({});
    const std::string air_b = dir.file("air_b"), ground_b = dir.file("ground_b"),
                      control_b = dir.file("b.ctl");
    Subprocess pair_b({binary("tools/linksim/airseg-linksim"), "--a", air_b, "--b", ground_b, "--baud",
                       "57600", "--seed", "8", "--control", control_b},
                      {}, dir.path());
    ASSERT_TRUE(
        wait_until([&] { return std::filesystem::exists(air_b) && std::filesystem::exists(ground_b); }));
    start_daemon(
        {"--set", "groundlink.mode=split", "--set", "groundlink.ports=[" + air() + "," + air_b + "]"});
    auto split_status = [&] {
        return run({binary("client/airsegctl"), "--link", ground() + "," + ground_b, "--mode", "split",
                    "--timeout", "30000", "status", "--json"},
                   {}, 40s);
    };
    auto both = split_status();
    ASSERT_EQ(both.exit_code, 0) << both.err << "\ndaemon:\n" << daemon->err();
    auto doc = nlohmann::json::parse(both.out);
    EXPECT_EQ(doc["groundlink"]["mode"], "split");
    ASSERT_EQ(doc["groundlink"]["paths"].size(), 2u);

    // Pair A dies: traffic falls back to pair B in both directions.
    control_command("down a");
    control_command("down b");
    auto one = split_status();
    EXPECT_EQ(one.exit_code, 0) << one.err << "\ndaemon:\n" << daemon->err();
    // The daemon goes before pair B's emulator: a daemon outliving its ports would keep reopening their
    // paths, and a pty number freed by the emulator is soon another test's line.
    daemon.reset();
}

TEST_F(GroundlinkEndToEnd, UdpModeServesTheSameCommands) {
    const int port = free_udp_port();
    start_daemon({"--set", "groundlink.mode=udp", "--set", "groundlink.udp.bind=127.0.0.1", "--set",
                  "groundlink.udp.port=" + std::to_string(port)});
    auto r = run({binary("client/airsegctl"), "--udp", "127.0.0.1:" + std::to_string(port), "--timeout",
                  "10000", "status", "--json"},
                 {}, 20s);
    ASSERT_EQ(r.exit_code, 0) << r.err << "\ndaemon:\n" << daemon->err();
    auto doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["groundlink"]["mode"], "udp");
    EXPECT_EQ(doc["services"]["groundlink"]["health"].get<std::string>() != "down", true);
}

TEST_F(GroundlinkEndToEnd, NoLinkIsExitCodeThree) {
    start_link({});
    // No daemon on the air side: nobody answers.
    auto r = status(2'000);
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_NE(r.err.find("no link"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace airseg::test

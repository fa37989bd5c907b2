// airsegd and the simulated APM:Rover (airseg-apmsim), both real binaries, joined by a pseudo-terminal; the
// operator's side is airsegctl on the local socket. The simulator's control socket says what the board
// really did. Simulated time runs faster than real time on the board's side (--speedup); every wait is on a
// condition with a generous deadline.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/support/control_client.hpp"
#include "tests/support/ground_station.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

using Json = nlohmann::json;

constexpr auto kGenerous = 30s;
constexpr auto kPoll = 100ms;  // each poll of the status runs airsegctl
constexpr double kHomeLat = 41.2756;
constexpr double kHomeLon = 1.9866;

bool exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

using SimControl = ControlClient;

struct Answer {
    int exit_code = -1;
    Json json;
};

class AutopilotE2e : public ::testing::Test {
  protected:
    static constexpr int kSpeedup = 10;  // board seconds per real second
    /// The board's silences as long as the daemon's autopilot.heartbeat_timeout (3 s, real time) or longer,
    /// by the simulator's record: a stall fault, a reboot, or the simulator itself not running. Each may end
    /// the link, rightly; nothing else may.
    int board_silences() {
        int n = 0;
        for (const auto& gap : control_->json("stats").value("long_heartbeat_gaps", Json::array())) {
            n += gap.value("s", 0.0) / kSpeedup >= 3.0 ? 1 : 0;
        }
        return n;
    }
    void SetUp() override {
        sim_ = std::make_unique<Subprocess>(
            with(std::vector<std::string>{binary("tools/apmsim/airseg-apmsim"), "--link",
                                          dir_.file("ttyACM0"), "--control", dir_.file("ctl"), "--home",
                                          std::to_string(kHomeLat) + "," + std::to_string(kHomeLon),
                                          "--speedup", std::to_string(kSpeedup), "--boot-delay", "0.5",
                                          "--calib-time", "0.5"},
                 extra_sim_args_),
            std::map<std::string, std::string>{}, dir_.path());
        ASSERT_TRUE(wait_until([&] { return exists(dir_.file("ttyACM0")) && exists(dir_.file("ctl")); },
                               kGenerous, kPoll))
            << sim_->err();
        control_ = std::make_unique<SimControl>(dir_.file("me"), dir_.file("ctl"));
        daemon_ = std::make_unique<Subprocess>(
            with(std::vector<std::string>{binary("daemon/airsegd"), "--config",
                                          source_path("config/airseg.yaml"), "--set",
                                          "status.socket=" + dir_.file("status.sock"), "--set",
                                          "state_dir=" + dir_.file("state"), "--set",
                                          "autopilot.port=" + dir_.file("ttyACM0"), "--set",
                                          "autopilot.reconnect_max=500ms", "--set",
                                          "groundlink.ports=[" + dir_.file("ttyUSB0") + "]", "--set",
                                          "groundlink.key_file=", "--set", "groundlink.insecure=true"},
                 extra_daemon_args_),
            std::map<std::string, std::string>{}, dir_.path());
    }

    void TearDown() override {
        if (daemon_ && daemon_->running()) {
            daemon_->signal(SIGTERM);
            EXPECT_EQ(daemon_->wait_exit(10s), 0) << daemon_->err() << daemon_->stuck();
        }
    }

    Answer ctl(std::vector<std::string> args) {
        std::vector<std::string> argv{binary("client/airsegctl"),
                                      "--local",
                                      "--socket",
                                      dir_.file("status.sock"),
                                      "--json",
                                      "--timeout",
                                      "15000"};
        argv.insert(argv.end(), args.begin(), args.end());
        const auto r = run(argv, {}, 30s);
        Answer a;
        a.exit_code = r.exit_code;
        a.json = Json::parse(r.out, nullptr, false);
        return a;
    }
    Answer request(const Json& r) { return ctl({"request", r.dump()}); }
    Json autopilot_section() {
        auto a = ctl({"status"});
        return a.exit_code == 0 && a.json.is_object() ? a.json.value("autopilot", Json()) : Json();
    }
    bool ready() {
        const auto ap = autopilot_section();
        return ap.is_object() && ap.value("ready", false);
    }

    static std::vector<std::string> with(std::vector<std::string> args,
                                         const std::vector<std::string>& more) {
        args.insert(args.end(), more.begin(), more.end());
        return args;
    }

    std::vector<std::string> extra_sim_args_;     // set by a derived fixture before SetUp
    std::vector<std::string> extra_daemon_args_;  // idem
    TempDir dir_;
    std::unique_ptr<Subprocess> sim_;
    std::unique_ptr<SimControl> control_;
    std::unique_ptr<Subprocess> daemon_;
};

// The same cases against each firmware profile of the simulator (docs/simulators.md): today's ArduPilot Rover
// and an APM:Rover 2.x board (MAVLink 1 only, SET_MODE never acknowledged, MAV_STATE_UNINIT in HOLD).
class AutopilotFirmwareE2e : public AutopilotE2e, public ::testing::WithParamInterface<std::string> {
  protected:
    AutopilotFirmwareE2e() { extra_sim_args_ = {"--firmware", GetParam()}; }
};

TEST_P(AutopilotFirmwareE2e, ReadyStatusStateChangesAndParameters) {
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    const auto ap = autopilot_section();
    EXPECT_EQ(ap["link"], "up");
    ASSERT_TRUE(ap["ready_s"].is_number()) << ap.dump();
    EXPECT_GT(ap["ready_s"].get<double>(), 0.0);
    EXPECT_TRUE(ap["mode"].is_string() && !ap["mode"].get<std::string>().empty()) << ap.dump();
    EXPECT_TRUE(ap["state"].is_string()) << ap.dump();
    EXPECT_TRUE(ap.contains("mission_current") && ap.contains("reboots") && ap.contains("reconnects"));
    ASSERT_TRUE(wait_until([&] { return autopilot_section()["position"].is_object(); }, kGenerous, kPoll));
    const auto pos = autopilot_section()["position"];
    EXPECT_NEAR(pos["lat"].get<double>(), kHomeLat, 1e-3);
    EXPECT_NEAR(pos["lon"].get<double>(), kHomeLon, 1e-3);

    // PARKING is HOLD on a Rover: answered only once the board has switched.
    auto parked = request({{"cmd", "state"}, {"state", "PARKING"}});
    ASSERT_EQ(parked.exit_code, 0) << parked.json.dump();
    EXPECT_EQ(parked.json["state"], "PARKING");
    EXPECT_EQ(control_->json("state")["mode"], "HOLD");
    const auto modes = control_->json("modes 1");
    ASSERT_TRUE(modes.is_array() && !modes.empty()) << modes.dump();
    EXPECT_EQ(modes.back()["to"], "HOLD");
    EXPECT_EQ(modes.back()["cause"], "command");
    ASSERT_TRUE(wait_until([&] { return autopilot_section()["state"] == "PARKING"; }, kGenerous, kPoll));
    EXPECT_EQ(autopilot_section()["mode"], "HOLD");

    // WAYPOINT_NAVIGATION needs a mission; the board has none, so the request is refused, not "ok".
    auto auto_mode = request({{"cmd", "state"}, {"state", "WAYPOINT_NAVIGATION"}});
    EXPECT_EQ(auto_mode.exit_code, 1) << auto_mode.json.dump();
    EXPECT_EQ(auto_mode.json.value("ok", true), false) << auto_mode.json.dump();
    EXPECT_EQ(control_->json("state")["mode"], "HOLD");
    EXPECT_EQ(autopilot_section()["state"], "PARKING");

    // DIRECTED hands the rover to the RC pilot: MANUAL on the board.
    auto directed = request({{"cmd", "state"}, {"state", "directed"}});
    ASSERT_EQ(directed.exit_code, 0) << directed.json.dump();
    EXPECT_EQ(directed.json["state"], "DIRECTED");
    EXPECT_EQ(control_->json("state")["mode"], "MANUAL");

    auto bad = request({{"cmd", "state"}, {"state", "FLYING"}});
    EXPECT_EQ(bad.exit_code, 1);
    EXPECT_EQ(bad.json.value("status", ""), "bad_request") << bad.json.dump();

    // Parameters: read, write, read back, and the board agrees.
    auto before = request({{"cmd", "param.get"}, {"name", "WP_RADIUS"}});
    ASSERT_EQ(before.exit_code, 0) << before.json.dump();
    ASSERT_TRUE(before.json["value"].is_number()) << before.json.dump();
    const double wanted = before.json["value"].get<double>() + 1.0;
    auto set = request({{"cmd", "param.set"}, {"name", "WP_RADIUS"}, {"value", wanted}});
    ASSERT_EQ(set.exit_code, 0) << set.json.dump();
    EXPECT_NEAR(set.json["value"].get<double>(), wanted, 1e-4);
    auto after = request({{"cmd", "param.get"}, {"name", "WP_RADIUS"}});
    ASSERT_EQ(after.exit_code, 0) << after.json.dump();
    EXPECT_NEAR(after.json["value"].get<double>(), wanted, 1e-4);

    auto unknown = request({{"cmd", "param.get"}, {"name", "NO_SUCH_PARAM"}});
    EXPECT_NE(unknown.exit_code, 0) << unknown.json.dump();

    // The whole table, as cached since the connection, includes the value just set.
    auto list = request({{"cmd", "param.list"}});
    ASSERT_EQ(list.exit_code, 0) << list.json.dump();
    EXPECT_GE(list.json["count"].get<int>(), 200);
    ASSERT_TRUE(list.json["params"].contains("WP_RADIUS")) << list.json.dump().substr(0, 300);
    EXPECT_NEAR(list.json["params"]["WP_RADIUS"].get<double>(), wanted, 1e-4);
}

TEST_P(AutopilotFirmwareE2e, UnplugShowsTheLinkDownAndReplugRecoversWithoutARestart) {
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    const auto reconnects = autopilot_section()["reconnects"].get<unsigned>();

    control_->ask("unplug");
    ASSERT_TRUE(wait_until([&] { return autopilot_section()["link"] == "down"; }, kGenerous, kPoll));
    EXPECT_FALSE(autopilot_section()["ready"].get<bool>());

    control_->ask("replug");
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    EXPECT_EQ(autopilot_section()["link"], "up");
    EXPECT_GT(autopilot_section()["reconnects"].get<unsigned>(), reconnects);
    EXPECT_TRUE(daemon_->running());
}

// The board's UART runs at 115200; the daemon is told to try 57600 first. A pty carries bytes at any rate,
// so the simulator reads the rate airsegd set on its end and, while it differs, both sides hear noise.
class AutopilotBaudProbeE2e : public AutopilotE2e {
  protected:
    AutopilotBaudProbeE2e() {
        extra_sim_args_ = {"--baud", "115200"};
        extra_daemon_args_ = {"--set", "autopilot.bauds=[57600, 115200]", "--set", "autopilot.baud_probe=1s"};
    }
};

TEST_F(AutopilotBaudProbeE2e, ProbesTheConfiguredRatesAndKeepsTheOneThatWorks) {
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    const auto ap = autopilot_section();
    EXPECT_EQ(ap["baud"], 115200) << ap.dump();
    EXPECT_EQ(ap["link"], "up");
    // The first rate was really tried, and really failed: the board heard noise at 57600.
    EXPECT_NE(sim_->err().find("peer at 57600 baud, board at 115200"), std::string::npos) << sim_->err();
    EXPECT_NE(daemon_->err().find("trying 115200 baud"), std::string::npos) << daemon_->err();
    EXPECT_EQ(ap["reconnects"], 0) << "a baud switch is not a reconnect";
}

// A ground station on the board's network (autopilot.gcs_endpoint.udp) talks to the simulated board through
// airsegd: it hears the board, reads a parameter, and its mission upload becomes the flight plan when none
// runs, or is refused with the reason while one does.
class GcsEndpointE2e : public AutopilotE2e {
  protected:
    GcsEndpointE2e() : port_(free_udp_port()) {
        extra_daemon_args_ = {"--set", "autopilot.gcs_endpoint.udp=127.0.0.1:" + std::to_string(port_)};
        // The endpoint sends every frame of the board as a datagram of its own (telemetry at 10 times its
        // rate here, a parameter list at once), and the station reads between its other calls: with the
        // kernel's default 208 KiB, about 200 datagrams, a slow moment of this process under a sanitizer
        // lost a banner in its own receive buffer (19 of 20). 4 MiB (forced where allowed) holds seconds.
        const int bytes = 4 << 20;
        if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes) != 0) {
            ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
        }
    }
    ~GcsEndpointE2e() override {
        if (fd_ >= 0) {
            ::close(fd_);
        }
    }
    void send(const std::vector<std::uint8_t>& frame) {
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        to.sin_port = htons(static_cast<std::uint16_t>(port_));
        ::sendto(fd_, frame.data(), frame.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    /// Reads what came until `found` says so or the time is up; true when found.
    bool hear(const std::function<bool(const mavlink::Frame&)>& found, std::chrono::milliseconds limit) {
        const auto end = std::chrono::steady_clock::now() + limit;
        bool seen = false;
        while (!seen && std::chrono::steady_clock::now() < end) {
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) {
                continue;
            }
            std::array<std::uint8_t, 2048> buf{};
            const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
            if (n > 0) {
                parser_.push(std::span(buf).first(static_cast<std::size_t>(n)),
                             [&](const mavlink::Frame& f) { seen = seen || found(f); });
            }
        }
        return seen;
    }

    struct Upload {
        int ack = -1;  // the MISSION_ACK type, -1 when none came
        std::string texts;
    };
    /// Uploads home and `points` as waypoints, the last one a stop until released, answering each request.
    Upload upload(const std::vector<std::pair<double, double>>& points) {
        Upload u;
        send(gcs_.mission_upload(static_cast<std::uint16_t>(points.size() + 1)));
        const auto answer = [&](const mavlink::Frame& f) {
            if (const int seq = GroundStation::mission_request(f); seq >= 0) {
                const auto& p = seq == 0 ? std::pair{kHomeLat, kHomeLon} : points[seq - 1];
                const bool last = static_cast<std::size_t>(seq) == points.size();
                send(gcs_.mission_item(static_cast<std::uint16_t>(seq), p.first, p.second,
                                       last ? mavlink::kCmdNavLoiterUnlim : mavlink::kCmdNavWaypoint));
            } else if (f.msgid == mavlink::Statustext::kId && f.sysid == 1) {
                u.texts +=
                    mavlink::text_of(mavlink::decode_payload<mavlink::Statustext>(f.payload_view()).text);
                u.texts += ' ';
            } else if (f.msgid == mavlink::MissionAck::kId) {
                const auto ack = mavlink::decode_payload<mavlink::MissionAck>(f.payload_view());
                if (ack.target_system == 254) {
                    u.ack = ack.type;
                    return true;
                }
            }
            return false;
        };
        hear(answer, kGenerous);
        hear(
            [&](const mavlink::Frame& f) {
                answer(f);
                return false;  // the texts that follow the acknowledgement
            },
            500ms);
        return u;
    }

    int port_;
    int fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    mavlink::Parser parser_;
    GroundStation gcs_;
};

// A second station on the board's network asks for the parameter list every 30 s of the board's time for 10
// minutes (60 s here at x10). Current ArduPilot, and airseg-apmsim's modern profile, answer each with the
// banner before the parameters, on the one link: airsegd hears every banner too. A banner is no reboot (it
// used to be one within 10 s of the link coming up, a loop with the daemon's own parameter request); the
// board's real reboot still is one.
TEST_F(GcsEndpointE2e, ParameterListsFromAnotherStationBringBannersButNoReboot) {
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    const auto at_ready = autopilot_section();
    EXPECT_EQ(at_ready["reboots"], 0) << at_ready.dump() << daemon_->err();
    EXPECT_EQ(at_ready["syncs"], 1) << at_ready.dump();
    send(gcs_.heartbeat());
    const auto board_t = [&] { return control_->json("state").value("t", 0.0); };
    const auto banner = [](const mavlink::Frame& f) {
        return f.msgid == mavlink::Statustext::kId && f.sysid == 1 &&
               mavlink::text_of(mavlink::decode_payload<mavlink::Statustext>(f.payload_view()).text)
                   .starts_with("ArduRover V4.");
    };
    // Everything the station hears is read as it comes (the parameters follow each banner, and the board's
    // telemetry all the time), the banners counted.
    int banners = 0;
    const auto listen = [&](std::chrono::milliseconds span) {
        hear(
            [&](const mavlink::Frame& f) {
                banners += banner(f) ? 1 : 0;
                return false;
            },
            span);
    };
    const double start = board_t();
    for (int request = 0; request < 20; ++request) {
        const double asked = board_t();
        send(gcs_.list_params());
        ASSERT_TRUE(wait_until(
            [&] {
                listen(100ms);
                return board_t() >= asked + 30.0;
            },
            kGenerous, kPoll));
    }
    listen(1s);
    const double board_minutes = (board_t() - start) / 60.0;
    const auto after = autopilot_section();
    EXPECT_EQ(banners, 20) << "each request brought the banner to the station: "
                           << after.value("ground_stations", Json()).dump();
    EXPECT_EQ(after["reboots"], 0) << after.dump() << daemon_->err();
    EXPECT_EQ(after["syncs"], 1) << "the parameters and the mission were read once";
    // A loaded machine can keep the simulator from running for seconds (30 board seconds and more at x10):
    // its board then really was silent for the daemon's heartbeat timeout, and a loss is the daemon right.
    const int silences = board_silences();
    EXPECT_LE(after["link_losses"].get<int>(), silences)
        << "the daemon's log says when the link was lost:\n"
        << daemon_->err() << "the board's log:\n"
        << sim_->err()
        << "the board's silences: " << control_->json("stats").value("long_heartbeat_gaps", Json());
    EXPECT_EQ(after["ready_s"], at_ready["ready_s"]);
    EXPECT_EQ(daemon_->err().find("rebooted"), std::string::npos) << daemon_->err();
    // The endpoint's counters in status: the station's heartbeat and 20 requests passed on, nothing damaged,
    // one UDP peer, and the drop counter present (a station that keeps up loses nothing).
    const auto stations = after.value("ground_stations", Json());
    EXPECT_GE(stations.value("frames_in", 0), 21) << stations.dump();
    EXPECT_EQ(stations.value("invalid_in", -1), 0) << stations.dump();
    EXPECT_EQ(stations.value("udp_peers", 0), 1) << stations.dump();
    EXPECT_TRUE(stations.contains("dropped_out")) << stations.dump();

    ASSERT_EQ(control_->ask("reboot").value_or("").rfind("ok", 0), 0u);
    EXPECT_TRUE(wait_until([&] { return autopilot_section().value("reboots", 0) == 1; }, kGenerous, kPoll))
        << daemon_->err();
    EXPECT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    const auto rebooted = autopilot_section();
    EXPECT_EQ(rebooted["reboots"], 1) << rebooted.dump();
    EXPECT_EQ(rebooted["syncs"], 2) << rebooted.dump();
    std::cout << "[ figures ] " << banners << " parameter lists with their banner over " << board_minutes
              << " board minutes: " << after["reboots"] << " reboots, " << after["syncs"] << " syncs; "
              << after["link_losses"] << " link losses over " << silences
              << " silences of the board; ready_s " << at_ready["ready_s"]
              << "; a real reboot: " << rebooted["reboots"] << " reboot, " << rebooted["syncs"]
              << " syncs; the endpoint: " << stations.dump() << "\n";
}

TEST_F(GcsEndpointE2e, AGroundStationsMissionBecomesThePlanAndAnotherIsRefusedWhileItRuns) {
    ASSERT_TRUE(wait_until([&] { return ready(); }, kGenerous, kPoll)) << daemon_->err();
    send(gcs_.heartbeat());
    EXPECT_TRUE(hear(GroundStation::board_heartbeat, 10s)) << daemon_->err();
    send(gcs_.read_param("CRUISE_SPEED"));
    EXPECT_TRUE(
        hear([](const mavlink::Frame& f) { return GroundStation::param_value(f, "CRUISE_SPEED"); }, 10s));

    // No plan runs: the mission becomes the plan, and the flight plan manager drives it.
    const auto first = upload({{kHomeLat + 0.0003, kHomeLon}, {kHomeLat + 0.0006, kHomeLon + 0.0003}});
    ASSERT_EQ(first.ack, mavlink::kMissionAccepted) << first.texts << daemon_->err();
    const auto shown = ctl({"plan", "show"});
    ASSERT_EQ(shown.exit_code, 0);
    EXPECT_EQ(shown.json["name"], "ground station mission") << shown.json.dump();
    EXPECT_EQ(shown.json["state"], "running") << shown.json.dump();
    EXPECT_GT(control_->json("stats")["mission_items_received"], 0) << "the plan's window went to the board";
    EXPECT_TRUE(wait_until([&] { return control_->json("state")["mode"] == "AUTO"; }, kGenerous, kPoll))
        << control_->json("state").dump();

    // While it runs, another upload is refused with the reason, and the plan stays.
    const auto second = upload({{kHomeLat - 0.0003, kHomeLon}});
    EXPECT_EQ(second.ack, mavlink::kMissionDenied) << second.texts;
    EXPECT_NE(second.texts.find("a flight plan is running (ground station mission)"), std::string::npos)
        << second.texts;
    EXPECT_EQ(ctl({"plan", "show"}).json["name"], "ground station mission");
    EXPECT_NE(daemon_->err().find("uploaded a mission"), std::string::npos) << daemon_->err();
}

INSTANTIATE_TEST_SUITE_P(Firmware, AutopilotFirmwareE2e, ::testing::Values("modern", "rover2"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// airsegd with a scripted board on a pseudo-terminal (the test holds the master end): the heartbeats of a
// running board, and GLOBAL_POSITION_INT with time_boot_ms flipping between 2^32-1 and 0, 200 frames a
// second for 5 s (a broken or hostile peer). Not a reboot, and no log line per frame (that was 4.3 MB of log
// a second).
TEST(AutopilotHostileClock, TimeBootFlippingBetweenItsLimitsIsNoRebootAndNoLogFlood) {
    TempDir dir;
    int master = -1;
    int slave = -1;
    std::array<char, 128> name{};
    ASSERT_EQ(::openpty(&master, &slave, name.data(), nullptr, nullptr), 0);
    ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
    Subprocess daemon({binary("daemon/airsegd"), "--config", source_path("config/airseg.yaml"), "--set",
                       "status.socket=" + dir.file("status.sock"), "--set", "state_dir=" + dir.file("state"),
                       "--set", std::string("autopilot.port=") + name.data(), "--set",
                       "autopilot.board=pixhawk", "--set", "groundlink.ports=[" + dir.file("ttyUSB0") + "]",
                       "--set", "groundlink.key_file=", "--set", "groundlink.insecure=true"},
                      {}, dir.path());
    const auto autopilot = [&] {
        const auto r = run({binary("client/airsegctl"), "--local", "--socket", dir.file("status.sock"),
                            "--json", "--timeout", "5000", "status"},
                           {}, 30s);
        const auto j = Json::parse(r.out, nullptr, false);
        return r.exit_code == 0 && j.is_object() ? j.value("autopilot", Json()) : Json();
    };
    ASSERT_TRUE(wait_until([&] { return autopilot().is_object(); }, kGenerous, kPoll)) << daemon.err();

    mavlink::Encoder board(1, 1);
    const auto put = [&](const auto& message) {
        const auto bytes = board.encode(message);
        EXPECT_EQ(::write(master, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
        std::array<std::uint8_t, 4096> sink{};
        while (::read(master, sink.data(), sink.size()) > 0) {
            // what the daemon asks of the board goes unanswered
        }
    };
    mavlink::Heartbeat hb;
    hb.type = 10;
    hb.autopilot = 3;
    hb.base_mode = 1;
    hb.custom_mode = 4;    // HOLD
    hb.system_status = 3;  // STANDBY
    put(hb);
    ASSERT_TRUE(wait_until([&] { return autopilot().value("link", "") == "up"; }, kGenerous, kPoll))
        << daemon.err();
    const auto log_before = daemon.err().size();
    mavlink::GlobalPositionInt position;
    position.lat = 412756000;
    position.lon = 19866000;
    const auto start = std::chrono::steady_clock::now();
    for (int frame = 0; std::chrono::steady_clock::now() - start < 5s; ++frame) {
        if (frame % 200 == 0) {
            put(hb);
        }
        position.time_boot_ms = frame % 2 == 0 ? 0xFFFFFFFFu : 0u;
        put(position);
        std::this_thread::sleep_for(5ms);  // the board's pace, not a wait for an outcome
    }
    put(hb);
    const auto ap = autopilot();
    const auto log_growth = daemon.err().size() - log_before;
    EXPECT_EQ(ap.value("reboots", 99), 0) << ap.dump() << daemon.err().substr(0, 4000);
    EXPECT_EQ(ap.value("link", ""), "up") << ap.dump();
    EXPECT_EQ(daemon.err().find("rebooted"), std::string::npos);
    EXPECT_LT(log_growth, 4096u) << daemon.err().substr(log_before, 4000);
    std::cout << "[ figures ] time_boot_ms flipping 2^32-1/0 for 5 s at 200 frames/s: "
              << ap.value("reboots", 99) << " reboots, " << log_growth << " bytes of log\n";
    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.wait_exit(10s), 0) << daemon.err();
    ::close(master);
    ::close(slave);
}

}  // namespace
}  // namespace airseg::test

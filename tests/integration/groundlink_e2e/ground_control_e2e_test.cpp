// The operator's side over the radio, end to end on real ptys: airseg-apmsim ⇄ airsegd ⇄ airseg-linksim
// (57600 baud) ⇄ airsegctl. Pushed telemetry, roles by key, joystick driving, and a lossy link.
#include <fcntl.h>
#include <gtest/gtest.h>

#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <map>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "services/autopilot/mavlink/parser.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"
#include "services/groundlink/transport/transport.hpp"
#include "tests/support/control_client.hpp"
#include "tests/support/ground_station.hpp"
#include "tests/support/json_lines.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

using Json = nlohmann::json;
constexpr auto kGenerous = 60s;
constexpr double kHomeLat = 41.2756;
constexpr double kHomeLon = 1.9866;

using SimControl = ControlClient;

bool exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

class GroundControlE2e : public ::testing::Test {
  protected:
    void TearDown() override {
        if (daemon && daemon->running()) {
            daemon->signal(SIGTERM);
            daemon->wait_exit(10s);
        }
    }

    void start_link(std::vector<std::string> impairments = {}) {
        std::vector<std::string> args{binary("tools/linksim/airseg-linksim"),
                                      "--a",
                                      dir.file("air"),
                                      "--b",
                                      ground(),
                                      "--baud",
                                      "57600",
                                      "--seed",
                                      "11",
                                      "--control",
                                      dir.file("linksim.ctl")};
        args.insert(args.end(), impairments.begin(), impairments.end());
        linksim = std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir.path());
        ASSERT_TRUE(wait_until([&] { return exists(dir.file("air")) && exists(ground()); }))
            << linksim->err();
    }

    void start_sim(std::vector<std::string> extra = {}) {
        std::vector<std::string> args{binary("tools/apmsim/airseg-apmsim"),
                                      "--link",
                                      dir.file("ttyACM0"),
                                      "--control",
                                      dir.file("sim.ctl"),
                                      "--home",
                                      std::to_string(kHomeLat) + "," + std::to_string(kHomeLon),
                                      "--boot-delay",
                                      "0.5",
                                      "--calib-time",
                                      "0.5",
                                      "--quiet"};
        args.insert(args.end(), extra.begin(), extra.end());
        sim = std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir.path());
        ASSERT_TRUE(wait_until([&] { return exists(dir.file("ttyACM0")) && exists(dir.file("sim.ctl")); }))
            << sim->err();
        sim_control = std::make_unique<SimControl>(dir.file("me.ctl"), dir.file("sim.ctl"));
    }

    void start_daemon(std::vector<std::string> extra = {}) {
        std::vector<std::string> args{binary("daemon/airsegd"),
                                      "--config",
                                      source_path("config/airseg.yaml"),
                                      "--set",
                                      "status.socket=" + dir.file("status.sock"),
                                      "--set",
                                      "state_dir=" + dir.file("state"),
                                      "--set",
                                      "autopilot.port=" + dir.file("ttyACM0"),
                                      "--set",
                                      "autopilot.reconnect_max=500ms",
                                      "--set",
                                      "groundlink.ports=[" + dir.file("air") + "]"};
        const auto unkeyed = unkeyed_ground_link();
        args.insert(args.end(), unkeyed.begin(), unkeyed.end());
        args.insert(args.end(), extra.begin(), extra.end());
        daemon = std::make_unique<Subprocess>(args, std::map<std::string, std::string>{}, dir.path());
    }

    /// The link, the simulated rover at speedup 4 and the daemon, until the daemon says the autopilot is
    /// ready.
    void start_ready_vehicle() {
        start_link();
        start_sim({"--speedup", "4"});
        start_daemon();
        ASSERT_TRUE(
            wait_until([&] { return status_doc().value("autopilot", Json::object()).value("ready", false); },
                       kGenerous, 500ms))
            << daemon->err();
    }

    /// airsegctl over the radio; `key` empty = unkeyed link.
    RunResult ctl(std::vector<std::string> args, const std::string& key = {}, long timeout_ms = 30'000) {
        std::vector<std::string> argv{binary("client/airsegctl"), "--link", ground(), "--timeout",
                                      std::to_string(timeout_ms), "--json"};
        if (!key.empty()) {
            argv.insert(argv.end(), {"--key", key});
        }
        argv.insert(argv.end(), args.begin(), args.end());
        return run(argv, {}, std::chrono::milliseconds(timeout_ms + 60'000));
    }

    Json status_doc(const std::string& key = {}) {
        auto r = ctl({"status"}, key);
        auto j = Json::parse(r.out, nullptr, false);
        return r.exit_code == 0 && !j.is_discarded() ? j : Json::object();
    }

    std::string key_file(const std::string& name, char fill) {
        const auto path = dir.file(name);
        write_file(path, std::string(64, fill) + "\n");
        ::chmod(path.c_str(), 0600);
        return path;
    }

    std::string ground() const { return dir.file("ground"); }

    TempDir dir;
    std::unique_ptr<Subprocess> linksim, sim, daemon;
    std::unique_ptr<SimControl> sim_control;
};

TEST_F(GroundControlE2e, StatusAndPushedTelemetryOverTheRadio) {
    start_link();
    start_sim();
    // This case counts the pushed samples at the requested rate, so the vehicle's samples have a floor of
    // 2 Hz however weak the link is judged: under qemu-arm beside the rest of the suite the daemon's own
    // delays are seen as loss (a run measured 25 %), the weak-link factor halves every 2 s of it, and 6 s of
    // watching at half the rate had no sample to spare. The lowering and recovery have their own tests
    // (TelemetryScheduler.LowersUnderAWeakLink…).
    start_daemon({"--set", "groundlink.telemetry.min_hz=2"});
    Json doc;
    ASSERT_TRUE(wait_until(
        [&] {
            doc = status_doc();
            return doc.value("autopilot", Json::object()).value("ready", false) &&
                   doc["autopilot"]["position"].is_object();
        },
        kGenerous, 500ms))
        << doc.dump() << "\ndaemon:\n"
        << daemon->err();
    EXPECT_TRUE(doc["autopilot"]["state"].is_string());
    EXPECT_NEAR(doc["autopilot"]["position"]["lat"].get<double>(), kHomeLat, 1e-3);
    EXPECT_EQ(doc["groundlink"]["link"], "up");
    EXPECT_GE(doc["groundlink"]["frames_received"].get<int>(), 1);
    // The rates: as requested, whatever the link's factor (the floor, see above, is above both).
    const auto& telemetry = doc["groundlink"]["telemetry"];
    EXPECT_EQ(telemetry["requested_hz"]["vehicle"], 2.0) << telemetry.dump();
    EXPECT_NEAR(telemetry["effective_hz"]["vehicle"].get<double>(), 2.0, 0.001) << telemetry.dump();
    EXPECT_NEAR(telemetry["effective_hz"]["link_stats"].get<double>(), 1.0, 0.001) << telemetry.dump();

    // watch over the radio: the pushed samples, not the status document.
    auto watch = ctl({"watch", "--duration", "6000"});
    ASSERT_EQ(watch.exit_code, 0) << watch.err;
    const auto lines = json_lines(watch.out);
    ASSERT_FALSE(lines.empty()) << watch.out;
    // One view per interval (500 ms), whatever comes over the link: a bounded output.
    EXPECT_LE(lines.size(), 13u) << watch.out.substr(0, 3000);
    const auto& last = lines.back();
    // 2 Hz for 6 s: 12 samples; a sample lost on the half-duplex radio is not sent again (the freshest goes).
    EXPECT_GE(last["samples"].get<int>(), 6) << last.dump();
    EXPECT_NEAR(last["vehicle"]["lat"].get<double>(), kHomeLat, 1e-3) << last.dump();
    EXPECT_TRUE(last["vehicle"]["state"].is_string());
    EXPECT_TRUE(last.contains("vehicle_link")) << "link statistics are pushed too: " << last.dump();

    // The rates can be changed from the ground and status shows them.
    auto rates = ctl({"rates", "vehicle=5"});
    ASSERT_EQ(rates.exit_code, 0) << rates.err;
    const auto changed = Json::parse(rates.out);
    EXPECT_EQ(changed["requested_hz"]["vehicle"], 5.0) << changed.dump();
    EXPECT_NEAR(changed["effective_hz"]["vehicle"].get<double>(),
                std::max(2.0, 5.0 * changed["factor"].get<double>()), 0.001)
        << changed.dump();
    auto params = ctl({"param", "get", "WP_RADIUS"});
    EXPECT_EQ(params.exit_code, 0) << params.err;
    EXPECT_TRUE(Json::parse(params.out, nullptr, false).value("value", Json()).is_number()) << params.out;
}

// A plan sent over the radio as one Safe message (the file is read on the ground), driven by the simulated
// rover; show, pause, resume and skip each acknowledged, and the pushed telemetry carries the plan's
// progress. The plan is long enough that it still runs when the watch ends: 15 legs after the skip, about
// 25 s at speedup 4, where a 12-point plan could end before a slow client's watch did (its last sample then
// said "done", next_waypoint 0).
TEST_F(GroundControlE2e, APlanLoadedOverTheRadioIsDrivenPausedResumedAndSkipped) {
    start_ready_vehicle();
    if (HasFatalFailure()) {
        return;
    }
    const std::string plan = dir.file("square.yaml");
    std::string elements;
    for (int i = 1; i <= 24; ++i) {
        elements += "    - waypoint: {lat: " + std::to_string(kHomeLat + 0.00008 * (i % 2)) +
                    ", lon: " + std::to_string(kHomeLon + 0.0001 * i) + "}\n";
    }
    write_file(plan, "plan:\n  name: radio-square\n  vehicle: {type: rover}\n  elements:\n" + elements);

    auto load = ctl({"plan", "load", plan});
    ASSERT_EQ(load.exit_code, 0) << load.out << load.err << "\ndaemon:\n" << daemon->err();
    Json shown;
    auto plan_show = [&] {
        auto r = ctl({"plan", "show"});
        shown = Json::parse(r.out, nullptr, false);
        return r.exit_code == 0 && !shown.is_discarded();
    };
    ASSERT_TRUE(
        wait_until([&] { return plan_show() && shown.value("waypoints_reached", 0) >= 2; }, kGenerous, 500ms))
        << shown.dump();
    EXPECT_EQ(shown["name"], "radio-square");
    EXPECT_EQ(shown["state"], "running");

    auto pause = ctl({"plan", "pause"});
    ASSERT_EQ(pause.exit_code, 0) << pause.out << pause.err;
    ASSERT_TRUE(plan_show());
    EXPECT_EQ(shown["state"], "paused");
    EXPECT_EQ(status_doc()["autopilot"]["state"], "PARKING");

    auto resume = ctl({"plan", "resume"});
    ASSERT_EQ(resume.exit_code, 0) << resume.out << resume.err;
    auto skip = ctl({"plan", "skip", "9"});
    ASSERT_EQ(skip.exit_code, 0) << skip.out << skip.err;
    ASSERT_TRUE(plan_show());
    EXPECT_EQ(shown["state"], "running");
    EXPECT_GE(shown.value("next_waypoint", 0), 9) << shown.dump();

    auto watch = ctl({"watch", "--duration", "3000"});
    ASSERT_EQ(watch.exit_code, 0) << watch.err;
    const auto lines = json_lines(watch.out);
    ASSERT_FALSE(lines.empty()) << watch.out;
    int running = 0;
    for (const auto& line : lines) {
        if (line["vehicle"].is_null()) {
            continue;  // a line printed before the first sample
        }
        ASSERT_TRUE(line["vehicle"].contains("plan"))
            << "the pushed samples carry the plan's progress: " << line.dump();
        const auto& progress = line["vehicle"]["plan"];
        if (progress["state"] == "running") {
            ++running;
            EXPECT_GE(progress["next_waypoint"].get<int>(), 9) << line.dump();
        }
    }
    EXPECT_GT(running, 0) << "no sample of the running plan in the watch:\n" << watch.out;
    // Events in plan terms, once per waypoint: not the window's slots, nor the board's texts about them,
    // in the words the map uses too (groundside/event_wording.hpp): "waypoint 11 reached", numbered from 1.
    // `log` follows the events until two waypoints are reached: by then the board's slot events and texts
    // of those reaches would have come too. `watch` runs alongside and lists the same lines.
    Subprocess log({binary("client/airsegctl"), "--link", ground(), "--json", "log", "--duration", "120000"},
                   {}, dir.path());
    const auto reached_in = [&](const std::string& out) {
        std::map<std::string, int> per_waypoint;  // "waypoint 11 reached" -> lines
        for (const auto& e : json_lines(out)) {
            const auto text = e.value("text", "");
            if (text.starts_with("waypoint ") && text.ends_with(" reached")) {
                ++per_waypoint[text];
            }
        }
        return per_waypoint;
    };
    EXPECT_TRUE(wait_until([&] { return reached_in(log.out()).size() >= 2; }, kGenerous, 500ms)) << log.out();
    log.signal(SIGTERM);
    ASSERT_TRUE(log.wait_exit(kGenerous));
    for (const auto& e : json_lines(log.out())) {
        const auto text = e.value("text", "");
        EXPECT_EQ(text.find("mission slot"), std::string::npos) << text;
        EXPECT_EQ(text.find("Reached waypoint #"), std::string::npos) << text;
        EXPECT_EQ(text.find("flight plan received"), std::string::npos) << text;
        EXPECT_EQ(text.find("plan waypoint"), std::string::npos) << "the vehicle's words, reworded: " << text;
        EXPECT_FALSE(e.contains("raw")) << "the vehicle's own words only with --debug";
    }
    const auto per_waypoint = reached_in(log.out());
    EXPECT_GE(per_waypoint.size(), 2u) << log.out() << log.err();
    for (const auto& [line, n] : per_waypoint) {
        EXPECT_EQ(n, 1) << "one line per waypoint: " << line << "\n" << log.out();
        // Numbered in plan terms: past the skip to index 9, the first reached is waypoint 10 or later.
        EXPECT_GE(std::stoi(line.substr(9)), 10) << line;
    }
    const auto folded = status_doc()["groundlink"].value("events_folded", 0);
    EXPECT_GT(folded, 0) << "the board's slot events and texts are counted";
}

// Another plan loaded over the running one (here on the board's own socket) leaves the plan "running": the
// vehicle announces it, and `log` over the radio says so, asks for the new plan's count while the events go
// on, and numbers the new plan's waypoints "of" its own count, never the last plan's.
TEST_F(GroundControlE2e, AnotherPlanOverTheRunningOneIsAnnouncedAndLogCountsItsWaypoints) {
    start_ready_vehicle();
    if (HasFatalFailure()) {
        return;
    }
    const auto zigzag = [&](const std::string& name, int legs, double lat_offset) {
        const std::string path = dir.file(name + ".yaml");
        std::string elements;
        for (int i = 1; i <= legs; ++i) {
            elements += "    - waypoint: {lat: " + std::to_string(kHomeLat + lat_offset + 0.00008 * (i % 2)) +
                        ", lon: " + std::to_string(kHomeLon + 0.0001 * i) + "}\n";
        }
        write_file(path, "plan:\n  name: " + name + "\n  vehicle: {type: rover}\n  elements:\n" + elements);
        return path;
    };
    auto first = ctl({"plan", "load", zigzag("long-one", 24, 0)});
    ASSERT_EQ(first.exit_code, 0) << first.out << first.err << "\ndaemon:\n" << daemon->err();

    Subprocess log({binary("client/airsegctl"), "--link", ground(), "--json", "log", "--duration", "120000"},
                   {}, dir.path());
    const auto texts = [&] {
        std::vector<std::string> out;
        for (const auto& e : json_lines(log.out())) {
            out.push_back(e.value("text", ""));
        }
        return out;
    };
    const auto has = [&](const std::function<bool(const std::string&)>& pred) {
        const auto t = texts();
        return std::find_if(t.begin(), t.end(), pred) != t.end();
    };
    // "waypoint N of COUNT reached": the count `log` knows for the plan that drives.
    const auto counted = [](int count) {
        return [suffix = " of " + std::to_string(count) + " reached"](const std::string& t) {
            return t.ends_with(suffix);
        };
    };
    const auto wait_for_count = [&](int count, const char* why) {
        return wait_until([&] { return has(counted(count)); }, kGenerous, 500ms)
                   ? ::testing::AssertionSuccess()
                   : ::testing::AssertionFailure() << why << ":\n"
                                                   << log.out() << log.err();
    };
    ASSERT_TRUE(wait_for_count(24, "the running plan's count, asked as the log starts"));

    const auto second = run({binary("client/airsegctl"), "--local", "--socket", dir.file("status.sock"),
                             "--json", "plan", "load", zigzag("short-one", 10, 0.00004)});
    ASSERT_EQ(second.exit_code, 0) << second.out << second.err;
    EXPECT_TRUE(wait_for_count(10, "the new plan's count, asked when it was announced"));
    // An append grows the count of the plan that drives: announced too, and asked again.
    const auto appended = run({binary("client/airsegctl"), "--local", "--socket", dir.file("status.sock"),
                               "--json", "plan", "append", zigzag("more-one", 6, 0.00008)});
    ASSERT_EQ(appended.exit_code, 0) << appended.out << appended.err;
    EXPECT_TRUE(wait_for_count(16, "the count after the append"));
    log.signal(SIGTERM);
    ASSERT_TRUE(log.wait_exit(kGenerous));

    // Each announcement comes once, and the count from before it is never used after it.
    const auto all = texts();
    const auto announced_once_then_not_counted_by = [&](const std::function<bool(const std::string&)>& is_it,
                                                        int old_count) {
        const auto at = std::find_if(all.begin(), all.end(), is_it);
        ASSERT_NE(at, all.end()) << log.out();
        EXPECT_EQ(std::count_if(all.begin(), all.end(), is_it), 1) << log.out();
        for (auto it = at; it != all.end(); ++it) {
            EXPECT_FALSE(counted(old_count)(*it))
                << "the count from before the announcement, after it: " << *it << "\n"
                << log.out();
        }
    };
    announced_once_then_not_counted_by([](const std::string& t) { return t == "plan 'short-one' started"; },
                                       24);
    announced_once_then_not_counted_by(
        [](const std::string& t) { return t.starts_with("plan '") && t.ends_with("' extended"); }, 10);
}

TEST_F(GroundControlE2e, AMonitorKeyWatchesButItsCommandsAreRefused) {
    const auto control = key_file("control.key", 'a');
    const auto monitor = key_file("monitor.key", 'b');
    start_link();
    start_daemon(
        {"--set", "groundlink.key_file=" + control, "--set", "groundlink.monitor_key_file=" + monitor});

    auto watched = ctl({"status"}, monitor);
    ASSERT_EQ(watched.exit_code, 0) << watched.err << "\ndaemon:\n" << daemon->err();
    EXPECT_EQ(Json::parse(watched.out)["groundlink"]["role"], "monitor");

    auto refused = ctl({"rates", "vehicle=4"}, monitor);
    EXPECT_EQ(refused.exit_code, 1) << refused.err;
    const auto why = Json::parse(refused.out, nullptr, false);
    EXPECT_EQ(why.value("status", ""), "forbidden") << refused.out;
    EXPECT_NE(why.value("error", "").find("monitor key"), std::string::npos) << refused.out;
    auto stick = ctl({"joystick", "--duration", "500"}, monitor);
    EXPECT_EQ(stick.exit_code, 1) << stick.err;

    // The control key commands; status counts the refusals.
    auto accepted = ctl({"rates", "vehicle=4"}, control);
    ASSERT_EQ(accepted.exit_code, 0) << accepted.err << "\ndaemon:\n" << daemon->err();
    const auto doc = status_doc(control);
    EXPECT_EQ(doc["groundlink"]["role"], "control");
    EXPECT_EQ(doc["groundlink"]["commands_refused"], 2);
    EXPECT_EQ(doc["groundlink"]["telemetry"]["requested_hz"]["vehicle"], 4.0);

    // No key at all gets nowhere.
    auto stranger = ctl({"status"}, {}, 3'000);
    EXPECT_EQ(stranger.exit_code, 3);
}

TEST_F(GroundControlE2e, AClientWithoutTheVehiclesKeyIsToldItIsNotAuthorised) {
    const auto control = key_file("control.key", 'a');
    const auto other = key_file("other.key", 'c');
    start_link();
    start_daemon({"--set", "groundlink.key_file=" + control});

    // Told at once, not after the whole timeout: the vehicle's handshakes carry a tag this end cannot check.
    const auto started = std::chrono::steady_clock::now();
    auto stranger = ctl({"status"}, {}, 60'000);
    EXPECT_EQ(stranger.exit_code, 3) << stranger.err;
    EXPECT_NE(stranger.err.find("not authorised"), std::string::npos) << stranger.err;
    EXPECT_NE(stranger.err.find("--key"), std::string::npos) << stranger.err;
    EXPECT_EQ(Json::parse(stranger.out, nullptr, false).value("status", ""), "not_authorised")
        << stranger.out;
    EXPECT_LT(std::chrono::steady_clock::now() - started, 30s);

    auto wrong = ctl({"status"}, other, 60'000);
    EXPECT_EQ(wrong.exit_code, 3) << wrong.err;
    EXPECT_NE(wrong.err.find("not authorised"), std::string::npos) << wrong.err;

    auto right = ctl({"rates", "vehicle=4"}, control);
    EXPECT_EQ(right.exit_code, 0) << right.err << "\ndaemon:\n" << daemon->err();
}

TEST_F(GroundControlE2e, AVehicleWithoutAKeyRefusesEveryCommandAndSaysWhy) {
    start_link();
    start_daemon({"--set", "groundlink.insecure=false"});

    auto refused = ctl({"rates", "vehicle=4"});
    EXPECT_EQ(refused.exit_code, 1) << refused.err << "\ndaemon:\n" << daemon->err();
    const auto why = Json::parse(refused.out, nullptr, false);
    EXPECT_EQ(why.value("status", ""), "forbidden") << refused.out;
    EXPECT_NE(why.value("error", "").find("not authorised"), std::string::npos) << refused.out;
    EXPECT_NE(why.value("error", "").find("groundlink.insecure"), std::string::npos) << refused.out;
    auto stick = ctl({"joystick", "--duration", "500"});
    EXPECT_EQ(stick.exit_code, 1) << stick.err;

    const auto doc = status_doc();
    ASSERT_TRUE(doc.contains("groundlink")) << daemon->err();
    EXPECT_EQ(doc["groundlink"]["commands_refused"], 2);  // the rates and the joystick's mode change
    EXPECT_NE(doc["groundlink"]["role"].get<std::string>().find("commands refused"), std::string::npos);
    EXPECT_NE(doc["groundlink"].value("commands_refused_because", "").find("groundlink.key_file"),
              std::string::npos)
        << doc.dump();
    EXPECT_EQ(doc["groundlink"]["telemetry"]["requested_hz"]["vehicle"], 2.0)
        << "the refused rate was not set";
    EXPECT_NE(daemon->err().find("groundlink.insecure is not set"), std::string::npos) << daemon->err();
}

TEST_F(GroundControlE2e, AnInsecureVehicleWarnsAtStartAndTakesCommandsWithoutAKey) {
    start_link();
    start_daemon();  // groundlink.insecure: true, no key (unkeyed_ground_link)
    auto accepted = ctl({"rates", "vehicle=4"});
    EXPECT_EQ(accepted.exit_code, 0) << accepted.err << "\ndaemon:\n" << daemon->err();
    EXPECT_NE(daemon->err().find("groundlink.insecure is set"), std::string::npos) << daemon->err();
    EXPECT_EQ(status_doc()["groundlink"]["role"], "control (unauthenticated, groundlink.insecure)");
}

TEST_F(GroundControlE2e, JoystickDrivesTheRoverAndTheOverrideIsReleasedWhenInputStops) {
    start_link();
    start_sim();
    start_daemon();
    ASSERT_TRUE(
        wait_until([&] { return status_doc().value("autopilot", Json::object()).value("ready", false); },
                   kGenerous, 500ms))
        << daemon->err();
    auto manual = ctl({"state", "MANUAL_NAVIGATION"});
    ASSERT_EQ(manual.exit_code, 0) << manual.err << manual.out;
    const auto start = sim_control->try_json("state");

    // The joystick device is a FIFO standing in for /dev/input/js0: the test writes js_event records.
    const auto fifo = dir.file("js0");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const int writer = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    ASSERT_GE(writer, 0);
    Subprocess stick({binary("client/airsegctl"), "--link", ground(), "--timeout", "30000", "joystick",
                      "--device", fifo, "--rate", "10"},
                     {}, dir.path());
    auto event = [&](std::int16_t value, std::uint8_t axis) {
        std::uint8_t e[8] = {0, 0, 0, 0, 0, 0, 0x02, axis};
        std::memcpy(e + 4, &value, 2);  // struct js_event is in the host's byte order
        ASSERT_EQ(::write(writer, e, sizeof e), 8);
    };
    event(-32767, 1);  // full forward
    event(8000, 0);    // a little right
    double moved = 0;
    ASSERT_TRUE(wait_until(
        [&] {
            const auto s = sim_control->try_json("state");
            const double dlat = (s.value("lat", 0.0) - start.value("lat", 0.0)) * 111'000;
            const double dlon =
                (s.value("lon", 0.0) - start.value("lon", 0.0)) * 111'000 * std::cos(kHomeLat * M_PI / 180);
            moved = std::hypot(dlat, dlon);
            return moved > 3.0 && s.value("speed", 0.0) > 0.5;
        },
        kGenerous, 200ms))
        << "moved " << moved << " m; sim: " << sim_control->try_json("state").dump() << "\nclient:\n"
        << stick.err() << "\ndaemon:\n"
        << daemon->err();

    // Input stops (the device goes away): the client ends, the vehicle releases the override and stops.
    ::close(writer);
    ASSERT_EQ(stick.wait_exit(10s), 0) << stick.err();
    const auto stopped_at = std::chrono::steady_clock::now();
    ASSERT_TRUE(
        wait_until([&] { return sim_control->try_json("state").value("speed", 1.0) < 0.05; }, 20s, 100ms))
        << sim_control->try_json("state").dump();
    // Override released within the configured input timeout (500 ms), plus the rover coasting to a stop.
    const auto to_stop = std::chrono::steady_clock::now() - stopped_at;
    EXPECT_LT(to_stop, 10s);
    std::cout << "joystick: moved " << moved << " m; stopped "
              << std::chrono::duration_cast<std::chrono::milliseconds>(to_stop).count()
              << " ms after the client ended\n";
}

TEST_F(GroundControlE2e, WithTwentyPercentFrameLossTelemetryArrivesAndEveryCommandIsAnswered) {
    start_link({"--frame-loss", "0.2"});
    start_sim();
    start_daemon();
    ASSERT_TRUE(
        wait_until([&] { return status_doc().value("autopilot", Json::object()).value("ready", false); },
                   kGenerous, 500ms))
        << daemon->err();
    auto watch = ctl({"watch", "--duration", "20000"});
    ASSERT_EQ(watch.exit_code, 0) << watch.err;
    const auto lines = json_lines(watch.out);
    ASSERT_FALSE(lines.empty());
    const int samples = lines.back()["samples"].get<int>();
    EXPECT_GE(samples, 3) << "telemetry still arrives: " << lines.back().dump();
    EXPECT_LT(samples, 2 * 20 + 1) << "never above the requested 2 Hz";
    // The vehicle measured the loss from the ground's reception reports and lowered the rates.
    const auto lowered = status_doc()["groundlink"]["telemetry"];
    EXPECT_GE(lowered.value("lowerings", 0), 1) << lowered.dump();
    EXPECT_LT(lowered["effective_hz"].value("vehicle", 2.0), 2.0) << lowered.dump();
    EXPECT_GT(lowered["effective_hz"].value("vehicle", 0.0), 0.0) << lowered.dump();

    int answered = 0;
    for (const auto& cmd : std::vector<std::vector<std::string>>{{"rates"},
                                                                 {"param", "get", "WP_RADIUS"},
                                                                 {"state", "PARKING"},
                                                                 {"rates", "link_stats=1"},
                                                                 {"status"}}) {
        auto r = ctl(cmd, {}, 45'000);
        EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1)
            << cmd[0] << ": exit " << r.exit_code << " " << r.err;
        EXPECT_FALSE(r.out.empty() && r.err.empty()) << "a failure is reported, never silent";
        answered += r.exit_code == 0 ? 1 : 0;
    }
    EXPECT_GE(answered, 4);
    const auto doc = status_doc();
    std::cout << "under 20 % frame loss: " << samples << " samples in 20 s; vehicle telemetry "
              << doc["groundlink"]["telemetry"].dump() << "\n";
}

TEST_F(GroundControlE2e, SighupAppliesTheTelemetryRatesOverThoseSetFromTheGround) {
    const std::string config = dir.file("airseg.yaml");
    const std::string original = read_file(source_path("config/airseg.yaml"));
    write_file(config, original);
    daemon = std::make_unique<Subprocess>(
        std::vector<std::string>{
            binary("daemon/airsegd"), "--config", config, "--set", "status.socket=" + dir.file("status.sock"),
            "--set", "state_dir=" + dir.file("state"), "--set", "autopilot.port=" + dir.file("ttyACM0"),
            "--set", "groundlink.ports=[" + dir.file("air") + "]", "--set", "groundlink.key_file=", "--set",
            "groundlink.insecure=true"},
        std::map<std::string, std::string>{}, dir.path());
    auto local = [&](std::vector<std::string> args) {
        std::vector<std::string> argv{binary("client/airsegctl"), "--local", "--socket",
                                      dir.file("status.sock"), "--json"};
        argv.insert(argv.end(), args.begin(), args.end());
        auto r = run(argv, {}, 20s);
        auto j = Json::parse(r.out, nullptr, false);
        return r.exit_code == 0 && !j.is_discarded() ? j : Json::object();
    };
    ASSERT_TRUE(wait_until([&] { return local({"rates"}).contains("requested_hz"); }, 20s)) << daemon->err();
    EXPECT_EQ(local({"rates", "vehicle=7"})["requested_hz"]["vehicle"], 7.0);

    std::string changed = original;
    const std::string from = "rates: {vehicle: 2, link_stats: 1}";
    ASSERT_NE(changed.find(from), std::string::npos);
    changed.replace(changed.find(from), from.size(), "rates: {vehicle: 4, link_stats: 0}");
    write_file(config, changed);
    daemon->signal(SIGHUP);
    ASSERT_TRUE(
        wait_until([&] { return local({"rates"})["requested_hz"].value("vehicle", 0.0) == 4.0; }, 20s))
        << daemon->err();
    const auto rates = local({"rates"});
    EXPECT_EQ(rates["effective_hz"]["link_stats"], 0.0) << rates.dump();
    EXPECT_NE(daemon->err().find("groundlink.telemetry.rates"), std::string::npos) << daemon->err();
}

/// A ground end of the radio link in the test itself, over UDP: the transport core and the ground protocol,
/// as a ground daemon serving standard ground stations runs them.
class GroundEnd {
  public:
    explicit GroundEnd(int port) : transport_(config(), airseg::SteadyClock::now()) {
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        to.sin_port = htons(static_cast<std::uint16_t>(port));
        ::connect(fd_, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    ~GroundEnd() { ::close(fd_); }
    GroundEnd(const GroundEnd&) = delete;
    GroundEnd& operator=(const GroundEnd&) = delete;

    /// Sends whole MAVLink frames to the vehicle (Safe, bulk channel).
    void send(const std::vector<std::uint8_t>& frames) {
        namespace proto = airseg::groundlink::protocol;
        transport_.send_safe(proto::kPriorityBulk, proto::encode(proto::MavlinkFrames{frames}),
                             airseg::SteadyClock::now());
        pump();
    }
    /// Runs the link until `found` accepts a frame from the vehicle or `limit` has passed.
    bool hear(const std::function<bool(const airseg::mavlink::Frame&)>& found,
              std::chrono::milliseconds limit) {
        const auto end = std::chrono::steady_clock::now() + limit;
        bool seen = false;
        while (!seen && std::chrono::steady_clock::now() < end) {
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 20) > 0) {
                std::array<std::uint8_t, 4096> buf{};
                const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
                if (n > 0) {
                    transport_.handle_bytes(0, std::span(buf).first(static_cast<std::size_t>(n)),
                                            airseg::SteadyClock::now());
                }
            }
            pump();
            while (auto m = transport_.poll_message()) {
                const auto d = airseg::groundlink::protocol::decode(m->bytes);
                if (const auto* f =
                        d.message ? std::get_if<airseg::groundlink::protocol::MavlinkFrames>(&*d.message)
                                  : nullptr) {
                    ++messages_;
                    airseg::mavlink::Parser parser;
                    parser.push(f->bytes,
                                [&](const airseg::mavlink::Frame& frame) { seen = seen || found(frame); });
                }
            }
        }
        return seen;
    }
    std::size_t messages() const { return messages_; }

  private:
    static airseg::groundlink::TransportConfig config() {
        airseg::groundlink::TransportConfig c;
        c.half_duplex = false;
        c.boot_nonce = 0x5eed;
        return c;
    }
    void pump() {
        const auto now = airseg::SteadyClock::now();
        if (transport_.poll_timeout() <= now) {
            transport_.handle_timeout(now);
        }
        while (auto frame = transport_.poll_transmit(0, now)) {
            ::send(fd_, frame->data(), frame->size(), 0);
        }
    }

    int fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    airseg::groundlink::Transport transport_;
    std::size_t messages_ = 0;
};

// A standard ground station's MAVLink through the radio link (groundlink.mavlink_forward): the ground end
// hears the board's telemetry, reads a parameter, and clearing the mission is answered DENIED by airsegd, the
// board's mission untouched; the status document counts both directions.
TEST_F(GroundControlE2e, MavlinkForwardCarriesAGroundStationsTrafficAndRefusesMissionClears) {
    start_sim();
    const int port = free_udp_port();
    start_daemon({"--set", "groundlink.mode=udp", "--set", "groundlink.udp.bind=127.0.0.1", "--set",
                  "groundlink.udp.port=" + std::to_string(port), "--set",
                  "groundlink.mavlink_forward.enabled=true", "--set",
                  "groundlink.mavlink_forward.rates={ATTITUDE: 2, default: 1}"});
    const auto local_status = [&] {
        auto r = run(
            {binary("client/airsegctl"), "--local", "--socket", dir.file("status.sock"), "--json", "status"});
        auto j = Json::parse(r.out, nullptr, false);
        return r.exit_code == 0 && !j.is_discarded() ? j : Json::object();
    };
    ASSERT_TRUE(
        wait_until([&] { return local_status().value("autopilot", Json::object()).value("ready", false); },
                   kGenerous, 500ms))
        << daemon->err();

    GroundEnd ground_end(port);
    GroundStation gcs;
    EXPECT_TRUE(ground_end.hear(GroundStation::board_heartbeat, 20s)) << daemon->err();
    ground_end.send(gcs.read_param("CRUISE_SPEED"));
    EXPECT_TRUE(ground_end.hear(
        [](const airseg::mavlink::Frame& f) { return GroundStation::param_value(f, "CRUISE_SPEED"); }, 20s));

    const auto mission_before = sim_control->json("state")["mission_count"];
    ground_end.send(gcs.mission_clear());
    EXPECT_TRUE(ground_end.hear(GroundStation::mission_denied, 20s));
    EXPECT_EQ(sim_control->json("state")["mission_count"], mission_before);

    // The section is refreshed once a second.
    Json fwd;
    EXPECT_TRUE(wait_until(
        [&] {
            fwd = local_status()["groundlink"]["mavlink_forward"];
            return fwd.is_object() && fwd["forwarded"].get<int>() > 3 && fwd["from_ground"] == 2;
        },
        10s, 200ms))
        << fwd.dump();
    EXPECT_EQ(fwd["enabled"], true) << fwd.dump();
    EXPECT_EQ(fwd["budget_bytes_per_s"], 1728) << fwd.dump();
}

}  // namespace
}  // namespace airseg::test

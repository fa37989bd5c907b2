// The ground station hub end to end on real ptys: airseg-apmsim ⇄ airsegd ⇄ airseg-linksim (57600 baud) ⇄
// airseg-ground ⇄ several airsegctl at once. Watchers and one operator share the one radio session; the
// operator's plan reaches every watcher; a monitor's command is refused by the vehicle; control is held by
// one client at a time.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <iostream>

#include <nlohmann/json.hpp>

#include "client/hub_client.hpp"
#include "groundside/hub_wire.hpp"
#include "tests/support/control_client.hpp"
#include "tests/support/ground_chain.hpp"
#include "tests/support/json_lines.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

using Json = nlohmann::json;
constexpr auto kGenerous = 60s;
constexpr double kHomeLat = GroundChain::kHomeLat;
constexpr double kHomeLon = GroundChain::kHomeLon;

class GroundHubE2e : public ::testing::Test {
  protected:
    /// `mavlink_udp`: where the hub sends the vehicle's MAVLink; off but for the test that plays the ground
    /// station (on a reserved port), so that no other hub's vehicle reaches it.
    void start_chain(const std::string& mavlink_udp = "off") {
        chain = std::make_unique<GroundChain>(
            dir.path(), std::vector<std::string>{"--map", "127.0.0.1:0", "--tcp", "127.0.0.1:0",
                                                 "--mavlink-udp", mavlink_udp, "--mavlink-udp-listen",
                                                 "127.0.0.1:0", "--mavlink-tcp", "127.0.0.1:0"});
        const auto error = chain->start();
        ASSERT_EQ(error, "");
        hub = chain->hub.get();
        key = chain->key();
    }

    std::vector<std::string> ctl_argv(std::vector<std::string> args, bool with_key) const {
        return chain->ctl_argv(std::move(args), with_key);
    }
    RunResult ctl(std::vector<std::string> args, bool with_key = false) {
        return chain->ctl(std::move(args), with_key);
    }

    std::string plan_file() {
        const std::string path = dir.file("line.yaml");
        std::string elements;
        for (int i = 1; i <= 10; ++i) {
            elements += "    - waypoint: {lat: " + std::to_string(kHomeLat + 0.00008 * (i % 2)) +
                        ", lon: " + std::to_string(kHomeLon + 0.0001 * i) + "}\n";
        }
        write_file(path,
                   "plan:\n  name: through-the-hub\n  vehicle: {type: rover}\n  elements:\n" + elements);
        return path;
    }

    std::string socket() const { return chain->socket(); }

    /// The word after `prefix` in the hub's log (an address it bound to), empty until it is there.
    std::string logged_after(const std::string& prefix) const {
        const auto log = hub->err();
        const auto at = log.find(prefix);
        if (at == std::string::npos) {
            return {};
        }
        const auto begin = at + prefix.size();
        return log.substr(begin, log.find_first_of(" ,\n", begin) - begin);
    }
    std::string tcp_address() const { return logged_after("clients on tcp "); }
    std::string map_url() const { return logged_after("the map on "); }

    /// What the page drew, as its own counts (window.airsegMap.state(), mirrored into the DOM), from a real
    /// headless browser that follows the vehicle for `seconds`.
    Json map_snapshot(int seconds, std::string& dom) {
        const auto browser = run({"/bin/sh", "-c", "command -v chromium || command -v chromium-browser"});
        EXPECT_EQ(browser.exit_code, 0)
            << "chromium is not installed: sudo apt-get install chromium libjs-leaflet";
        if (browser.exit_code != 0) {
            return {};
        }
        auto r =
            run({browser.out.substr(0, browser.out.find('\n')), "--headless", "--no-sandbox", "--disable-gpu",
                 "--disable-dev-shm-usage", "--no-first-run", "--user-data-dir=" + dir.file("browser"),
                 "--window-size=1200,800", "--virtual-time-budget=30000", "--dump-dom",
                 map_url() + "?for=" + std::to_string(seconds)},
                {}, 120s);
        dom = r.out;
        const auto open = dom.find("<pre id=\"airseg-state\"");
        const auto start = dom.find('>', open);
        const auto end = dom.find("</pre>", start);
        if (open == std::string::npos || end == std::string::npos) {
            ADD_FAILURE() << "no page state in what chromium drew:\n" << dom.substr(0, 2000) << r.err;
            return {};
        }
        auto text = dom.substr(start + 1, end - start - 1);
        for (const auto& [entity, ch] : std::vector<std::pair<std::string, std::string>>{
                 {"&quot;", "\""}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
            for (auto at = text.find(entity); at != std::string::npos;
                 at = text.find(entity, at + ch.size())) {
                text.replace(at, entity.size(), ch);
            }
        }
        return Json::parse(text, nullptr, false);
    }

    client::HubOptions operator_options(const std::string& name, const std::string& key_file) const {
        client::HubOptions o;
        o.socket = socket();
        o.key_file = key_file;
        o.want_control = true;
        o.name = name;
        return o;
    }

    TempDir dir;
    std::unique_ptr<GroundChain> chain;
    Subprocess* hub = nullptr;
    std::string key;
};

TEST_F(GroundHubE2e, ThreeWatchersAndOneOperatorShareTheRadio) {
    start_chain();
    std::vector<std::unique_ptr<Subprocess>> watchers;
    for (int i = 0; i < 3; ++i) {
        watchers.push_back(std::make_unique<Subprocess>(ctl_argv({"watch", "--duration", "25000"}, false),
                                                        std::map<std::string, std::string>{}, dir.path()));
    }
    // Every watcher is connected and has seen a sample before the plan goes in.
    ASSERT_TRUE(wait_until(
        [&] {
            for (auto& w : watchers) {
                if (json_lines(w->out()).empty()) {
                    return false;
                }
            }
            return true;
        },
        kGenerous, 200ms));

    // A monitor (no key) may look but not command: the vehicle refuses, and says why.
    auto refused = ctl({"plan", "load", plan_file()});
    EXPECT_EQ(refused.exit_code, 1) << refused.out << refused.err;
    EXPECT_NE(refused.err.find("monitor"), std::string::npos) << refused.err;
    EXPECT_EQ(ctl({"plan", "show"}).exit_code, 0) << "monitor commands still work";

    auto loaded = ctl({"plan", "load", plan_file()}, true);
    ASSERT_EQ(loaded.exit_code, 0) << loaded.out << loaded.err << "\nhub:\n" << hub->err();
    EXPECT_EQ(Json::parse(loaded.out)["name"], "through-the-hub") << loaded.out;

    for (auto& w : watchers) {
        ASSERT_TRUE(w->wait_exit(kGenerous)) << w->err();
        const auto lines = json_lines(w->out());
        bool saw_plan = false;
        for (const auto& line : lines) {
            const auto& plan = line.value("vehicle", Json::object()).value("plan", Json::object());
            saw_plan = saw_plan || plan.value("state", "") == "running";
        }
        EXPECT_TRUE(saw_plan) << "every watcher sees the plan the operator loaded: " << lines.back().dump();
        EXPECT_GE(lines.back()["samples"].get<int>(), 20) << lines.back().dump();
        EXPECT_EQ(lines.back()["ground_link"]["link"], "up") << lines.back().dump();
    }
}

TEST_F(GroundHubE2e, ControlIsHeldByOneClientAtATime) {
    start_chain();
    client::HubClient holder(operator_options("holder", key));
    ASSERT_EQ(holder.open(10s), "");
    EXPECT_EQ(holder.role(), "control");

    auto second = ctl({"plan", "pause"}, true);
    EXPECT_EQ(second.exit_code, 1) << second.out << second.err;
    EXPECT_NE(second.err.find("control is held by holder"), std::string::npos) << second.err;

    // The holder's commands go through and are answered end to end.
    auto answer = holder.request({{"cmd", "plan.show"}}, 30s);
    ASSERT_TRUE(answer.answer) << answer.error;
    EXPECT_TRUE(answer.answer->value("ok", false)) << answer.answer->dump();

    // A key that is not the hub's gives no control.
    const auto wrong = dir.file("wrong.key");
    write_file(wrong, std::string(64, 'd') + "\n");
    ::chmod(wrong.c_str(), 0600);
    client::HubClient impostor(operator_options("x", wrong));
    ASSERT_EQ(impostor.open(10s), "");
    EXPECT_EQ(impostor.role(), "monitor");
    EXPECT_NE(impostor.role_reason().find("does not match"), std::string::npos) << impostor.role_reason();
}

TEST_F(GroundHubE2e, OverTcpTheKeyDecidesTheRole) {
    start_chain();
    ASSERT_FALSE(tcp_address().empty()) << hub->err();
    auto options = operator_options("tcp operator", key);
    options.tcp = tcp_address();
    client::HubClient keyed(options);
    ASSERT_EQ(keyed.open(10s), "");
    EXPECT_EQ(keyed.role(), "control");
    auto answer = keyed.request({{"cmd", "status"}}, 30s);
    ASSERT_TRUE(answer.answer) << answer.error;
    EXPECT_TRUE(answer.answer->value("ok", false)) << answer.answer->dump();

    // airsegctl over TCP without a key: a monitor, whose plan command the vehicle refuses.
    auto refused =
        run({binary("client/airsegctl"), "--ground-tcp", tcp_address(), "--json", "plan", "pause"}, {}, 60s);
    EXPECT_EQ(refused.exit_code, 1) << refused.out << refused.err;
    EXPECT_NE(refused.err.find("no key given"), std::string::npos) << refused.err;
    EXPECT_NE(refused.out.find("a monitor client of the ground hub"), std::string::npos) << refused.out;
}

TEST_F(GroundHubE2e, ControlPassesOnWhenTheHolderLeaves) {
    start_chain();
    {
        client::HubClient holder(operator_options("first", key));
        ASSERT_EQ(holder.open(10s), "");
        ASSERT_EQ(holder.role(), "control");
    }
    // The hub notices the close asynchronously; the next operator gets control once it has.
    RunResult next;
    ASSERT_TRUE(wait_until(
        [&] {
            next = ctl({"plan", "pause"}, true);
            return next.err.find("control is held") == std::string::npos;
        },
        kGenerous, 200ms))
        << next.err;
    // No plan runs, so the vehicle answers the pause itself (refused or done), never "forbidden".
    EXPECT_EQ(next.err.find("monitor"), std::string::npos) << next.err;
}

TEST_F(GroundHubE2e, TheMapShowsThePlanAndTheVehicleDrivingIt) {
    start_chain();
    ASSERT_FALSE(map_url().empty()) << hub->err();
    auto loaded = ctl({"plan", "load", plan_file()}, true);
    ASSERT_EQ(loaded.exit_code, 0) << loaded.out << loaded.err;
    std::string dom;
    const auto state = map_snapshot(8, dom);
    ASSERT_TRUE(state.is_object()) << dom.substr(0, 2000);
    EXPECT_EQ(state["plan"], "through-the-hub") << state.dump();
    EXPECT_EQ(state["plan_elements"], 10) << state.dump();
    ASSERT_TRUE(state["vehicle"].is_object()) << state.dump();
    EXPECT_GT(state["vehicle"]["lon"].get<double>(), kHomeLon)
        << "driving east along the plan: " << state.dump();
    EXPECT_GT(state["track_points"].get<int>(), 5) << state.dump();
    EXPECT_GT(state["track_m"].get<int>(), 5) << "the vehicle moved: " << state.dump();
    EXPECT_FALSE(state["control"].get<bool>()) << "view only without --map-control";
    // Drawn, not only counted: the track and the vehicle marker are in the page's SVG and markers.
    EXPECT_NE(dom.find("airseg-track"), std::string::npos);
    EXPECT_NE(dom.find("airseg-vehicle"), std::string::npos);
}

// A standard ground station on the hub's MAVLink endpoint, played by node-mavlink as QGroundControl behaves
// on connect: heartbeats and position at 1 Hz or more, every parameter, the mission, a mode change (LOITER).
// Meanwhile airseg's own telemetry keeps its rate on the same 57600-baud link.
TEST_F(GroundHubE2e, AGroundStationGetsTheAutopilotsMavlinkThroughTheHub) {
    // As with the hub's default (UDP 14550, where QGroundControl listens), the vehicle's MAVLink goes to
    // the port the ground station listens on, and it answers to the port the frames came from. A port of this
    // test's own: 14550 may be taken by a demo or by another suite's run of this case on the machine.
    const std::string gcs_port = std::to_string(free_udp_port());
    start_chain("127.0.0.1:" + gcs_port);
    const auto node = run({"/bin/sh", "-c", "command -v node"});
    ASSERT_EQ(node.exit_code, 0) << "node is not installed: sudo apt-get install nodejs";
    // A paused plan: the autopilot's mission holds its window, and nothing drives while the mode changes.
    auto loaded = ctl({"plan", "load", plan_file(), "--paused"}, true);
    ASSERT_EQ(loaded.exit_code, 0) << loaded.out << loaded.err;
    Subprocess watcher(ctl_argv({"watch", "--duration", "40000"}, false), {}, dir.path());
    auto gcs = run(
        {node.out.substr(0, node.out.find('\n')), source_path("tests/integration/ground_hub/gcs_client.js"),
         "listen:" + gcs_port, binary("mavlink_interop/node_modules"), "5"},
        {}, 240s);
    const auto summary = Json::parse(gcs.out, nullptr, false);
    ASSERT_TRUE(summary.is_object()) << gcs.out << gcs.err << "\nhub:\n" << hub->err();
    EXPECT_TRUE(summary["ok"].get<bool>()) << summary.dump(2);
    EXPECT_GE(summary["heartbeat_hz"].get<double>(), 0.9) << summary.dump();
    EXPECT_GE(summary["position_hz"].get<double>(), 0.9) << summary.dump();
    EXPECT_GT(summary["params"]["count"].get<int>(), 20) << summary.dump();
    EXPECT_EQ(summary["params"]["received"], summary["params"]["count"]) << summary.dump();
    EXPECT_GE(summary["mission"]["count"].get<int>(), 3) << "home and the plan's window: " << summary.dump();
    EXPECT_EQ(summary["mission"]["received"], summary["mission"]["count"]) << summary.dump();
    EXPECT_EQ(summary["mode"]["ack"], 0) << summary.dump();
    EXPECT_TRUE(summary["mode"]["seen"].get<bool>()) << summary.dump();

    // airseg's own Fast telemetry (2 Hz) kept its rate while the ground station downloaded.
    watcher.signal(SIGTERM);
    ASSERT_TRUE(watcher.wait_exit(kGenerous));
    const auto lines = json_lines(watcher.out());
    ASSERT_FALSE(lines.empty()) << watcher.err();
    EXPECT_GE(lines.back()["sample_rate"].get<double>(), 1.8) << lines.back().dump();
    // And the vehicle counted both directions.
    auto status = ctl({"status"});
    const auto forward = Json::parse(status.out, nullptr, false)["groundlink"]["mavlink_forward"];
    EXPECT_GT(forward.value("forwarded", 0), 0) << forward.dump();
    EXPECT_GT(forward.value("from_ground", 0), 0) << forward.dump();
}

/// A raw client of the hub's Unix socket that reads frames (and says nothing unless asked).
class RawHubClient {
  public:
    explicit RawHubClient(const std::string& path) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    }
    ~RawHubClient() { ::close(fd_); }
    RawHubClient(const RawHubClient&) = delete;
    RawHubClient& operator=(const RawHubClient&) = delete;
    bool connected() const { return connected_; }
    void send(const std::vector<std::uint8_t>& frame) {
        ASSERT_EQ(::send(fd_, frame.data(), frame.size(), MSG_NOSIGNAL), static_cast<ssize_t>(frame.size()));
    }
    /// The JSON frames the hub sent until it closed the connection or `timeout` passed; closed() says which.
    std::vector<Json> read_until_closed(std::chrono::milliseconds timeout) {
        std::vector<Json> out;
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (!closed_ && std::chrono::steady_clock::now() < deadline) {
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) {
                continue;
            }
            std::uint8_t buf[4096];
            const auto n = ::recv(fd_, buf, sizeof buf, 0);
            if (n <= 0) {
                closed_ = true;
                break;
            }
            reader_.push(std::span(buf, static_cast<std::size_t>(n)));
            while (auto f = reader_.next()) {
                if (f->type == groundside::hub::FrameType::Json) {
                    out.push_back(Json::parse(f->payload, nullptr, false));
                }
            }
        }
        return out;
    }
    bool closed() const { return closed_; }

  private:
    int fd_ = -1;
    bool connected_ = false;
    bool closed_ = false;
    groundside::hub::FrameReader reader_;
};

// 64 clients that connect and say nothing: one more is refused with a line, and the silent ones are closed
// once their time to say hello is over; a client that says hello is served as before.
TEST_F(GroundHubE2e, ClientsPastTheBoundAreRefusedAndSilentOnesAreClosed) {
    start_chain();
    std::vector<std::unique_ptr<RawHubClient>> silent;
    for (int i = 0; i < 64; ++i) {
        silent.push_back(std::make_unique<RawHubClient>(socket()));
        ASSERT_TRUE(silent.back()->connected());
    }
    RawHubClient extra(socket());
    const auto frames = extra.read_until_closed(kGenerous);
    ASSERT_TRUE(extra.closed());
    ASSERT_FALSE(frames.empty());
    EXPECT_NE(frames.back().value("error", "").find("64 clients already"), std::string::npos)
        << frames.back().dump();
    // The silent ones are closed within the hello timeout and the hub's one-second tick.
    const auto waited = std::chrono::steady_clock::now();
    for (auto& c : silent) {
        const auto said = c->read_until_closed(20s);
        ASSERT_TRUE(c->closed());
        ASSERT_FALSE(said.empty());
        EXPECT_NE(said.back().value("error", "").find("no hello within 10 s"), std::string::npos);
    }
    std::cout << "[ figures ] 64 silent clients closed " << seconds_since(waited)
              << " s after the 65th was refused\n";
    // A name cut at 64 bytes in the middle of a character, with a terminal escape: the hub escapes it for its
    // log and the link reports every client gets, and goes on.
    RawHubClient named(socket());
    named.send(groundside::hub::encode_json(
        {{"hello", {{"want", "monitor"}, {"name", std::string(63, 'a') + "\xc3\xa9\x1b[2J"}}}}));
    const auto welcome = named.read_until_closed(3s);
    EXPECT_FALSE(named.closed());
    EXPECT_FALSE(welcome.empty()) << "welcomed";
    const auto status = ctl({"status"});
    ASSERT_EQ(status.exit_code, 0) << status.err;
    EXPECT_NE(hub->err().find(std::string(63, 'a') + "\\xc3 (unix) as monitor"), std::string::npos)
        << hub->err();
}

}  // namespace
}  // namespace airseg::test

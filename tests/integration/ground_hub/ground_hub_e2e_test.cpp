// The ground station hub end to end on real ptys: airseg-apmsim ⇄ airsegd ⇄ airseg-linksim (57600 baud) ⇄
// airseg-ground ⇄ several airsegctl at once. Watchers and one operator share the one radio session; the
// operator's plan reaches every watcher; a monitor's command is refused by the vehicle; control is held by
// one client at a time.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "client/hub_client.hpp"
#include "groundside/hub_wire.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/parser.hpp"
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
    // The vehicle's forwarder as the station ended: a freshest frame goes at most at its rate and within the
    // byte budget, and a newer one replaces it meanwhile ("replaced"); with a rate short of 0.9 Hz, the
    // counts of each id (freshest_by_id: "0" the heartbeat, "33" the position; how many went out and the
    // longest gap between two) say whether the vehicle held them back or they were lost after it.
    const auto vehicle_status = Json::parse(ctl({"status"}).out, nullptr, false);
    const Json forwarder =
        vehicle_status.is_object()
            ? vehicle_status.value("groundlink", Json::object()).value("mavlink_forward", Json())
            : Json();
    EXPECT_GE(summary["heartbeat_hz"].get<double>(), 0.9)
        << summary.dump() << "\nforwarder: " << forwarder.dump();
    EXPECT_GE(summary["position_hz"].get<double>(), 0.9)
        << summary.dump() << "\nforwarder: " << forwarder.dump();
    EXPECT_GT(summary["params"]["count"].get<int>(), 20) << summary.dump();
    EXPECT_EQ(summary["params"]["received"], summary["params"]["count"]) << summary.dump();
    EXPECT_GE(summary["mission"]["count"].get<int>(), 3) << "home and the plan's window: " << summary.dump();
    EXPECT_EQ(summary["mission"]["received"], summary["mission"]["count"]) << summary.dump();
    EXPECT_EQ(summary["mode"]["ack"], 0) << summary.dump();
    EXPECT_TRUE(summary["mode"]["seen"].get<bool>()) << summary.dump();

    // airseg's own Fast telemetry (2 Hz) kept its rate while the ground station downloaded. The watcher
    // counts the samples of its last 5 s, 0.2 Hz a sample: a healthy link reads 1.8 or 2.0 by where the
    // last line falls between two samples (1.8 in both runs of the case alone on amd64), one sample late
    // under qemu reads 1.6, and a rate the vehicle lowered (halved by a link judged weak) reads 1.2 or less.
    watcher.signal(SIGTERM);
    ASSERT_TRUE(watcher.wait_exit(kGenerous));
    const auto lines = json_lines(watcher.out());
    ASSERT_FALSE(lines.empty()) << watcher.err();
    // Short of it, the vehicle's scheduler says whether it lowered the rate ("factor", "lowerings": the link
    // judged weak, by loss or by samples replaced before they could go) or the samples were lost after it.
    auto status = ctl({"status"});
    const auto groundlink = Json::parse(status.out, nullptr, false).value("groundlink", Json::object());
    EXPECT_GE(lines.back()["sample_rate"].get<double>(), 1.5)
        << lines.back().dump()
        << "\nthe vehicle's telemetry: " << groundlink.value("telemetry", Json()).dump();
    // And the vehicle counted both directions.
    const auto forward = groundlink.value("mavlink_forward", Json());
    EXPECT_GT(forward.value("forwarded", 0), 0) << forward.dump();
    EXPECT_GT(forward.value("from_ground", 0), 0) << forward.dump();
}

/// A ground station of the test's own on the hub's MAVLink endpoint (UDP or TCP, real sockets), as
/// QGroundControl identifies itself: heartbeats as (255, `compid`). Counts what it receives.
class TestStation {
  public:
    TestStation(bool tcp, const std::string& address, std::uint8_t compid) : encoder_(255, compid) {
        const auto colon = address.rfind(':');
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_port = htons(static_cast<std::uint16_t>(std::stoi(address.substr(colon + 1))));
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        fd_ = ::socket(AF_INET, (tcp ? SOCK_STREAM : SOCK_DGRAM) | SOCK_CLOEXEC, 0);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0;
    }
    ~TestStation() { ::close(fd_); }
    TestStation(const TestStation&) = delete;
    TestStation& operator=(const TestStation&) = delete;
    bool connected() const { return connected_; }

    template <class M>
    void send(const M& m) {
        const auto bytes = encoder_.encode(m);
        ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    }
    void heartbeat() {
        mavlink::Heartbeat hb;
        hb.type = 6;       // MAV_TYPE_GCS
        hb.autopilot = 8;  // MAV_AUTOPILOT_INVALID
        send(hb);
    }
    /// Reads what has arrived (at most `wait`), a heartbeat once a second meanwhile.
    void poll(std::chrono::milliseconds wait) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_heartbeat_ >= 1s) {
            last_heartbeat_ = now;
            heartbeat();
        }
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) {
            return;
        }
        std::uint8_t buf[65536];
        const auto n = ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
        if (n <= 0) {
            return;
        }
        parser_.push(std::span(buf, static_cast<std::size_t>(n)),
                     [&](const mavlink::Frame& f) { on_frame(f); });
    }

    std::map<int, float> params;  // index -> value
    int param_count = 0;
    int param_frames = 0;
    std::map<std::uint32_t, int> mission_items;  // seq -> count
    int mission_count = -1;
    int to_others = 0;   // frames addressed to another component of system 255 than this station's
    int to_airsegd = 0;  // frames addressed to airsegd (255/191)
    int addressed_to_me = 0;
    std::vector<std::uint16_t> mission_requests;  // seqs asked of this station (its mission upload)
    std::optional<int> mission_ack;               // the MISSION_ACK type that ended this station's upload

  private:
    void on_frame(const mavlink::Frame& f) {
        if (const auto t = addressee(f)) {
            if (t->first == 255 && t->second == 191) {
                ++to_airsegd;
            } else if (t->first == 255 && t->second != 0 && t->second != encoder_.compid()) {
                ++to_others;
            } else if (t->first == 255 && t->second == encoder_.compid()) {
                ++addressed_to_me;
            }
        }
        if (auto v = mavlink::decode<mavlink::ParamValue>(f)) {
            ++param_frames;
            param_count = v->param_count;
            params[v->param_index] = v->param_value;
        } else if (auto c = mavlink::decode<mavlink::MissionCount>(f)) {
            if (c->target_component == encoder_.compid()) {
                mission_count = c->count;
            }
        } else if (auto item = mavlink::decode<mavlink::MissionItemInt>(f)) {
            if (item->target_component == encoder_.compid()) {
                ++mission_items[item->seq];
            }
        } else if (auto r = mavlink::decode<mavlink::MissionRequestInt>(f)) {
            if (r->target_component == encoder_.compid()) {
                mission_requests.push_back(r->seq);
            }
        } else if (auto r1 = mavlink::decode<mavlink::MissionRequest>(f)) {
            if (r1->target_component == encoder_.compid()) {
                mission_requests.push_back(r1->seq);
            }
        } else if (auto ack = mavlink::decode<mavlink::MissionAck>(f)) {
            if (ack->target_component == encoder_.compid()) {
                mission_ack = ack->type;
            }
        }
    }
    /// (target_system, target_component) of the messages the test watches.
    static std::optional<std::pair<int, int>> addressee(const mavlink::Frame& f) {
        const auto* info = mavlink::find_dialect_message(f.msgid);
        const auto* sys = info != nullptr ? info->find_field("target_system") : nullptr;
        const auto* comp = info != nullptr ? info->find_field("target_component") : nullptr;
        if (sys == nullptr || comp == nullptr) {
            return std::nullopt;
        }
        return std::pair<int, int>{f.payload[sys->offset], f.payload[comp->offset]};
    }

    int fd_ = -1;
    bool connected_ = false;
    mavlink::Encoder encoder_;
    mavlink::Parser parser_;
    std::chrono::steady_clock::time_point last_heartbeat_{};
};

// Two ground stations at once through the hub, one on UDP (component 190) and one on TCP (component 200):
// the first downloads every parameter across an 8 s radio outage (no value lost, none asked again), then
// again from the hub's cache; the second downloads the mission while airsegd writes the plan's window, and
// the first uploads one. Neither ever sees what is addressed to the other or to airsegd.
TEST_F(GroundHubE2e, TwoGroundStationsRoutedAndParametersThroughAnOutageThenFromTheHub) {
    start_chain();
    std::string udp;
    std::string tcp;
    ASSERT_TRUE(wait_until(
        [&] {
            udp = logged_after("MAVLink for ground stations on udp ");
            tcp = logged_after(", tcp ");
            return !udp.empty() && !tcp.empty();
        },
        kGenerous))
        << hub->err();
    TestStation a(false, udp, 190);
    TestStation b(true, tcp, 200);
    ASSERT_TRUE(a.connected() && b.connected());
    const auto poll_both = [&] {
        a.poll(20ms);
        b.poll(0ms);
    };
    // Heard by the hub before anything is asked (each sends a heartbeat at once, then once a second).
    for (int i = 0; i < 100; ++i) {
        poll_both();
    }
    // airsegd writes a plan's window meanwhile: its own mission traffic with the autopilot (255/191).
    auto loaded = ctl({"plan", "load", plan_file(), "--paused"}, true);
    ASSERT_EQ(loaded.exit_code, 0) << loaded.out << loaded.err;

    mavlink::ParamRequestList list;
    list.target_system = 1;
    list.target_component = 0;
    a.send(list);
    ASSERT_TRUE(wait_until(
        [&] {
            poll_both();
            return a.param_count > 0 && static_cast<int>(a.params.size()) >= a.param_count / 3;
        },
        120s))
        << "params " << a.params.size() << " of " << a.param_count << "\nhub:\n"
        << hub->err();
    const auto before_outage = a.params.size();
    ASSERT_LT(static_cast<int>(before_outage), a.param_count) << "the download ended before the outage";
    // An 8 s radio outage: the radios stop carrying anything.
    chain->linksim->signal(SIGSTOP);
    const auto outage_end = std::chrono::steady_clock::now() + 8s;
    while (std::chrono::steady_clock::now() < outage_end) {
        poll_both();
    }
    chain->linksim->signal(SIGCONT);
    EXPECT_NE(hub->err().find("link to the vehicle down"), std::string::npos)
        << "the outage did not take the link down:\n"
        << hub->err();
    const bool whole = wait_until(
        [&] {
            poll_both();
            return static_cast<int>(a.params.size()) == a.param_count;
        },
        180s);
    EXPECT_TRUE(whole) << "params " << a.params.size() << " of " << a.param_count << " (" << before_outage
                       << " before the outage)\nhub:\n"
                       << hub->err();
    std::cerr << "first download: " << a.params.size() << " of " << a.param_count << ", " << before_outage
              << " before the 8 s outage\n";

    // Again, now from the hub.
    const auto values_first = a.params;
    a.params.clear();
    const auto asked = std::chrono::steady_clock::now();
    a.send(list);
    ASSERT_TRUE(wait_until(
        [&] {
            a.poll(5ms);
            return static_cast<int>(a.params.size()) == a.param_count;
        },
        60s))
        << "params " << a.params.size() << " of " << a.param_count;
    const auto took = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
    std::cerr << "second download (from the hub): " << a.param_count << " values in " << took * 1000
              << " ms\n";
    EXPECT_LT(took, 1.0) << "not from the hub's copy; the hub's log:\n" << hub->err();
    EXPECT_EQ(a.params, values_first);

    // B downloads the mission (the plan's window): MISSION_COUNT and MISSION_ITEM_INTs addressed to B.
    mavlink::MissionRequestList ask;
    ask.target_system = 1;
    ask.target_component = 1;
    b.send(ask);
    ASSERT_TRUE(wait_until(
        [&] {
            poll_both();
            return b.mission_count >= 0;
        },
        60s))
        << hub->err();
    for (int seq = 0; seq < b.mission_count; ++seq) {
        mavlink::MissionRequestInt item;
        item.target_system = 1;
        item.target_component = 1;
        item.seq = static_cast<std::uint16_t>(seq);
        b.send(item);
        ASSERT_TRUE(wait_until(
            [&] {
                poll_both();
                return b.mission_items.contains(static_cast<std::uint32_t>(seq));
            },
            60s))
            << "item " << seq << " of " << b.mission_count;
    }
    mavlink::MissionAck done;
    done.target_system = 1;
    done.target_component = 1;
    b.send(done);
    // A uploads a mission: the MISSION_REQUESTs and the MISSION_ACK answering it go to A alone, whether the
    // flight plan manager takes the mission as the plan or refuses it.
    std::vector<mavlink::MissionItemInt> upload(3);
    for (std::size_t i = 0; i < upload.size(); ++i) {
        auto& it = upload[i];
        it.target_system = 1;
        it.target_component = 1;
        it.seq = static_cast<std::uint16_t>(i);
        it.frame = i == 0 ? 0 : 6;  // home in MAV_FRAME_GLOBAL, then MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
        it.command = 16;            // MAV_CMD_NAV_WAYPOINT
        it.autocontinue = 1;
        it.x = 413900000 + static_cast<std::int32_t>(i) * 900;
        it.y = 21100000 + static_cast<std::int32_t>(i) * 900;
    }
    mavlink::MissionCount count;
    count.target_system = 1;
    count.target_component = 1;
    count.count = static_cast<std::uint16_t>(upload.size());
    a.send(count);
    std::size_t answered = 0;
    ASSERT_TRUE(wait_until(
        [&] {
            poll_both();
            for (; answered < a.mission_requests.size(); ++answered) {
                const auto seq = a.mission_requests[answered];
                if (seq < upload.size()) {
                    a.send(upload[seq]);
                }
            }
            return a.mission_ack.has_value();
        },
        60s))
        << "no MISSION_ACK for A's upload after " << a.mission_requests.size() << " requests\nhub:\n"
        << hub->err();
    std::cerr << "A's upload: " << a.mission_requests.size() << " requests, MISSION_ACK type "
              << *a.mission_ack << "\n";
    for (int i = 0; i < 100; ++i) {
        poll_both();
    }
    EXPECT_GE(b.mission_count, 1);
    EXPECT_TRUE(b.mission_requests.empty()) << "B was asked for A's items";
    EXPECT_FALSE(b.mission_ack.has_value()) << "B got the answer to A's upload";
    EXPECT_GT(b.addressed_to_me, b.mission_count);
    EXPECT_EQ(a.to_others, 0) << "frames addressed to the other station reached A";
    EXPECT_EQ(b.to_others, 0) << "frames addressed to the other station reached B";
    EXPECT_EQ(a.to_airsegd, 0) << "frames addressed to airsegd reached A";
    EXPECT_EQ(b.to_airsegd, 0) << "frames addressed to airsegd reached B";
    EXPECT_EQ(b.mission_items.size(), static_cast<std::size_t>(b.mission_count));
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

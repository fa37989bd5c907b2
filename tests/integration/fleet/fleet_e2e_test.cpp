// The fleet bridge end to end: mosquitto on localhost with passwords, an ACL in which only the operator may
// command, and persistence; two vehicles (airseg-apmsim ⇄ airsegd ⇄ airseg-linksim ⇄ airseg-ground each),
// "rover1" and "rover2", on it. Both vehicles' telemetry reaches the broker; a command to one is answered by
// that one only; the broker keeps an observer from commanding and a wrong password out; and after the broker
// restarts, the hubs come back and a QoS 1 command sent meanwhile is answered.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/ground_chain.hpp"
#include "tests/support/json_lines.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

using Json = nlohmann::json;
constexpr auto kGenerous = 60s;

/// One message as mosquitto_sub -F '%r %t %p' prints it.
struct Seen {
    bool retained = false;
    std::string topic;
    Json payload;
};

std::vector<Seen> seen_in(const std::string& text) {
    std::vector<Seen> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        const auto space = line.find(' ', 2);
        if (line.size() < 3 || space == std::string::npos) {
            continue;
        }
        out.push_back(
            {line[0] == '1', line.substr(2, space - 2), Json::parse(line.substr(space + 1), nullptr, false)});
    }
    return out;
}

class FleetE2e : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto found = run({"/bin/sh", "-c",
                                "PATH=$PATH:/usr/sbin:/usr/local/sbin command -v mosquitto && command -v "
                                "mosquitto_passwd && command -v mosquitto_sub && command -v mosquitto_pub"});
        ASSERT_EQ(found.exit_code, 0)
            << "mosquitto is not installed: sudo apt-get install mosquitto mosquitto-clients";
        std::istringstream paths(found.out);
        for (auto* path : {&mosquitto, &mosquitto_passwd, &mosquitto_sub, &mosquitto_pub}) {
            std::getline(paths, *path);
        }
        port = free_tcp_port();
        ASSERT_NE(port, 0);
        write_broker_config();
    }

    void write_broker_config() {
        const auto passwd = dir.file("passwd");
        bool first = true;
        for (const auto& [user, password] : passwords) {
            std::vector<std::string> argv{mosquitto_passwd, "-b"};
            if (first) {
                argv.push_back("-c");
            }
            first = false;
            argv.insert(argv.end(), {passwd, user, password});
            auto r = run(argv);
            ASSERT_EQ(r.exit_code, 0) << r.err;
            write_file(dir.file(user + ".password"), password + "\n");
        }
        write_file(dir.file("acl"),
                   "user hub1\ntopic write airseg/rover1/#\ntopic read airseg/rover1/cmd\n\n"
                   "user hub2\ntopic write airseg/rover2/#\ntopic read airseg/rover2/cmd\n\n"
                   "user operator\ntopic write airseg/+/cmd\ntopic read airseg/#\n\n"
                   "user observer\ntopic read airseg/#\n");
        std::filesystem::create_directories(dir.file("mosquitto-db"));
        write_file(dir.file("mosquitto.conf"),
                   "listener " + std::to_string(port) + " 127.0.0.1\nallow_anonymous false\npassword_file " +
                       passwd + "\nacl_file " + dir.file("acl") +
                       "\npersistence true\npersistence_location " + dir.file("mosquitto-db") +
                       "/\nlog_dest stderr\nlog_type all\n" + (::geteuid() == 0 ? "user root\n" : ""));
    }

    void start_broker() {
        broker = std::make_unique<Subprocess>(
            std::vector<std::string>{mosquitto, "-c", dir.file("mosquitto.conf")},
            std::map<std::string, std::string>{}, dir.path());
        ASSERT_TRUE(wait_until([&] { return broker->err().find("running") != std::string::npos; }, kGenerous))
            << broker->err();
    }

    std::unique_ptr<GroundChain> chain(const std::string& vehicle, const std::string& user) {
        return std::make_unique<GroundChain>(
            dir.file(vehicle),
            std::vector<std::string>{"--map", "off", "--mavlink-udp", "off", "--mavlink-udp-listen", "off",
                                     "--mavlink-tcp", "off", "--mqtt", "127.0.0.1:" + std::to_string(port),
                                     "--vehicle", vehicle, "--mqtt-user", user, "--mqtt-password-file",
                                     dir.file(user + ".password")});
    }

    std::vector<std::string> client_argv(const std::string& program, const std::string& user) const {
        return {program, "-h", "127.0.0.1", "-p", std::to_string(port), "-u", user, "-P", passwords.at(user)};
    }

    /// Everything under airseg/ the observer sees, retained flag first.
    std::unique_ptr<Subprocess> watch(const std::string& log_name) {
        auto argv = client_argv(mosquitto_sub, "observer");
        argv.insert(argv.end(), {"-t", "airseg/#", "-q", "1", "-F", "%r %t %p"});
        // Each watcher its own log directory: Subprocess names the logs after the program.
        std::filesystem::create_directories(dir.file(log_name));
        return std::make_unique<Subprocess>(argv, std::map<std::string, std::string>{}, dir.file(log_name));
    }

    RunResult publish(const std::string& user, const std::string& topic, const std::string& payload) {
        auto argv = client_argv(mosquitto_pub, user);
        argv.insert(argv.end(), {"-q", "1", "-t", topic, "-m", payload});
        return run(argv);
    }

    static std::vector<Seen> on(const Subprocess& watcher, const std::string& topic) {
        std::vector<Seen> out;
        for (auto& s : seen_in(watcher.out())) {
            if (s.topic == topic) {
                out.push_back(std::move(s));
            }
        }
        return out;
    }
    static std::vector<Json> results(const Subprocess& watcher, const std::string& vehicle, const Json& id) {
        std::vector<Json> out;
        for (const auto& s : on(watcher, "airseg/" + vehicle + "/cmd/result")) {
            if (s.payload.is_object() && s.payload["id"] == id) {
                out.push_back(s.payload["answer"]);
            }
        }
        return out;
    }
    std::string logs() const {
        return "\nbroker:\n" + broker->err() + "\nrover1 hub:\n" + rover1->hub->err() + "\nrover2 hub:\n" +
               rover2->hub->err();
    }

    TempDir dir;
    std::map<std::string, std::string> passwords{
        {"hub1", "pw-hub1"}, {"hub2", "pw-hub2"}, {"operator", "pw-operator"}, {"observer", "pw-observer"}};
    std::string mosquitto, mosquitto_passwd, mosquitto_sub, mosquitto_pub;
    int port = 0;
    std::unique_ptr<Subprocess> broker;
    std::unique_ptr<GroundChain> rover1, rover2;
};

TEST_F(FleetE2e, TwoVehiclesOnOneBroker) {
    ASSERT_NO_FATAL_FAILURE(start_broker());
    auto watcher = watch("watch1");
    rover1 = chain("rover1", "hub1");
    rover2 = chain("rover2", "hub2");
    ASSERT_EQ(rover1->start(), "");
    ASSERT_EQ(rover2->start(), "");

    // Telemetry, link statistics and status of both.
    ASSERT_TRUE(wait_until(
        [&] {
            for (const std::string v : {"rover1", "rover2"}) {
                const auto telemetry = on(*watcher, "airseg/" + v + "/telemetry");
                const auto link = on(*watcher, "airseg/" + v + "/link");
                const auto status = on(*watcher, "airseg/" + v + "/status");
                if (telemetry.empty() || link.empty() || status.empty() ||
                    status.back().payload.value("link", "") != "up") {
                    return false;
                }
            }
            return true;
        },
        kGenerous, 200ms))
        << watcher->out() << logs();
    const auto sample = on(*watcher, "airseg/rover1/telemetry").back().payload;
    EXPECT_GT(sample.value("at", 0.0), 1.7e9) << sample.dump();
    EXPECT_NEAR(sample["vehicle"].value("lat", 0.0), GroundChain::kHomeLat, 0.01) << sample.dump();
    const auto link = on(*watcher, "airseg/rover2/link").back().payload;
    EXPECT_EQ(link["ground"].value("link", ""), "up") << link.dump();
    const auto status = on(*watcher, "airseg/rover1/status").back().payload;
    EXPECT_EQ(
        status,
        (Json{{"online", true}, {"link", "up"}, {"vehicle", "rover1"}, {"hub", status.value("hub", "")}}));
    EXPECT_EQ(status.value("hub", "").rfind("airseg-ground ", 0), 0u) << status.dump();

    // A command to rover1, answered by rover1 with its id, and nothing on rover2's results.
    auto sent = publish("operator", "airseg/rover1/cmd", R"({"id":"op-1","request":{"cmd":"status"}})");
    ASSERT_EQ(sent.exit_code, 0) << sent.err;
    ASSERT_TRUE(wait_until([&] { return !results(*watcher, "rover1", "op-1").empty(); }, kGenerous, 100ms))
        << watcher->out() << logs();
    const auto answer = results(*watcher, "rover1", "op-1").front();
    EXPECT_TRUE(answer.value("ok", false)) << answer.dump();
    EXPECT_TRUE(on(*watcher, "airseg/rover2/cmd/result").empty()) << watcher->out();

    // QoS 1 may deliver twice: the same id runs once, and its answer is given again, unchanged.
    sent = publish("operator", "airseg/rover1/cmd", R"({"id":"op-1","request":{"cmd":"status"}})");
    ASSERT_EQ(sent.exit_code, 0) << sent.err;
    ASSERT_TRUE(wait_until([&] { return results(*watcher, "rover1", "op-1").size() == 2; }, kGenerous, 100ms))
        << watcher->out();
    EXPECT_EQ(results(*watcher, "rover1", "op-1")[1], answer);

    // The id also reaches the vehicle as the command's request id: a hub that restarted has forgotten the ids
    // it answered, and the vehicle's record answers for it. Sent again under a new MQTT id but naming that
    // request id, a command that changes something is answered from the record, not run again.
    sent = publish("operator", "airseg/rover1/cmd", R"({"id":"op-pause","request":{"cmd":"plan.pause"}})");
    ASSERT_EQ(sent.exit_code, 0) << sent.err;
    ASSERT_TRUE(
        wait_until([&] { return !results(*watcher, "rover1", "op-pause").empty(); }, kGenerous, 100ms))
        << watcher->out() << logs();
    EXPECT_FALSE(results(*watcher, "rover1", "op-pause").front().value("replayed", false));
    sent = publish("operator", "airseg/rover1/cmd",
                   R"({"id":"op-pause-again","request":{"cmd":"plan.pause","request_id":"mqtt:op-pause"}})");
    ASSERT_EQ(sent.exit_code, 0) << sent.err;
    ASSERT_TRUE(
        wait_until([&] { return !results(*watcher, "rover1", "op-pause-again").empty(); }, kGenerous, 100ms))
        << watcher->out() << logs();
    EXPECT_TRUE(results(*watcher, "rover1", "op-pause-again").front().value("replayed", false))
        << results(*watcher, "rover1", "op-pause-again").front().dump();

    // Not a command: a bad_request result, with the id when there is one.
    ASSERT_EQ(publish("operator", "airseg/rover1/cmd", "not json").exit_code, 0);
    ASSERT_EQ(publish("operator", "airseg/rover1/cmd", R"({"id":7})").exit_code, 0);
    ASSERT_TRUE(wait_until(
        [&] {
            return !results(*watcher, "rover1", nullptr).empty() && !results(*watcher, "rover1", 7).empty();
        },
        kGenerous, 100ms))
        << watcher->out();
    EXPECT_EQ(results(*watcher, "rover1", nullptr).front().value("status", ""), "bad_request");
    EXPECT_EQ(results(*watcher, "rover1", 7).front().value("status", ""), "bad_request");

    // The observer may read but not command: the broker drops its publication, so the hub never sees it.
    // The operator's command after it is answered, and by then the observer's would have been too.
    ASSERT_EQ(
        publish("observer", "airseg/rover2/cmd", R"({"id":"obs-1","request":{"cmd":"status"}})").exit_code,
        0);
    ASSERT_EQ(
        publish("operator", "airseg/rover2/cmd", R"({"id":"op-2","request":{"cmd":"plan.show"}})").exit_code,
        0);
    ASSERT_TRUE(wait_until([&] { return !results(*watcher, "rover2", "op-2").empty(); }, kGenerous, 100ms))
        << watcher->out() << logs();
    EXPECT_TRUE(results(*watcher, "rover2", "obs-1").empty()) << watcher->out();
    for (const auto& s : on(*watcher, "airseg/rover2/cmd")) {
        EXPECT_NE(s.payload.value("id", ""), "obs-1") << "the ACL let the observer's command through";
    }
    EXPECT_TRUE(results(*watcher, "rover1", "op-2").empty()) << watcher->out();

    // airsegctl --mqtt HOST --vehicle ID: the operator's command answered through the broker, the observer's
    // live view of rover1, and the observer's command never answered (the ACL drops it).
    const auto airsegctl = [&](const std::string& user, long timeout_ms, std::vector<std::string> args) {
        std::vector<std::string> argv{binary("client/airsegctl"),
                                      "--mqtt",
                                      "127.0.0.1:" + std::to_string(port),
                                      "--vehicle",
                                      "rover1",
                                      "--mqtt-user",
                                      user,
                                      "--mqtt-password-file",
                                      dir.file(user + ".password"),
                                      "--json",
                                      "--timeout",
                                      std::to_string(timeout_ms)};
        argv.insert(argv.end(), args.begin(), args.end());
        return run(argv, {}, 90s);
    };
    const auto by_operator = airsegctl("operator", 30'000, {"status"});
    ASSERT_EQ(by_operator.exit_code, 0) << by_operator.out << by_operator.err << logs();
    EXPECT_TRUE(Json::parse(by_operator.out, nullptr, false).value("autopilot", Json()).is_object())
        << by_operator.out;
    const auto view = airsegctl("observer", 30'000, {"watch", "--duration", "4000"});
    ASSERT_EQ(view.exit_code, 0) << view.err;
    const auto lines = json_lines(view.out);
    ASSERT_FALSE(lines.empty()) << view.err;
    // Redrawn at its interval (500 ms) only: it once printed 143,000 lines in 3 s, the MQTT client's wait
    // returning at once between two messages.
    EXPECT_LE(lines.size(), 4000u / 500u + 2u) << view.out.substr(0, 2000);
    EXPECT_GE(lines.size(), 4u);
    EXPECT_GE(lines.back()["samples"].get<int>(), 3) << lines.back().dump();
    EXPECT_TRUE(lines.back()["vehicle"]["lat"].is_number()) << lines.back().dump();
    EXPECT_EQ(lines.back()["ground_link"]["link"], "up") << lines.back().dump();
    EXPECT_EQ(airsegctl("observer", 3'000, {"status"}).exit_code, 3)
        << "the broker drops an observer's command";

    // A wrong password is refused by the broker.
    auto intruder = client_argv(mosquitto_sub, "operator");
    intruder[intruder.size() - 1] = "wrong";
    intruder.insert(intruder.end(), {"-t", "airseg/#", "-C", "1", "-W", "20"});
    const auto refused = run(intruder);
    EXPECT_NE(refused.exit_code, 0);
    EXPECT_TRUE(refused.err.find("not authorised") != std::string::npos ||
                refused.err.find("Connection Refused") != std::string::npos)
        << refused.err;

    // The broker restarts with its persistence: the hubs' sessions survive it, so a QoS 1 command published
    // before rover1's hub is back waits for it, and is answered once it is.
    watcher->signal(SIGTERM);
    watcher->wait_exit(10s);
    broker->signal(SIGTERM);
    ASSERT_TRUE(broker->wait_exit(30s)) << broker->err();
    ASSERT_TRUE(wait_until([&] { return rover1->hub->err().find("connection lost") != std::string::npos; },
                           kGenerous))
        << logs();
    ASSERT_NO_FATAL_FAILURE(start_broker());
    auto after = watch("watch2");
    ASSERT_TRUE(wait_until([&] { return !on(*after, "airseg/rover1/status").empty(); }, kGenerous, 50ms))
        << "the retained status survives the restart" << after->err() << logs();
    sent = publish("operator", "airseg/rover1/cmd", R"({"id":"after-restart","request":{"cmd":"status"}})");
    ASSERT_EQ(sent.exit_code, 0) << sent.err;
    ASSERT_TRUE(
        wait_until([&] { return !results(*after, "rover1", "after-restart").empty(); }, kGenerous, 100ms))
        << after->out() << logs();
    EXPECT_TRUE(results(*after, "rover1", "after-restart").front().value("ok", false));
    ASSERT_TRUE(wait_until(
        [&] {
            for (const auto& s : on(*after, "airseg/rover1/status")) {
                if (!s.retained && s.payload.value("online", false)) {
                    return true;
                }
            }
            return false;
        },
        kGenerous, 100ms))
        << "rover1 says it is online again: " << after->out();
    ASSERT_TRUE(wait_until([&] { return !on(*after, "airseg/rover2/telemetry").empty(); }, kGenerous, 100ms))
        << "rover2's hub is back too" << logs();

    // A hub that stops says so itself: a clean disconnect does not fire the will.
    rover2->hub->signal(SIGTERM);
    ASSERT_EQ(rover2->hub->wait_exit(30s), 0) << logs();
    ASSERT_TRUE(wait_until(
        [&] {
            const auto status = on(*after, "airseg/rover2/status");
            return !status.empty() && !status.back().retained &&
                   status.back().payload == Json{{"online", false}, {"vehicle", "rover2"}};
        },
        kGenerous, 100ms))
        << after->out();
}

}  // namespace
}  // namespace airseg::test

// airsegctl: the thin ground client of airseg. All state lives in airsegd; this program asks and shows.
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <unistd.h>
#include <algorithm>
#include <climits>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cli/command_line.hpp"
#include "client/hub_client.hpp"
#include "client/json_text.hpp"
#include "client/live_commands.hpp"
#include "client/local_client.hpp"
#include "client/mqtt_client.hpp"
#include "client/plan_command.hpp"
#include "client/radio_client.hpp"
#include "client/status_view.hpp"
#include "client/vehicle_commands.hpp"
#include "groundside/mqtt_options.hpp"
#include "groundside/radio_options.hpp"
#include "services/common/nearest_word.hpp"

namespace {

// Exit codes shared by every subcommand.
constexpr int kDone = 0;
constexpr int kRefused = 1;
constexpr int kNoLink = 3;

/// The --help text around the options block (from the option table).
const char* const kUsageHead =
    "Usage: airsegctl [CONNECTION] [--json] [--timeout MS] COMMAND [ARGS]\n"
    "\n"
    "Talks to airsegd, the on-board daemon, and shows what it says. Nothing is shown as done before\n"
    "the vehicle has acknowledged it.\n"
    "\n";

const char* const kUsageTail =
    "\n"
    "Commands:\n"
    "  status             health of every service and the vehicle's state\n"
    "  watch [--interval MS] [--duration MS] [--debug] [--note TEXT]...\n"
    "                     a live view refreshed in place until Ctrl-C: over the radio from the telemetry\n"
    "                     the vehicle pushes (state, position, speed, battery, plan, link, events), redrawn\n"
    "                     every --interval (default 500 ms), locally from the status document every\n"
    "                     --interval (default 1000 ms); each --note is a\n"
    "                     line kept under the view; --debug also lists the events said once already\n"
    "                     or about the autopilot's mission slots, in the vehicle's own words\n"
    "  state STATE        PARKING | DIRECTED | MANUAL_NAVIGATION | WAYPOINT_NAVIGATION\n"
    "  param get NAME | param set NAME VALUE | param list\n"
    "                     the autopilot's parameters\n"
    "  rates [KIND=HZ ...]  show, or set, the pushed telemetry rates (kinds: vehicle, link_stats)\n"
    "  log [--duration MS] [--debug]\n"
    "                     follow the vehicle's events and autopilot texts (radio or hub), each once;\n"
    "                     --debug as for watch\n"
    "  joystick [--device /dev/input/jsN] [--rate HZ] [--duration MS]\n"
    "                     drive in MANUAL_NAVIGATION from a joystick, or the keyboard without --device\n"
    "                     (w/s/a/d or arrows, space centres, q quits); inputs go at --rate (default 10 Hz)\n"
    "  request JSON       send one raw request object, e.g. '{\"cmd\":\"status\"}', print the answer\n"
    "  plan load FILE [--paused] | append FILE | show | skip N|NAME | pause | resume\n"
    "                     the flight plan: answered once the autopilot has confirmed (see "
    "docs/flight-plan.md);\n"
    "                     a loaded plan drives at once, or waits for plan resume with --paused\n"
    "\n"
    "Exit codes: 0 done, 1 refused by the vehicle (\"not authorised\" from a vehicle without a key), 2 "
    "usage,\n"
    "3 no link (no answer in time; \"not authorised\" when the link's keys do not match).\n";

struct Options {
    std::string socket = "/run/airseg/status.sock";
    airseg::groundside::RadioOptions radio;
    airseg::client::HubOptions hub;
    airseg::groundside::MqttOptions mqtt;
    std::string vehicle;
    bool use_radio = false;
    bool use_hub = false;
    bool use_mqtt = false;
    bool local_chosen = false;  // --local or --socket: never look for a ground hub instead
    bool json = false;
    long timeout_ms = 5000;
    std::string request_id;  // --request-id; otherwise a new one per run (one-shot commands)
    std::vector<std::string> positional;
};

const std::vector<std::string> kCommandNames{"status", "watch",    "state",   "param", "rates",
                                             "log",    "joystick", "request", "plan"};

bool exists(const std::string& path) {
    return ::access(path.c_str(), F_OK) == 0;
}

/// A bad command line in one line and where the help is: the whole help would push the reason off the
/// screen.
int usage_error(const std::string& message) {
    return airseg::cli::usage_error(std::cerr, "airsegctl", message);
}

/// The connection and output options; they may stand anywhere on the line. The first other word is the
/// command, and options the table does not know after it are the command's own (watch --duration MS).
std::optional<int> parse(int argc, char** argv, Options& o) {
    using namespace airseg::cli;
    OptionTable table("Options");
    table
        .flag("local", "through airsegd's local socket on the board (the default)",
              [&o] {
                  o.use_radio = o.use_hub = false;
                  o.local_chosen = true;
              })  // named for scripts to be explicit
        .value("socket", "PATH", "local socket path (default /run/airseg/status.sock)",
               [&o](std::string_view, std::string_view v) {
                   o.socket = v;
                   o.local_chosen = true;
               })
        .flag("ground",
              "through the ground hub airseg-ground on its default socket (/run/airseg-ground/ground.sock); "
              "chosen "
              "by itself when that socket exists and airsegd's does not",
              [&o] { o.use_hub = true; })
        .value("ground-socket", "PATH", "through the ground hub on this Unix socket",
               [&o](std::string_view, std::string_view v) {
                   o.hub.socket = v;
                   o.use_hub = true;
               })
        .value("ground-tcp", "HOST:PORT", "through the ground hub's TCP listener",
               [&o](std::string_view, std::string_view v) {
                   o.hub.tcp = v;
                   o.use_hub = true;
               });
    airseg::groundside::add_radio_options(table, o.radio, [&o] { o.use_radio = true; });
    airseg::groundside::add_mqtt_options(table, o.mqtt, o.vehicle, [&o] { o.use_mqtt = true; });
    table
        .value("timeout", "MS", "how long to wait for an answer, in milliseconds (default 5000)",
               [&o](std::string_view option, std::string_view v) {
                   try {
                       o.timeout_ms = static_cast<long>(parse_unsigned(option, v, 1, LONG_MAX));
                   } catch (const UsageError&) {
                       throw UsageError(std::string(option) +
                                        ": expected a positive number of milliseconds, got '" +
                                        std::string(v) + "'");
                   }
               })
        .value("request-id", "ID",
               "name the command for the vehicle's record of recent commands: sent again under the same ID "
               "within 10 minutes (its answer lost, the link down), it is answered from the record and never "
               "done twice; 1 to 64 printable characters (default: a new random ID, printed when no answer "
               "comes)",
               [&o](std::string_view option, std::string_view v) {
                   const bool printable =
                       std::all_of(v.begin(), v.end(), [](char c) { return c > ' ' && c < 0x7f; });
                   if (v.empty() || v.size() > 64 || !printable) {
                       throw UsageError(std::string(option) +
                                        ": expected 1 to 64 printable characters without spaces, got '" +
                                        std::string(v) + "'");
                   }
                   o.request_id = v;
               })
        .flag("json", "machine-readable JSON instead of text", [&o] { o.json = true; })
        .help_and_version();
    const Program program{"airsegctl", [&table] { return kUsageHead + describe(table) + kUsageTail; }};
    auto line = run(program, std::vector<std::string>(argv + std::min(argc, 1), argv + argc), table,
                    std::cout, std::cerr, {.max = SIZE_MAX, .take_unknown_options = true});
    if (line.exit_code) {
        return line.exit_code;
    }
    o.positional = std::move(line.operands);
    if (o.positional.empty()) {
        return usage_error("no command given");
    }
    if (o.use_mqtt + o.use_radio + o.use_hub > 1) {
        return usage_error(
            "choose one way to the vehicle: the radio (--link, --udp), the ground hub (--ground...) "
            "or an MQTT broker (--mqtt)");
    }
    if (o.use_mqtt && o.vehicle.empty()) {
        return usage_error("--mqtt needs --vehicle ID: a broker serves many vehicles");
    }
    if (auto problem = airseg::groundside::check_mqtt_options(o.mqtt); o.use_mqtt && !problem.empty()) {
        return usage_error(problem);
    }
    if (o.use_radio && o.use_hub) {
        return usage_error(
            "--ground and the radio options (--link, --udp) exclude each other: the hub owns the "
            "radio");
    }
    if (o.use_radio) {
        if (auto problem = airseg::groundside::validate(o.radio); !problem.empty()) {
            return usage_error(problem);
        }
    }
    if (!o.use_radio && !o.use_hub && !o.use_mqtt && !o.local_chosen && !exists(o.socket) &&
        exists(std::string(airseg::groundside::hub::kDefaultSocket))) {
        o.use_hub = true;  // a ground laptop: no airsegd here, but a hub
    }
    return std::nullopt;
}

/// A new request id for this run: random, so two operators' commands never share one.
std::string new_request_id() {
    std::random_device random;
    const auto value = (static_cast<std::uint64_t>(random()) << 32) | random();
    return fmt::format("{:016x}", value);
}

/// A one-shot command goes with a request id (--request-id, or a new one): sent again under it, the vehicle
/// answers from its record instead of doing it twice (docs/ground-protocol.md, "At most once").
nlohmann::json with_request_id(nlohmann::json request, Options& o) {
    if (o.request_id.empty()) {
        o.request_id = new_request_id();
    }
    if (request.is_object() && !request.contains("request_id")) {
        request["request_id"] = o.request_id;
    }
    return request;
}

/// Prints an answer; the exit code says whether the vehicle did it.
int show_answer(const Options& o, const airseg::client::LocalAnswer& a,
                const std::function<std::string(const nlohmann::json&)>& render) {
    if (!a.answer) {
        if (o.json) {
            nlohmann::json out{
                {"ok", false},
                {"status", a.error.starts_with("not authorised") ? "not_authorised" : "no_link"},
                {"error", a.error}};
            if (!o.request_id.empty()) {
                out["request_id"] = o.request_id;
            }
            std::cout << airseg::client::dump_text(out) << "\n";
        }
        std::cerr << "airsegctl: " << a.error << "\n";
        if (!o.request_id.empty()) {
            // The command may have reached the vehicle and only its answer been lost.
            std::cerr << "airsegctl: the vehicle may have done it; send it again with --request-id "
                      << o.request_id << " (within 10 minutes) and it is done at most once\n";
        }
        return kNoLink;
    }
    const auto& answer = *a.answer;
    const bool ok = answer.value("ok", false);
    const bool replayed = answer.value("replayed", false);
    if (o.json) {
        auto shown = ok ? answer["result"] : answer;
        if (replayed && shown.is_object()) {
            shown["replayed"] = true;
        }
        std::cout << airseg::client::dump_text(shown) << "\n";
    } else if (ok) {
        std::cout << render(answer["result"]);
    } else {
        std::cerr << "airsegctl: refused: " << answer.value("error", "no reason given") << "\n";
    }
    if (replayed && !o.json) {
        std::cerr << "airsegctl: answered from the vehicle's record of request " << o.request_id
                  << ": done once, at an earlier try, not again\n";
    }
    return ok ? kDone : kRefused;
}

/// The local live view: the status document redrawn in place on a terminal, appended otherwise (for logs).
int watch(const Options& o, const std::function<airseg::client::LocalAnswer(const nlohmann::json&)>& request,
          airseg::client::VehicleLink* radio, std::chrono::milliseconds interval,
          const airseg::client::LiveOptions& live) {
    const bool tty = ::isatty(STDOUT_FILENO) == 1;
    const auto began = std::chrono::steady_clock::now();
    while (!airseg::client::stop_requested() &&
           (live.duration.count() == 0 || std::chrono::steady_clock::now() - began < live.duration)) {
        const auto started = std::chrono::steady_clock::now();
        auto answer = request({{"cmd", "status"}});
        std::string screen;
        if (answer.answer && answer.answer->value("ok", false)) {
            const auto& doc = (*answer.answer)["result"];
            screen = o.json ? airseg::client::dump_text(doc) + "\n" : airseg::client::render_status(doc);
        } else {
            screen = "airsegctl: " +
                     (answer.answer ? answer.answer->value("error", std::string("refused")) : answer.error) +
                     "\n";
        }
        if (radio != nullptr && !o.json) {
            screen += "ground end of the link:\n";
            const auto stats = radio->link_stats();
            for (const auto& [key, value] : stats.items()) {
                screen += "  " + key + std::string(key.size() < 28 ? 28 - key.size() : 1, ' ') + " " +
                          airseg::client::dump_text(value) + "\n";
            }
        }
        screen += airseg::client::notes_text(live);
        std::cout << (tty ? "\x1b[H\x1b[2J" : "") << screen << std::flush;
        // Wait out the rest of the interval; over the radio keep the link serviced meanwhile.
        while (!airseg::client::stop_requested() && std::chrono::steady_clock::now() - started < interval) {
            if (radio != nullptr) {
                radio->run_for(std::chrono::milliseconds(50), [](const auto&) {});
            } else {
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
            }
        }
    }
    return kDone;
}

struct Requester {
    airseg::client::LocalClient& local;
    airseg::client::VehicleLink* radio;
    std::chrono::milliseconds timeout;
    airseg::client::LocalAnswer request(const nlohmann::json& r) {
        return radio ? radio->request(r, timeout, {}) : local.request(r);
    }
};

/// watch, log and joystick: their own options follow the command name.
int live_command(const Options& o, Requester& client, airseg::client::VehicleLink* radio) {
    const auto& cmd = o.positional[0];
    airseg::client::LiveOptions live;
    live.json = o.json;
    live.timeout = std::chrono::milliseconds(o.timeout_ms);
    airseg::client::JoystickOptions stick;
    double interval_ms = 1000;
    bool interval_given = false;
    double duration_ms = 0;
    using namespace airseg::cli;
    // Each command's own options, after its name; the same parser and messages as the global ones.
    OptionTable table;
    table.value("duration", "MS", "", number(duration_ms, 1, 1e9));
    if (cmd == "watch" || cmd == "log") {
        table.flag("debug", "", [&live] { live.debug = true; });
    }
    if (cmd == "watch") {
        table
            .value("interval", "MS", "",
                   [&](std::string_view option, std::string_view v) {
                       number(interval_ms, 100, 1e9)(option, v);
                       interval_given = true;
                   })
            .value("note", "TEXT", "",
                   [&live](std::string_view, std::string_view v) { live.notes.emplace_back(v); });
    } else if (cmd == "joystick") {
        table.value("device", "PATH", "", text(stick.device))
            .value("rate", "HZ", "", number(stick.rate_hz, 0.1, 50));
    }
    try {
        airseg::cli::parse({o.positional.begin() + 1, o.positional.end()}, table);
    } catch (const UsageError& e) {
        return usage_error(cmd + ": " + e.what());
    }
    live.duration = std::chrono::milliseconds(static_cast<long>(duration_ms));
    if (interval_given) {
        live.refresh = std::chrono::milliseconds(static_cast<long>(interval_ms));  // the radio's view too
    }
    airseg::client::install_stop_handlers();
    if (cmd == "watch") {
        if (radio != nullptr) {
            return airseg::client::run_radio_watch(*radio, live);
        }
        return watch(
            o, [&](const nlohmann::json& r) { return client.request(r); }, nullptr,
            std::chrono::milliseconds(static_cast<long>(interval_ms)), live);
    }
    if (radio == nullptr) {
        return usage_error(
            cmd + " needs the radio link (--link, --udp, --ground or --mqtt): the vehicle pushes it");
    }
    if (cmd == "log") {
        return airseg::client::run_log(*radio, live);
    }
    return airseg::client::run_joystick(*radio, live, stick);
}

}  // namespace

int main(int argc, char** argv) {
    // stdout carries answers (JSON for scripts); the libraries' log lines go to stderr, warnings only.
    spdlog::set_default_logger(spdlog::stderr_color_st("airsegctl"));
    spdlog::set_level(spdlog::level::warn);
    Options o;
    if (auto exit_code = parse(argc, argv, o)) {
        return *exit_code;
    }
    const auto timeout = std::chrono::milliseconds(o.timeout_ms);
    airseg::client::LocalClient local(o.socket, timeout);
    const auto& cmd = o.positional[0];
    std::unique_ptr<airseg::client::VehicleLink> radio;
    if (o.use_radio) {
        auto direct = std::make_unique<airseg::client::RadioClient>(o.radio);
        if (auto error = direct->open(); !error.empty()) {
            std::cerr << "airsegctl: " << error << "\n";
            return kNoLink;
        }
        radio = std::move(direct);
    } else if (o.use_mqtt) {
        if (cmd == "joystick") {
            return usage_error(
                "joystick needs the radio or the ground hub: a broker's latency is no way to drive");
        }
        auto broker = std::make_unique<airseg::client::MqttClient>(o.mqtt, o.vehicle);
        if (auto error = broker->open(timeout); !error.empty()) {
            std::cerr << "airsegctl: " << error << "\n";
            return kNoLink;
        }
        radio = std::move(broker);
    } else if (o.use_hub) {
        auto options = o.hub;
        options.key_file = o.radio.key_file;
        // Watching needs no control, so watchers never keep an operator from taking it.
        options.want_control = cmd != "status" && cmd != "watch" && cmd != "log";
        options.name = "airsegctl " + cmd;
        auto hub = std::make_unique<airseg::client::HubClient>(options);
        if (auto error = hub->open(timeout); !error.empty()) {
            std::cerr << "airsegctl: " << error << "\n";
            return kNoLink;
        }
        if (options.want_control && hub->role() != "control") {
            std::cerr << "airsegctl: the ground hub made this client a monitor: " << hub->role_reason()
                      << "\n";
        }
        radio = std::move(hub);
    }
    Requester client{local, radio.get(), timeout};
    if (cmd == "status") {
        if (o.positional.size() != 1) {
            return usage_error("status takes no arguments");
        }
        return show_answer(o, client.request({{"cmd", "status"}}), airseg::client::render_status);
    }
    if (cmd == "watch" || cmd == "log" || cmd == "joystick") {
        return live_command(o, client, radio.get());
    }
    if (airseg::client::is_vehicle_command(cmd)) {
        auto built = airseg::client::build_vehicle_command(o.positional);
        if (!built.usage_error.empty()) {
            return usage_error(built.usage_error);
        }
        return show_answer(o, client.request(with_request_id(built.request, o)), built.render);
    }
    if (cmd == "request") {
        if (o.positional.size() != 2) {
            return usage_error("request takes one JSON object");
        }
        auto req = nlohmann::json::parse(o.positional[1], nullptr, false);
        if (req.is_discarded() || !req.is_object()) {
            return usage_error("request: not a JSON object: " + o.positional[1]);
        }
        return show_answer(o, client.request(with_request_id(req, o)),
                           [](const nlohmann::json& r) { return airseg::client::dump_text(r, 2) + "\n"; });
    }
    if (cmd == "plan") {
        auto plan =
            airseg::client::plan_command({o.positional.begin() + 1, o.positional.end()}, radio == nullptr);
        if (!plan.request && plan.file_refused) {
            std::cerr << "airsegctl: " << plan.error << "\n";  // nothing sent: the file cannot be a plan
            return kRefused;
        }
        if (!plan.request) {
            return usage_error(plan.error);
        }
        return show_answer(o, client.request(with_request_id(*plan.request, o)), plan.render);
    }
    return usage_error("unknown command '" + cmd + "'" + airseg::did_you_mean(cmd, kCommandNames));
}

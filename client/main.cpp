// airsegctl: the thin ground client of airseg. All state lives in airsegd; this program asks and shows.
#include <fmt/format.h>

#include <cstdlib>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "client/local_client.hpp"
#include "client/status_view.hpp"

namespace {

// Exit codes shared by every subcommand.
constexpr int kDone = 0;
constexpr int kRefused = 1;
constexpr int kUsage = 2;
constexpr int kNoLink = 3;

const char* kUsageText =
    "Usage: airsegctl [--local] [--socket PATH] [--json] [--timeout MS] COMMAND [ARGS]\n"
    "\n"
    "Talks to airsegd, the on-board daemon, and shows what it says. Nothing is shown as done before\n"
    "the vehicle has acknowledged it.\n"
    "\n"
    "Connection:\n"
    "  --local            through airsegd's local socket on the board (the default)\n"
    "  --socket PATH      local socket path (default /run/airseg/status.sock)\n"
    "  --timeout MS       how long to wait for an answer (default 5000)\n"
    "\n"
    "Output:\n"
    "  --json             machine-readable JSON instead of text\n"
    "\n"
    "Commands:\n"
    "  status             health of every service and the vehicle's state\n"
    "  request JSON       send one raw request object, e.g. '{\"cmd\":\"status\"}', print the answer\n"
    "\n"
    "Exit codes: 0 done, 1 refused by the vehicle, 2 usage, 3 no link (no answer in time).\n";

struct Options {
    std::string socket = "/run/airseg/status.sock";
    bool json = false;
    long timeout_ms = 5000;
    std::vector<std::string> positional;
};

int usage_error(const std::string& message) {
    std::cerr << "airsegctl: " << message << "\n\n" << kUsageText;
    return kUsage;
}

std::optional<int> parse(int argc, char** argv, Options& o) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](const char* name) -> std::optional<std::string> {
            if (i + 1 >= argc) {
                return std::nullopt;
            }
            (void)name;
            return std::string(argv[++i]);
        };
        if (a == "--help" || a == "-h") {
            std::cout << kUsageText;
            return kDone;
        } else if (a == "--version") {
            std::cout << "airsegctl " << AIRSEG_VERSION << "\n";
            return kDone;
        } else if (a == "--local") {
            // The only connection this build offers; accepted for scripts that name it.
        } else if (a == "--json") {
            o.json = true;
        } else if (a == "--socket") {
            auto v = value("--socket");
            if (!v) {
                return usage_error("--socket needs a PATH");
            }
            o.socket = *v;
        } else if (a == "--timeout") {
            auto v = value("--timeout");
            char* end = nullptr;
            const long ms = v ? std::strtol(v->c_str(), &end, 10) : 0;
            if (!v || *end != '\0' || ms <= 0) {
                return usage_error("--timeout needs a positive number of milliseconds");
            }
            o.timeout_ms = ms;
        } else if (a.starts_with("-") && a.size() > 1) {
            return usage_error("unknown option '" + a + "'");
        } else {
            o.positional.push_back(a);
        }
    }
    if (o.positional.empty()) {
        return usage_error("no command given");
    }
    return std::nullopt;
}

/// Prints an answer; the exit code says whether the vehicle did it.
int show_answer(const Options& o, const airseg::client::LocalAnswer& a,
                const std::function<std::string(const nlohmann::json&)>& render) {
    if (!a.answer) {
        if (o.json) {
            std::cout << nlohmann::json{{"ok", false}, {"status", "no_link"}, {"error", a.error}}.dump()
                      << "\n";
        }
        std::cerr << "airsegctl: " << a.error << "\n";
        return kNoLink;
    }
    const auto& answer = *a.answer;
    const bool ok = answer.value("ok", false);
    if (o.json) {
        std::cout << (ok ? answer["result"] : answer).dump() << "\n";
    } else if (ok) {
        std::cout << render(answer["result"]);
    } else {
        std::cerr << "airsegctl: refused: " << answer.value("error", "no reason given") << "\n";
    }
    return ok ? kDone : kRefused;
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    if (auto exit_code = parse(argc, argv, o)) {
        return *exit_code;
    }
    airseg::client::LocalClient client(o.socket, std::chrono::milliseconds(o.timeout_ms));
    const auto& cmd = o.positional[0];
    if (cmd == "status") {
        if (o.positional.size() != 1) {
            return usage_error("status takes no arguments");
        }
        return show_answer(o, client.request({{"cmd", "status"}}), airseg::client::render_status);
    }
    if (cmd == "request") {
        if (o.positional.size() != 2) {
            return usage_error("request takes one JSON object");
        }
        auto req = nlohmann::json::parse(o.positional[1], nullptr, false);
        if (req.is_discarded() || !req.is_object()) {
            return usage_error("request: not a JSON object: " + o.positional[1]);
        }
        return show_answer(o, client.request(req), [](const nlohmann::json& r) { return r.dump(2) + "\n"; });
    }
    return usage_error("unknown command '" + cmd + "'");
}

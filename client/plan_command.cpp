#include "client/plan_command.hpp"

#include <filesystem>
#include <sstream>

#include "base/file_text.hpp"
#include "base/utf8.hpp"
#include "client/json_text.hpp"
#include "services/common/nearest_word.hpp"

namespace airseg::client {

namespace {

// The local socket takes requests up to 1 MiB; JSON escaping can grow a text a little.
constexpr std::uintmax_t kInlineLimit = 900'000;
// The radio carries a plan as one command; the daemon refuses plans over 16 MiB anyway.
constexpr std::size_t kMaxPlanFile = 16u << 20;

std::string show_value(const nlohmann::json& v) {
    return v.is_string() ? v.get<std::string>() : v.is_null() ? std::string("-") : dump_text(v);
}

std::optional<nlohmann::json> file_request(const std::string& cmd, const std::string& file, bool local,
                                           std::string& error) {
    // A regular file only, read whole here (a FIFO or /dev/zero is refused at once).
    auto read = read_file_text(file, kMaxPlanFile);
    if (!read.ok()) {
        error = file + ": " + read.error;
        return std::nullopt;
    }
    // The daemon refuses such a text as well; caught here, it is said with its place before anything is sent
    // (a JSON request could not even carry its bytes).
    if (const auto fault = first_text_fault(read.text)) {
        const auto at = position_of(read.text, fault->offset);
        error = file + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) + ": " +
                fault->what() + ": a plan is UTF-8 text without control characters";
        return std::nullopt;
    }
    const auto size = read.text.size();
    if (size > kInlineLimit) {
        if (!local) {
            error = file + ": too large to send over the radio in one command (" + std::to_string(size) +
                    " bytes; the limit is " + std::to_string(kInlineLimit) + ")";
            return std::nullopt;
        }
        return nlohmann::json{{"cmd", cmd}, {"path", std::filesystem::absolute(file).string()}};
    }
    return nlohmann::json{{"cmd", cmd}, {"text", std::move(read.text)}, {"source", file}};
}

}  // namespace

std::string render_plan(const nlohmann::json& r) {
    std::ostringstream o;
    if (r.value("kept", false)) {
        o << "kept; starts when the autopilot is ready\n";
    }
    for (const char* key : {"state", "name", "source", "element", "waypoints_reached", "next_waypoint",
                            "window", "reaction", "interruption", "error"}) {
        if (r.contains(key)) {
            o << "plan." << key << std::string(18 - std::string(key).size(), ' ') << show_value(r[key])
              << "\n";
        }
    }
    if (r.contains("elements") && r["elements"].is_array()) {
        o << "elements:\n";
        for (const auto& e : r["elements"]) {
            o << "  " << show_value(e.value("path", nlohmann::json())) << "  "
              << show_value(e.value("kind", nlohmann::json()));
            if (e.value("name", std::string()) != "") {
                o << " '" << e["name"].get<std::string>() << "'";
            }
            o << "  line " << show_value(e.value("line", nlohmann::json())) << ", waypoints "
              << show_value(e.value("waypoints", nlohmann::json())) << "\n";
        }
    }
    return o.str();
}

PlanCommand plan_command(const std::vector<std::string>& args, bool local) {
    PlanCommand out;
    out.render = render_plan;
    if (args.empty()) {
        out.error = "plan needs a subcommand: load FILE | append FILE | show | skip N|NAME | pause | resume";
        return out;
    }
    const std::string& sub = args[0];
    const auto want = [&](std::size_t n, const char* form) {
        if (args.size() != n) {
            out.error = std::string("usage: plan ") + form;
            return false;
        }
        return true;
    };
    if (sub == "load") {
        // plan load FILE [--paused]: the plan drives at once unless --paused.
        std::vector<std::string> files;
        bool paused = false;
        for (std::size_t i = 1; i < args.size(); ++i) {
            if (args[i] == "--paused") {
                paused = true;
            } else if (args[i].starts_with("--")) {
                out.error = "plan load: unknown option '" + args[i] + "'" +
                            did_you_mean(args[i], std::vector<std::string>{"--paused"});
                return out;
            } else {
                files.push_back(args[i]);
            }
        }
        if (files.size() != 1) {
            out.error = "usage: plan load FILE [--paused]";
            return out;
        }
        out.request = file_request("plan.load", files[0], local, out.error);
        out.file_refused = !out.request;
        if (out.request && paused) {
            (*out.request)["paused"] = true;
        }
    } else if (sub == "append") {
        if (want(2, "append FILE")) {
            out.request = file_request("plan." + sub, args[1], local, out.error);
            out.file_refused = !out.request;
        }
    } else if (sub == "show" || sub == "pause" || sub == "resume") {
        if (want(1, sub.c_str())) {
            out.request = nlohmann::json{{"cmd", "plan." + sub}};
        }
    } else if (sub == "skip") {
        if (want(2, "skip N (a waypoint index of the expanded plan) | skip NAME (a named element)")) {
            const std::string& target = args[1];
            if (!target.empty() && target.size() <= 19 &&
                target.find_first_not_of("0123456789") == std::string::npos) {
                out.request = nlohmann::json{{"cmd", "plan.skip"}, {"index", std::stoull(target)}};
            } else {
                out.request = nlohmann::json{{"cmd", "plan.skip"}, {"element", target}};
            }
        }
    } else {
        out.error =
            "unknown plan subcommand '" + sub + "'" +
            did_you_mean(sub, std::vector<std::string>{"load", "append", "show", "skip", "pause", "resume"}) +
            " (load, append, show, skip, pause, resume)";
    }
    return out;
}

}  // namespace airseg::client

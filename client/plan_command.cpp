#include "client/plan_command.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/common/nearest_word.hpp"

namespace airseg::client {

namespace {

// The local socket takes requests up to 1 MiB; JSON escaping can grow a text a little.
constexpr std::uintmax_t kInlineLimit = 900'000;
// The radio carries a plan as one command; the daemon refuses plans over 16 MiB anyway.
constexpr std::uintmax_t kMaxPlanFile = 16u << 20;

std::string show_value(const nlohmann::json& v) {
    return v.is_string() ? v.get<std::string>() : v.is_null() ? std::string("-") : v.dump();
}

std::optional<nlohmann::json> file_request(const std::string& cmd, const std::string& file, bool local,
                                           std::string& error) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) {
        error = file + ": " + ec.message();
        return std::nullopt;
    }
    if (size > kMaxPlanFile) {
        error = file + ": larger than 16 MiB";
        return std::nullopt;
    }
    if (size > kInlineLimit) {
        if (!local) {
            error = file + ": too large to send over the radio in one command (" + std::to_string(size) +
                    " bytes; the limit is " + std::to_string(kInlineLimit) + ")";
            return std::nullopt;
        }
        return nlohmann::json{{"cmd", cmd}, {"path", std::filesystem::absolute(file).string()}};
    }
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) {
        error = file + ": cannot read";
        return std::nullopt;
    }
    return nlohmann::json{{"cmd", cmd}, {"text", text.str()}, {"source", file}};
}

}  // namespace

std::string render_plan(const nlohmann::json& r) {
    std::ostringstream o;
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
        if (out.request && paused) {
            (*out.request)["paused"] = true;
        }
    } else if (sub == "append") {
        if (want(2, "append FILE")) {
            out.request = file_request("plan." + sub, args[1], local, out.error);
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

#pragma once
// airsegctl's `plan` subcommands: turns `plan load FILE | append FILE | show | skip N|NAME | pause | resume`
// into the daemon's plan.* requests and renders their answers.
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace airseg::client {

struct PlanCommand {
    std::optional<nlohmann::json> request;  // empty: `error` says what is wrong with the arguments
    std::string error;
    bool file_refused = false;  // the error is about the plan file (its kind, size or text), not the usage
    std::function<std::string(const nlohmann::json&)> render;  // text form of an ok result
};

/// `args` are the words after "plan". A plan file is read here and sent as text, so that the same command
/// works over the radio; on the board's own socket (`local`) a file too large for one request is sent by
/// its absolute path for the daemon to read.
PlanCommand plan_command(const std::vector<std::string>& args, bool local);

/// The text form of plan.show and of every plan command's answer (the plan's progress).
std::string render_plan(const nlohmann::json& result);

}  // namespace airseg::client

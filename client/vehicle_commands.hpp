#pragma once
// airsegctl's one-shot vehicle commands (state, param, rates): the request each command line makes and how
// its acknowledged result is shown to people.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace airseg::client {

struct BuiltCommand {
    nlohmann::json request;
    std::function<std::string(const nlohmann::json& result)> render;
    std::string usage_error;  // set when the arguments are wrong; nothing is sent then
};

/// `args` is the command line from the command name on: {"state", "PARKING"}, {"param", "get", "NAME"},
/// {"rates", "vehicle=5"}. Returns a BuiltCommand with usage_error set for a command this does not know.
BuiltCommand build_vehicle_command(const std::vector<std::string>& args);

/// Whether build_vehicle_command handles this command name.
bool is_vehicle_command(const std::string& name);

}  // namespace airseg::client

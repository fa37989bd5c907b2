#pragma once
// The configuration schema: every key the daemon understands, its type, range, default (the Config struct's
// initializer), documentation, and whether SIGHUP may change it on a running daemon.
#include <yaml-cpp/yaml.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "daemon/config.hpp"

namespace airseg::daemon {

struct KeySpec {
    std::string path;       // dotted key path, e.g. "autopilot.port"
    std::string type_name;  // for people: "integer 1..64", "duration", "one of single|split|..."
    std::string doc;        // one line
    bool runtime = false;   // applied by SIGHUP without a restart
    // Parses `node` into `config`; returns a message (without location) when the value is wrong.
    std::function<std::optional<std::string>(const YAML::Node& node, Config& config)> apply;
    // The key's current value, as it would be written in YAML.
    std::function<std::string(const Config& config)> show;
};

const std::vector<KeySpec>& config_schema();
const KeySpec* find_key(const std::string& path);
/// True when `path` names a section (a prefix of some key), e.g. "autopilot".
bool is_section(const std::string& path);

}  // namespace airseg::daemon

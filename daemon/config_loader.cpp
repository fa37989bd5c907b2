#include "daemon/config_loader.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "daemon/autopilot_setup.hpp"
#include "daemon/config_schema.hpp"

namespace airseg::daemon {
namespace {

std::string location(const std::string& source, const YAML::Mark& mark) {
    if (mark.is_null()) {
        return source;
    }
    return fmt::format("{}:{}:{}", source, mark.line + 1, mark.column + 1);
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) {
        prev[j] = j;
    }
    for (std::size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

/// "did you mean 'autopilot.port'?" for a near miss among the keys of the same section.
std::string suggestion(const std::string& path) {
    const auto dot = path.rfind('.');
    const std::string section = dot == std::string::npos ? "" : path.substr(0, dot + 1);
    std::string best;
    std::size_t best_distance = 3;  // only close misses are worth suggesting
    for (const auto& spec : config_schema()) {
        std::string candidate = spec.path;
        if (!candidate.starts_with(section)) {
            continue;
        }
        // Compare against the key or the section at the same depth.
        const auto next_dot = candidate.find('.', section.size());
        if (next_dot != std::string::npos) {
            candidate = candidate.substr(0, next_dot);
        }
        const auto d = edit_distance(path, candidate);
        if (d < best_distance) {
            best_distance = d;
            best = candidate;
        }
    }
    return best.empty() ? "" : fmt::format(" (did you mean '{}'?)", best);
}

class Walker {
  public:
    Walker(const std::string& source, Config& config, std::vector<ConfigError>& errors,
           std::map<std::string, std::string>& where)
        : source_(source), config_(config), errors_(errors), where_(where) {}

    void walk(const YAML::Node& node, const std::string& prefix) {
        if (!node.IsMap()) {
            error(node.Mark(), prefix,
                  prefix.empty() ? "the file must be a mapping of keys to values"
                                 : "expected a mapping of keys to values");
            return;
        }
        std::set<std::string> seen;
        for (const auto& entry : node) {
            const YAML::Node& key_node = entry.first;
            const YAML::Node& value = entry.second;
            if (!key_node.IsScalar()) {
                error(key_node.Mark(), prefix, "keys must be plain names");
                continue;
            }
            const std::string path = prefix.empty() ? key_node.Scalar() : prefix + "." + key_node.Scalar();
            if (!seen.insert(path).second) {
                error(key_node.Mark(), path, "duplicate key");
                continue;
            }
            if (const KeySpec* spec = find_key(path)) {
                where_[path] = location(source_, key_node.Mark());
                if (auto message = spec->apply(value, config_)) {
                    error(value.Mark(), path, *message);
                }
            } else if (is_section(path)) {
                walk(value, path);
            } else {
                error(key_node.Mark(), path, fmt::format("unknown key '{}'{}", path, suggestion(path)));
            }
        }
    }

  private:
    void error(const YAML::Mark& mark, const std::string& key, std::string message) {
        errors_.push_back({location(source_, mark), key, std::move(message)});
    }

    const std::string& source_;
    Config& config_;
    std::vector<ConfigError>& errors_;
    std::map<std::string, std::string>& where_;
};

void apply_override(const std::string& text, Config& config, std::vector<ConfigError>& errors,
                    std::map<std::string, std::string>& where) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0) {
        errors.push_back({"--set", "", fmt::format("'{}' must be KEY=VALUE", text)});
        return;
    }
    const std::string key = text.substr(0, eq);
    const std::string value = text.substr(eq + 1);
    const KeySpec* spec = find_key(key);
    if (spec == nullptr) {
        errors.push_back({"--set", key, fmt::format("unknown key '{}'{}", key, suggestion(key))});
        return;
    }
    where[key] = "--set " + key;
    try {
        // Parsed as YAML so that lists ("[a, b]") and quoting work as in the file.
        const YAML::Node node = value.empty() ? YAML::Node(YAML::NodeType::Null) : YAML::Load(value);
        if (auto message = spec->apply(node, config)) {
            errors.push_back({"--set", key, *message});
        }
    } catch (const YAML::Exception& e) {
        errors.push_back({"--set", key, fmt::format("value is not valid YAML: {}", e.msg)});
    }
}

/// Rules that involve more than one key.
void check_consistency(const Config& c, const std::string& source,
                       const std::map<std::string, std::string>& where, std::vector<ConfigError>& errors) {
    // Name the place the offending key was set: its line in the file, or the --set that changed it.
    auto at = [&](const std::string& key, const std::string& or_key = {}) {
        auto it = where.find(key);
        if (it == where.end() && !or_key.empty()) {
            it = where.find(or_key);
        }
        return it == where.end() ? source : it->second;
    };
    const auto& g = c.groundlink;
    if ((g.mode == "split" || g.mode == "redundant") && g.ports.size() != 2) {
        errors.push_back({at("groundlink.ports", "groundlink.mode"), "groundlink.ports",
                          fmt::format("mode '{}' needs two ports, {} given", g.mode, g.ports.size())});
    }
    if (g.mode == "single" && g.ports.size() != 1) {
        errors.push_back({at("groundlink.ports", "groundlink.mode"), "groundlink.ports",
                          "mode 'single' uses exactly one port"});
    }
    if (c.autopilot.reconnect_min > c.autopilot.reconnect_max) {
        errors.push_back({at("autopilot.reconnect_min"), "autopilot.reconnect_min",
                          "must not be longer than autopilot.reconnect_max"});
    }
    if (g.reconnect_min > g.reconnect_max) {
        errors.push_back({at("groundlink.reconnect_min"), "groundlink.reconnect_min",
                          "must not be longer than groundlink.reconnect_max"});
    }
    for (const auto& [kind, hz] : g.telemetry_rates) {
        if (hz < 0 || hz > 20) {
            errors.push_back({at("groundlink.telemetry.rates"), "groundlink.telemetry.rates",
                              fmt::format("{}: {} Hz is out of range 0..20", kind, hz)});
        }
    }
    if (!g.monitor_key_file.empty() && g.key_file.empty()) {
        errors.push_back({at("groundlink.monitor_key_file"), "groundlink.monitor_key_file",
                          "needs groundlink.key_file (the control key)"});
    }
    // The autopilot layer's own rules, reported at the key they name.
    for (const auto& problem : autopilot_setup(c).problems) {
        const std::string key = problem_key(problem);
        if (key.empty()) {
            errors.push_back({at("autopilot", "autopilot.board"), "autopilot", problem});
        } else {
            errors.push_back({at(key), key, problem.substr(key.size() + 2)});
        }
    }
}

}  // namespace

std::string ConfigError::to_string() const {
    if (key.empty()) {
        return fmt::format("{}: {}", where, message);
    }
    return fmt::format("{}: {}: {}", where, key, message);
}

ConfigResult load_config_text(std::string_view text, const std::string& source,
                              const std::vector<std::string>& overrides) {
    ConfigResult result;
    std::map<std::string, std::string> where;
    try {
        const YAML::Node root = YAML::Load(std::string(text));
        if (root.IsDefined() && !root.IsNull()) {
            Walker(source, result.config, result.errors, where).walk(root, "");
        }
    } catch (const YAML::ParserException& e) {
        result.errors.push_back({location(source, e.mark), "", fmt::format("YAML syntax error: {}", e.msg)});
        return result;
    }
    for (const auto& o : overrides) {
        apply_override(o, result.config, result.errors, where);
    }
    if (result.errors.empty()) {
        check_consistency(result.config, source, where, result.errors);
    }
    return result;
}

ConfigResult load_config_file(const std::string& path, const std::vector<std::string>& overrides) {
    std::ifstream in(path);
    if (!in) {
        ConfigResult result;
        result.errors.push_back({path, "", "cannot read the configuration file"});
        return result;
    }
    std::stringstream buffer;
    buffer << in.rdbuf();
    return load_config_text(buffer.str(), path, overrides);
}

std::vector<ConfigChange> diff_config(const Config& before, const Config& after) {
    std::vector<ConfigChange> out;
    for (const auto& spec : config_schema()) {
        auto a = spec.show(before);
        auto b = spec.show(after);
        if (a != b) {
            out.push_back({spec.path, std::move(a), std::move(b), spec.runtime});
        }
    }
    return out;
}

}  // namespace airseg::daemon

#include "daemon/config_loader.hpp"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>

#include "base/file_text.hpp"
#include "base/utf8.hpp"
#include "daemon/autopilot_setup.hpp"
#include "daemon/config_paths.hpp"
#include "daemon/config_schema.hpp"
#include "services/common/nearest_word.hpp"

namespace airseg::daemon {
namespace {

std::string location(const std::string& source, const YAML::Mark& mark) {
    if (mark.is_null()) {
        return source;
    }
    return fmt::format("{}:{}:{}", source, mark.line + 1, mark.column + 1);
}

/// "did you mean 'autopilot.port'?" for a near miss among the keys of the same section.
std::string suggestion(const std::string& path) {
    const auto dot = path.rfind('.');
    const std::string section = dot == std::string::npos ? "" : path.substr(0, dot + 1);
    std::vector<std::string> candidates;
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
        candidates.push_back(std::move(candidate));
    }
    return did_you_mean(path, candidates);
}

/// The errors of one load: the first kMaxListedConfigErrors listed, the rest only counted. A key echoed in an
/// error is cut (excerpt), so a megabyte-long key is not printed whole.
class Errors {
  public:
    explicit Errors(ConfigResult& result) : result_(result) {}
    /// No more room: a caller may skip the work of describing the next error (add() still counts it).
    bool full() const { return result_.errors.size() >= kMaxListedConfigErrors; }
    void add(std::string where, const std::string& key, std::string message) {
        if (full()) {
            ++result_.unlisted_errors;
            return;
        }
        result_.errors.push_back({std::move(where), excerpt(key), std::move(message)});
    }

  private:
    ConfigResult& result_;
};

/// The first scalar of `node` (itself, or an item or key or value of it, as deep as a key's value is read: a
/// list, a mapping) holding a control character; a null node if none. Escapes ("\0", "\x01") put them in a
/// value although the file's text has none. Not deeper: a YAML alias bomb nests lists without end, and no key
/// reads below that depth.
YAML::Node scalar_with_control(const YAML::Node& node, int depth = 1) {
    if (node.IsScalar()) {
        for (const char c : node.Scalar()) {
            if (is_control(static_cast<unsigned char>(c))) {
                return node;
            }
        }
    } else if (depth > 0 && node.IsSequence()) {
        for (const auto& item : node) {
            if (auto found = scalar_with_control(item, depth - 1); !found.IsNull()) {
                return found;
            }
        }
    } else if (depth > 0 && node.IsMap()) {
        for (const auto& entry : node) {
            for (const auto& part : {entry.first, entry.second}) {
                if (auto found = scalar_with_control(part, depth - 1); !found.IsNull()) {
                    return found;
                }
            }
        }
    }
    return YAML::Node(YAML::NodeType::Null);
}

std::string control_message(const YAML::Node& node) {
    for (const char c : node.Scalar()) {
        if (is_control(static_cast<unsigned char>(c))) {
            return fmt::format("a control character (0x{:02x}) in '{}': not allowed in a configuration value",
                               static_cast<unsigned char>(c), excerpt(node.Scalar()));
        }
    }
    return "a control character";
}

class Walker {
  public:
    Walker(const std::string& source, Config& config, Errors& errors,
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
                if (const auto bad = scalar_with_control(value); !bad.IsNull()) {
                    error(bad.Mark(), path, control_message(bad));
                } else if (auto message = spec->apply(value, config_)) {
                    error(value.Mark(), path, *message);
                }
            } else if (is_section(path)) {
                walk(value, path);
            } else if (errors_.full()) {
                error(key_node.Mark(), path, "");  // counted, not listed: spare the suggestion's work
            } else {
                error(key_node.Mark(), path,
                      fmt::format("unknown key '{}'{}", excerpt(path), suggestion(path)));
            }
        }
    }

  private:
    void error(const YAML::Mark& mark, const std::string& key, std::string message) {
        errors_.add(location(source_, mark), key, std::move(message));
    }

    const std::string& source_;
    Config& config_;
    Errors& errors_;
    std::map<std::string, std::string>& where_;
};

void apply_override(const std::string& text, Config& config, Errors& errors,
                    std::map<std::string, std::string>& where) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0) {
        errors.add("--set", "", fmt::format("'{}' must be KEY=VALUE", excerpt(text)));
        return;
    }
    const std::string key = text.substr(0, eq);
    const std::string value = text.substr(eq + 1);
    const KeySpec* spec = find_key(key);
    if (spec == nullptr) {
        errors.add("--set", key, fmt::format("unknown key '{}'{}", excerpt(key), suggestion(key)));
        return;
    }
    where[key] = "--set " + key;
    if (const auto fault = first_text_fault(value)) {
        errors.add("--set", key, fault->what() + " in the value");
        return;
    }
    try {
        // Parsed as YAML so that lists ("[a, b]") and quoting work as in the file.
        const YAML::Node node = value.empty() ? YAML::Node(YAML::NodeType::Null) : YAML::Load(value);
        if (const auto bad = scalar_with_control(node); !bad.IsNull()) {
            errors.add("--set", key, control_message(bad));
        } else if (auto message = spec->apply(node, config)) {
            errors.add("--set", key, *message);
        }
    } catch (const YAML::Exception& e) {
        errors.add("--set", key, fmt::format("value is not valid YAML: {}", e.msg));
    }
}

/// Rules that involve more than one key.
void check_consistency(const Config& c, const std::string& source,
                       const std::map<std::string, std::string>& where, Errors& errors) {
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
        errors.add(at("groundlink.ports", "groundlink.mode"), "groundlink.ports",
                   fmt::format("mode '{}' needs two ports, {} given", g.mode, g.ports.size()));
    }
    if (g.mode == "single" && g.ports.size() != 1) {
        errors.add(at("groundlink.ports", "groundlink.mode"), "groundlink.ports",
                   "mode 'single' uses exactly one port");
    }
    if (c.autopilot.reconnect_min > c.autopilot.reconnect_max) {
        errors.add(at("autopilot.reconnect_min"), "autopilot.reconnect_min",
                   "must not be longer than autopilot.reconnect_max");
    }
    if (g.reconnect_min > g.reconnect_max) {
        errors.add(at("groundlink.reconnect_min"), "groundlink.reconnect_min",
                   "must not be longer than groundlink.reconnect_max");
    }
    for (const auto& [kind, hz] : g.telemetry_rates) {
        if (hz < 0 || hz > 20) {
            errors.add(at("groundlink.telemetry.rates"), "groundlink.telemetry.rates",
                       fmt::format("{}: {} Hz is out of range 0..20", kind, hz));
        }
    }
    for (const auto& problem : mavlink_forward_setup(c).problems) {
        const std::string key = problem.substr(0, problem.find(": "));
        const bool named =
            key.starts_with("groundlink.mavlink_forward.") && key.find(' ') == std::string::npos;
        errors.add(at(named ? key : "groundlink.mavlink_forward.rates"),
                   named ? key : "groundlink.mavlink_forward.rates",
                   named ? problem.substr(key.size() + 2) : problem);
    }
    // "groundlink.radio.packet_overhead needs packet ...": the key, then what is wrong with it.
    if (const auto problem = g.radio.validate("groundlink.radio"); !problem.empty()) {
        const auto space = problem.find(' ');
        const std::string key = problem.substr(0, space);
        errors.add(at(key), key, space == std::string::npos ? problem : problem.substr(space + 1));
    }
    if (!g.monitor_key_file.empty() && g.key_file.empty()) {
        errors.add(at("groundlink.monitor_key_file"), "groundlink.monitor_key_file",
                   "needs groundlink.key_file (the control key)");
    }
    for (auto& problem : port_problems(c)) {
        errors.add(at(problem.key), problem.key, std::move(problem.message));
    }
    // The autopilot layer's own rules, reported at the key they name.
    for (const auto& problem : autopilot_setup(c).problems) {
        const std::string key = problem_key(problem);
        if (key.empty()) {
            errors.add(at("autopilot", "autopilot.board"), "autopilot", problem);
        } else {
            errors.add(at(key), key, problem.substr(key.size() + 2));
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

namespace {

struct Source {
    std::string text;
    std::string name;  // a file name, in error locations
};

/// Reads a whole file (base/file_text.hpp: a regular file of at most kMaxConfigFileBytes); on failure the
/// error names the file and the cause (permission denied, a FIFO, too large, ...).
std::optional<Source> read_source(const std::string& path, Errors& errors) {
    auto file = read_file_text(path, kMaxConfigFileBytes);
    if (!file.ok()) {
        errors.add(
            path, "",
            "cannot read the configuration file: " +
                (file.errno_value != 0 ? std::generic_category().message(file.errno_value) : file.error));
        return std::nullopt;
    }
    return Source{std::move(file.text), path};
}

/// Records the start of a document, and nothing else: finds a second document without building it.
class DocumentCounter : public YAML::EventHandler {
  public:
    YAML::Mark start = YAML::Mark::null_mark();
    void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
    void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
    void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
    void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                         YAML::EmitterStyle::value) override {}
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                    YAML::EmitterStyle::value) override {}
    void OnMapEnd() override {}
};

/// Where a second YAML document of `text` starts, if it has one (yaml-cpp's Load reads the first only).
std::optional<YAML::Mark> second_document(const std::string& text) {
    std::istringstream in(text);
    YAML::Parser parser(in);
    DocumentCounter counter;
    if (!parser.HandleNextDocument(counter) || !parser.HandleNextDocument(counter)) {
        return std::nullopt;
    }
    return counter.start;
}

/// One source over the configuration so far; every problem goes to `errors`.
void load_source(const Source& source, Config& config, Errors& errors,
                 std::map<std::string, std::string>& where) {
    if (const auto fault = first_text_fault(source.text)) {
        // yaml-cpp would pass malformed bytes into the values and end the file at a NUL, silently.
        const auto at = position_of(source.text, fault->offset);
        errors.add(fmt::format("{}:{}:{}", source.name, at.line, at.column), "",
                   fault->what() + ": a configuration file is UTF-8 text without control characters");
        return;
    }
    try {
        const YAML::Node root = YAML::Load(source.text);
        if (const auto second = second_document(source.text)) {
            errors.add(location(source.name, *second), "",
                       "a second YAML document: a configuration file holds one (drop-ins go to conf.d/)");
        }
        if (root.IsDefined() && !root.IsNull()) {
            Walker(source.name, config, errors, where).walk(root, "");
        }
    } catch (const YAML::ParserException& e) {
        errors.add(location(source.name, e.mark), "", fmt::format("YAML syntax error: {}", e.msg));
    } catch (const YAML::Exception& e) {
        errors.add(location(source.name, e.mark), "", fmt::format("malformed configuration: {}", e.msg));
    }
}

/// Each source in order over the defaults (a key in a later one wins), then the overrides, then the rules
/// between keys. `main` names the configuration where no single key is to blame.
ConfigResult load_sources(const std::vector<Source>& sources, const std::string& main,
                          const std::vector<std::string>& overrides, ConfigResult result = {}) {
    Errors errors(result);
    std::map<std::string, std::string> where;
    for (const auto& source : sources) {
        load_source(source, result.config, errors, where);
    }
    for (const auto& o : overrides) {
        apply_override(o, result.config, errors, where);
    }
    if (result.errors.empty()) {
        check_consistency(result.config, main, where, errors);
    }
    return result;
}

}  // namespace

ConfigResult load_config_text(std::string_view text, const std::string& source,
                              const std::vector<std::string>& overrides) {
    return load_sources({Source{std::string(text), source}}, source, overrides);
}

std::vector<std::string> drop_in_files(const std::string& path) {
    namespace fs = std::filesystem;
    std::vector<std::string> files;
    std::error_code ec;
    const fs::path dir = fs::path(path).parent_path() / "conf.d";
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        // Editors' backups (x.yaml~, .x.yaml.swp) and dpkg's leftovers (x.yaml.dpkg-old) end otherwise.
        const auto name = it->path().filename().string();
        if (it->path().extension() == ".yaml" && !name.starts_with(".")) {
            files.push_back(it->path().string());
        }
    }
    std::sort(files.begin(), files.end());
    return files;
}

ConfigResult load_config_file(const std::string& path, const std::vector<std::string>& overrides) {
    ConfigResult result;
    Errors errors(result);
    auto main = read_source(path, errors);
    if (!main) {
        return result;
    }
    std::vector<Source> sources{std::move(*main)};
    for (const auto& file : drop_in_files(path)) {
        if (auto source = read_source(file, errors)) {
            sources.push_back(std::move(*source));
        }
    }
    return load_sources(sources, path, overrides, std::move(result));
}

std::vector<std::string> ConfigResult::error_lines() const {
    std::vector<std::string> lines;
    lines.reserve(errors.size() + 1);
    for (const auto& e : errors) {
        lines.push_back(e.to_string());
    }
    if (unlisted_errors > 0) {
        lines.push_back(
            fmt::format("... and {} more error{}", unlisted_errors, unlisted_errors == 1 ? "" : "s"));
    }
    return lines;
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

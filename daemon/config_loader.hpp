#pragma once
// Reads and validates the configuration. Every problem in a file is reported, each with the key path and its
// file:line:column, so one run of `airsegd --check-config` shows everything that needs fixing.
#include <string>
#include <string_view>
#include <vector>

#include "daemon/config.hpp"

namespace airseg::daemon {

struct ConfigError {
    std::string where;  // "file:line:column", or "--set" for a command-line override
    std::string key;    // dotted key path, may be empty for syntax errors
    std::string message;

    std::string to_string() const;
};

/// At most this many errors are listed; the rest are counted ("... and N more errors"), so a file of a
/// hundred thousand unknown keys does not print a hundred thousand lines.
inline constexpr std::size_t kMaxListedConfigErrors = 50;

struct ConfigResult {
    Config config;
    std::vector<ConfigError> errors;  // the first kMaxListedConfigErrors
    std::size_t unlisted_errors = 0;  // found after those
    bool ok() const { return errors.empty(); }
    std::size_t error_count() const { return errors.size() + unlisted_errors; }
    /// One line per listed error, then "... and N more errors" when some are not listed.
    std::vector<std::string> error_lines() const;
};

/// Loads `path`, then the drop-in files beside it (drop_in_files), then applies each "key=value" override
/// in order. A key set again later wins; every error names the file (or --set) it is in. Each file is read
/// as base/file_text.hpp reads (a regular file of at most kMaxConfigFileBytes, else an error naming it and
/// why) and must be one YAML document of UTF-8 text without control characters, whose root is a mapping (or
/// empty); no value may hold a control character.
ConfigResult load_config_file(const std::string& path, const std::vector<std::string>& overrides = {});

/// The local settings merged over `path`: conf.d/*.yaml in the same directory, in name order, so that the
/// packaged file stays as shipped and upgrades never ask about it.
std::vector<std::string> drop_in_files(const std::string& path);

/// Same from text; `source` names it in error locations.
ConfigResult load_config_text(std::string_view text, const std::string& source,
                              const std::vector<std::string>& overrides = {});

struct ConfigChange {
    std::string key;
    std::string from;
    std::string to;
    bool runtime;  // can be applied without a restart
};

/// Keys whose values differ between two configurations.
std::vector<ConfigChange> diff_config(const Config& before, const Config& after);

}  // namespace airseg::daemon

#pragma once
#include <optional>
#include <string>
#include <vector>

namespace airseg::daemon {

struct CliOptions {
    std::string config_path = "/etc/airseg/airseg.yaml";
    bool check_config = false;
    std::optional<std::string> log_level;  // overrides log_level from the file, also across SIGHUP
    std::vector<std::string> overrides;    // --set KEY=VALUE, in order
};

struct CliResult {
    enum class Action { Run, Exit } action = Action::Run;
    int exit_code = 0;
    std::string output;  // printed to stdout (help, version) or stderr (errors) before exiting
    CliOptions options;
};

/// Parses airsegd's command line. Bad arguments give exit code 2 with the usage text.
CliResult parse_cli(int argc, const char* const* argv);

std::string usage_text();

}  // namespace airseg::daemon

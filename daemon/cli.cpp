#include "daemon/cli.hpp"

#include <fmt/format.h>
#include <boost/program_options.hpp>

#include <algorithm>
#include <sstream>

#include "cli/command_line.hpp"
#include "services/common/nearest_word.hpp"

namespace airseg::daemon {
namespace po = cli::po;

namespace {

po::options_description describe() {
    po::options_description d("Options");
    // clang-format off
    d.add_options()
        ("config,c", po::value<std::string>()->value_name("FILE"),
         "configuration file (default /etc/airseg/airseg.yaml)")
        ("check-config", "validate the configuration (with any --set) and exit: 0 valid, 78 invalid")
        ("log-level", po::value<std::string>()->value_name("LEVEL"),
         "trace|debug|info|warn|error|critical|off; overrides log_level, also across SIGHUP")
        ("set", po::value<std::vector<std::string>>()->value_name("KEY=VALUE")->composing(),
         "override one configuration key for this run, validated like the file "
         "(repeatable), e.g. --set autopilot.port=/dev/ttyUSB1")
        ("version", "print the version and exit")
        ("help,h", "print this help and exit");
    // clang-format on
    return d;
}

/// A bad command line in one line and where the help is: the whole help would push the reason off the
/// screen.
std::string usage_error(const std::string& message) {
    std::ostringstream out;
    cli::usage_error(out, "airsegd", message);
    return out.str();
}

}  // namespace

std::string usage_text() {
    std::ostringstream out;
    out << "Usage: airsegd [--config FILE] [--set KEY=VALUE]... [--log-level LEVEL] [--check-config]\n"
           "\n"
           "airsegd drives an ArduPilot autopilot over serial MAVLink, feeds it flight plans through a "
           "rolling\n"
           "window of mission items, and talks to the ground over one or two serial radio pairs. It runs in\n"
           "the foreground; under systemd it reports readiness, status and watchdog pings (Type=notify).\n"
           "\n"
        << describe()
        << "\n"
           "Signals: SIGTERM/SIGINT stop in order (exit 0); SIGHUP re-reads the configuration file and "
           "applies\n"
           "the settings that can change at run time (an invalid file is reported and the running one "
           "kept).\n"
           "\n"
           "Exit codes: 0 stopped normally, 2 bad command line, 78 invalid configuration (EX_CONFIG),\n"
           "1 other fatal error.\n";
    return out.str();
}

CliResult parse_cli(int argc, const char* const* argv) {
    CliResult result;
    po::variables_map vm;
    try {
        // Unique prefixes of the long names have always been accepted here ("--conf").
        cli::parse(std::vector<std::string>(argv + std::min(argc, 1), argv + argc), describe(), vm,
                   {.allow_guessing = true});
    } catch (const cli::UsageError& e) {
        result.action = CliResult::Action::Exit;
        result.exit_code = cli::kUsageExit;
        result.output = usage_error(e.what());
        return result;
    }
    if (vm.count("help")) {
        result.action = CliResult::Action::Exit;
        result.output = usage_text();
        return result;
    }
    if (vm.count("version")) {
        result.action = CliResult::Action::Exit;
        result.output = fmt::format("airsegd {}\n", AIRSEG_VERSION);
        return result;
    }
    auto& o = result.options;
    if (vm.count("config")) {
        o.config_path = vm["config"].as<std::string>();
    }
    o.check_config = vm.count("check-config") > 0;
    if (vm.count("log-level")) {
        const auto level = vm["log-level"].as<std::string>();
        static const std::vector<std::string> kLevels{"trace", "debug",    "info", "warn",
                                                      "error", "critical", "off"};
        if (std::find(kLevels.begin(), kLevels.end(), level) == kLevels.end()) {
            result.action = CliResult::Action::Exit;
            result.exit_code = cli::kUsageExit;
            result.output = usage_error(fmt::format("--log-level: '{}' is not one of {}{}", level,
                                                    fmt::join(kLevels, ", "), did_you_mean(level, kLevels)));
            return result;
        }
        o.log_level = level;
    }
    if (vm.count("set")) {
        o.overrides = vm["set"].as<std::vector<std::string>>();
    }
    return result;
}

}  // namespace airseg::daemon

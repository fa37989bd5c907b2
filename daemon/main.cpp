// airsegd: the airseg on-board daemon.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "daemon/app.hpp"
#include "daemon/cli.hpp"
#include "daemon/config_loader.hpp"
#include "daemon/config_paths.hpp"
#include "daemon/logging.hpp"

namespace {
constexpr int kExitConfig = 78;  // EX_CONFIG from sysexits.h
}

int main(int argc, char** argv) {
    using namespace airseg::daemon;
    auto cli = parse_cli(argc, argv);
    if (cli.action == CliResult::Action::Exit) {
        (cli.exit_code == 0 ? std::cout : std::cerr) << cli.output;
        return cli.exit_code;
    }
    auto loaded = load_config_file(cli.options.config_path, cli.options.overrides);
    if (!loaded.ok()) {
        // Printed plainly (not through the logger) so they read the same in a terminal and in the journal.
        for (const auto& line : loaded.error_lines()) {
            std::cerr << "airsegd: " << line << "\n";
        }
        std::cerr << "airsegd: " << loaded.error_count()
                  << " error(s) in the configuration; nothing started\n";
        return kExitConfig;
    }
    if (cli.options.check_config) {
        // Valid, yet bound to fail under the unit's ProtectSystem=strict: said, not refused (a run by hand,
        // the demo, may write anywhere).
        for (const auto& w : unwritable_path_warnings(loaded.config)) {
            std::cerr << "airsegd: warning: " << w.key << ": " << w.message << "\n";
        }
        std::cout << "airsegd: " << cli.options.config_path;
        for (const auto& drop_in : drop_in_files(cli.options.config_path)) {
            std::cout << " + " << drop_in;
        }
        std::cout << ": configuration is valid\n";
        return 0;
    }
    if (cli.options.log_level) {
        loaded.config.log_level = *cli.options.log_level;
    }
    setup_logging(loaded.config.log_level);
    try {
        App app(cli.options, std::move(loaded.config));
        return app.run();
    } catch (const std::exception& e) {
        spdlog::critical("airsegd: fatal: {}", e.what());
        return 1;
    }
}

// airseg-apmsim: a simulated APM:Rover board on a pseudo-terminal. See usage() in options.cpp and
// docs/simulators.md.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <iostream>
#include <string>
#include <vector>

#include "cli/command_line.hpp"
#include "hal/asio.hpp"
#include "tools/apmsim/control.hpp"
#include "tools/apmsim/options.hpp"
#include "tools/apmsim/sim_driver.hpp"

int main(int argc, char** argv) {
    using namespace airseg::apmsim;
    std::optional<ApmSimOptions> options;
    try {
        options = parse_options(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const airseg::cli::UsageError& e) {
        return airseg::cli::usage_error(std::cerr, "airseg-apmsim", e.what());
    }
    if (!options) {
        std::cout << usage();
        return 0;
    }
    // Standard output carries the summary printed on exit; diagnostics go to standard error.
    spdlog::set_default_logger(spdlog::stderr_color_mt("apmsim"));
    boost::asio::io_context io;
    SimDriver driver(io, *options);
    if (auto error = driver.start(); !error.empty()) {
        std::cerr << "airseg-apmsim: " << error << '\n';
        return 1;
    }
    std::cerr << "airseg-apmsim: " << options->link_path << " -> " << driver.pty().slave_path()
              << ", speedup " << options->speedup << (options->sim.reset_on_open ? ", reboots on open" : "")
              << (options->control_path.empty() ? std::string() : ", control " + options->control_path)
              << std::endl;

    boost::asio::signal_set stop_signals(io, SIGINT, SIGTERM);
    stop_signals.async_wait([&](const boost::system::error_code& ec, int) {
        if (!ec) {
            driver.stop();
            io.stop();
        }
    });
    boost::asio::signal_set reboot_signal(io, SIGUSR1);
    std::function<void()> wait_reboot = [&] {
        reboot_signal.async_wait([&](const boost::system::error_code& ec, int) {
            if (!ec) {
                driver.reboot();
                wait_reboot();
            }
        });
    };
    wait_reboot();
    io.run();

    nlohmann::json summary{{"modes", modes_json(driver.sim())},
                           {"state", state_json(driver.sim(), driver.sim_now())},
                           {"stats", stats_json(driver.sim())}};
    std::cout << summary.dump() << std::endl;
    return 0;
}

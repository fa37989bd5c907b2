// airseg-linksim: a radio-link emulator between two pseudo-terminals. See usage() in options.cpp and
// docs/simulators.md.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <iostream>
#include <string>
#include <vector>

#include "cli/command_line.hpp"
#include "hal/asio.hpp"
#include "tools/linksim/link_emulator.hpp"
#include "tools/linksim/options.hpp"

int main(int argc, char** argv) {
    using namespace airseg::linksim;
    std::optional<LinkSimOptions> options;
    try {
        options = parse_options(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const airseg::cli::UsageError& e) {
        return airseg::cli::usage_error(std::cerr, "airseg-linksim", e.what());
    }
    if (!options) {
        std::cout << usage();
        return 0;
    }
    const bool json = options->json;
    // Standard output carries the statistics; diagnostics go to standard error.
    spdlog::set_default_logger(spdlog::stderr_color_mt("linksim"));

    boost::asio::io_context io;
    LinkEmulator emulator(io, *options);
    if (auto error = emulator.start(); !error.empty()) {
        std::cerr << "airseg-linksim: " << error << '\n';
        return 1;
    }
    std::cerr << "airseg-linksim: a " << options->a_path << " -> " << emulator.pty(Side::A).slave_path()
              << ", b " << options->b_path << " -> " << emulator.pty(Side::B).slave_path() << ", "
              << options->radio.baud << " baud, " << (options->radio.duplex == Duplex::Half ? "half" : "full")
              << " duplex"
              << (options->control_path.empty() ? std::string() : ", control " + options->control_path)
              << '\n';

    boost::asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code& ec, int) {
        if (!ec) {
            emulator.stop();
            io.stop();
        }
    });
    io.run();

    if (json) {
        std::cout << emulator.stats_json().dump() << std::endl;
    } else {
        std::cout << emulator.stats_text() << std::flush;
    }
    return 0;
}

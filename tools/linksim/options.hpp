#pragma once
// Command line of airseg-linksim.
#include <optional>
#include <string>
#include <vector>

#include "tools/linksim/radio_config.hpp"

namespace airseg::linksim {

struct LinkSimOptions {
    std::string a_path;  ///< symlink to the pty slave of radio A
    std::string b_path;  ///< symlink to the pty slave of radio B
    RadioConfig radio;
    std::string control_path;    ///< empty: no control socket
    Duration stats_interval{0};  ///< zero: statistics only on exit
    bool json = false;
    std::size_t host_backlog = 64 * 1024;  ///< bytes read from a pty waiting for the modelled UART
};

/// The full --help text.
std::string usage();

/// Parses argv. Throws cli::UsageError naming the option on bad input. Returns nullopt for --help.
std::optional<LinkSimOptions> parse_options(const std::vector<std::string>& args);

}  // namespace airseg::linksim

#pragma once
// Command line of airseg-apmsim.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/values.hpp"
#include "tools/apmsim/rover_sim.hpp"

namespace airseg::apmsim {

struct ApmSimOptions {
    std::string link_path;     // --link
    std::string control_path;  // --control
    double speedup = 1.0;      // --speedup
    unsigned baud = 0;         // --baud: the board's UART rate; 0 = whatever the peer sets
    RoverSimConfig sim;
    Faults faults;
    std::vector<std::pair<std::string, float>> params;  // --param NAME=VALUE
    std::optional<Duration> reboot_at;                  // --reboot-at S (simulated seconds after start)
    std::vector<cli::Window> hb_stalls;                 // --hb-stall START:DUR
    std::vector<cli::Window> unplugs;                   // --unplug START:DUR
    bool quiet = false;                                 // --quiet
};

std::string usage();
/// Parses the arguments (without argv[0]). nullopt for --help; throws cli::UsageError.
std::optional<ApmSimOptions> parse_options(const std::vector<std::string>& args);

}  // namespace airseg::apmsim

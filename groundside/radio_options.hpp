#pragma once
// The radio options airsegctl and airseg-ground share (--link, --udp, --baud, --mode, --key, --radio): one
// table so both programs spell, check and explain them the same way.
#include <functional>

#include "cli/command_line.hpp"
#include "groundside/ground_end.hpp"

namespace airseg::groundside {

/// Adds the radio options to `table`, writing into `radio`; `chosen` runs when --link or --udp is given.
void add_radio_options(cli::OptionTable& table, RadioOptions& radio, std::function<void()> chosen);

}  // namespace airseg::groundside

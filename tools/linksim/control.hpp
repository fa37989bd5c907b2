#pragma once
// Run-time fault commands of airseg-linksim, applied to the radio model (sans-IO: text and time in, reply
// out).
#include <string>
#include <string_view>

#include "tools/linksim/radio_model.hpp"

namespace airseg::linksim {

/// Applies one command (see usage() in options.hpp). Returns "ok ..." or "error: ...".
/// `stats` is answered by the caller, which knows the host counters; here it is an error.
std::string apply_control(RadioModel& model, std::string_view command, TimePoint now);

}  // namespace airseg::linksim

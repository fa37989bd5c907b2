#pragma once
// Bus messages of the status service.
#include <nlohmann/json.hpp>
#include <string>

namespace airseg::status {

/// A service's own part of the status document, e.g. "autopilot" → {"link":"up",...}. Published as an event;
/// the status service keeps the newest per name.
struct StatusSection {
    std::string name;
    nlohmann::json value;
};

/// The one-line summary for systemd's STATUS=, published as a variable whenever it changes.
struct StatusLine {
    std::string text;
};

}  // namespace airseg::status

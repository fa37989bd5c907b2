#pragma once
// Bus messages of the status service.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace airseg::status {

/// A service's own part of the status document, e.g. "autopilot" → {"link":"up",...}. Published as an event;
/// the status service keeps the newest per name. A section published often and read seldom gives `render`
/// instead of `value`: a function over a snapshot of plain values (it runs on the status service's strand,
/// so it may not touch its publisher's state), called only when the document is read.
struct StatusSection {
    std::string name;
    nlohmann::json value;
    std::function<nlohmann::json()> render;
};

/// The one-line summary for systemd's STATUS=, published as a variable whenever it changes.
struct StatusLine {
    std::string text;
};

}  // namespace airseg::status

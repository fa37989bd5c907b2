#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace airseg::client {

/// The status document as people read it: services first, then each section's keys.
std::string render_status(const nlohmann::json& doc);

}  // namespace airseg::client

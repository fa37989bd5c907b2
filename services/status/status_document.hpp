#pragma once
// Builds the status document and its one-line summary from service health and the services' own sections.
// Kept free of I/O so that both are tested directly.
#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "services/common/health.hpp"

namespace airseg::status {

nlohmann::json build_document(const std::vector<ServiceHealth>& services,
                              const std::map<std::string, nlohmann::json>& sections, double uptime_s);

/// e.g. "autopilot: DOWN (no /dev/ttyACM0) · groundlink: UP · plan: none".
std::string summary_line(const std::vector<ServiceHealth>& services,
                         const std::map<std::string, nlohmann::json>& sections);

/// ISO 8601 UTC with milliseconds, e.g. 2026-11-22T10:00:00.123Z.
std::string iso8601(std::chrono::system_clock::time_point t);

}  // namespace airseg::status

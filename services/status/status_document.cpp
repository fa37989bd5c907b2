#include "services/status/status_document.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <ctime>

namespace airseg::status {

std::string iso8601(std::chrono::system_clock::time_point t) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count();
    const std::time_t secs = static_cast<std::time_t>(ms / 1000);
    std::tm tm{};
    gmtime_r(&secs, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
    return fmt::format("{}.{:03}Z", buf, ms % 1000);
}

nlohmann::json build_document(const std::vector<ServiceHealth>& services,
                              const std::map<std::string, nlohmann::json>& sections, double uptime_s) {
    nlohmann::json doc;
    doc["version"] = AIRSEG_VERSION;
    doc["uptime_s"] = std::round(uptime_s * 10) / 10;
    auto& out = doc["services"] = nlohmann::json::object();
    for (const auto& s : services) {
        out[s.name] = {{"health", to_string(s.health)}, {"since", iso8601(s.since)}, {"error", s.error}};
    }
    for (const auto& [name, value] : sections) {
        doc[name] = value;
    }
    return doc;
}

std::string summary_line(const std::vector<ServiceHealth>& services,
                         const std::map<std::string, nlohmann::json>& sections) {
    std::string line;
    auto append = [&line](const std::string& part) {
        if (!line.empty()) {
            line += " · ";
        }
        line += part;
    };
    for (const auto& s : services) {
        if (s.name == "status") {
            continue;  // the status service is the one writing this line
        }
        std::string health = to_string(s.health);
        for (auto& ch : health) {
            ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
        }
        append(s.error.empty() ? fmt::format("{}: {}", s.name, health)
                               : fmt::format("{}: {} ({})", s.name, health, s.error));
    }
    if (auto it = sections.find("plan"); it != sections.end() && it->second.contains("state")) {
        append(fmt::format("plan: {}", it->second["state"].get<std::string>()));
    }
    return line;
}

}  // namespace airseg::status

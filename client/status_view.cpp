#include "client/status_view.hpp"

#include <fmt/format.h>

#include "client/json_text.hpp"
#include "services/common/text.hpp"

namespace airseg::client {
namespace {

std::string scalar(const nlohmann::json& v) {
    if (v.is_string()) {
        return v.get<std::string>();
    }
    if (v.is_number_float()) {
        return fmt::format("{:.7g}", v.get<double>());
    }
    return dump_text(v);
}

void flatten(const nlohmann::json& v, const std::string& prefix, std::string& out) {
    if (v.is_object()) {
        for (const auto& [key, value] : v.items()) {
            flatten(value, prefix.empty() ? key : prefix + "." + key, out);
        }
        return;
    }
    out += fmt::format("  {:<28} {}\n", prefix, scalar(v));
}

}  // namespace

std::string render_status(const nlohmann::json& doc) {
    std::string out =
        fmt::format("airsegd {}, up {} s\n", doc.value("version", "?"), scalar(doc.value("uptime_s", 0.0)));
    if (doc.contains("services") && doc["services"].is_object()) {
        out += "services:\n";
        for (const auto& [name, s] : doc["services"].items()) {
            const std::string error = s.value("error", "");
            out += fmt::format("  {:<12} {:<9} since {}{}\n", name, to_upper(s.value("health", "?")),
                               s.value("since", "?"), error.empty() ? "" : "  (" + error + ")");
        }
    }
    for (const auto& [name, section] : doc.items()) {
        if (name == "services" || name == "version" || name == "uptime_s") {
            continue;
        }
        out += name + ":\n";
        if (section.is_object()) {
            flatten(section, "", out);
        } else {
            out += "  " + scalar(section) + "\n";
        }
    }
    return out;
}

}  // namespace airseg::client

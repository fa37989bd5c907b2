#include "daemon/autopilot_status.hpp"

#include <cctype>
#include <cmath>

#include "services/status/status_messages.hpp"

namespace airseg::daemon {

std::string state_name(autopilot::VehicleState s) {
    std::string name = autopilot::to_string(s);
    for (char& c : name) {
        c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    return name;
}

std::optional<autopilot::VehicleState> parse_state_name(std::string_view text) {
    if (text.size() > 32) {
        return std::nullopt;
    }
    std::string lower(text);
    for (char& c : lower) {
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    return autopilot::vehicle_state_from_string(lower);
}

nlohmann::json autopilot_status_json(const autopilot::AutopilotStatus& s) {
    nlohmann::json j;
    j["link"] = s.link_up ? "up" : "down";
    j["ready"] = s.ready;
    // Tenths of a second are all a person or a script needs, and they keep the section from churning.
    j["ready_s"] = s.ready_s ? nlohmann::json(std::round(*s.ready_s * 10.0) / 10.0) : nlohmann::json(nullptr);
    j["state"] = state_name(s.state);
    j["mode"] = s.mode;
    if (s.position) {
        j["position"] = {{"lat", s.position->lat}, {"lon", s.position->lon}, {"alt", s.position->alt}};
    } else {
        j["position"] = nullptr;
    }
    j["position_invalid"] =
        s.position_invalid.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.position_invalid);
    j["mission_current"] = s.mission_current;
    j["reboots"] = s.reboots;
    j["link_losses"] = s.link_losses;
    j["link_verdicts_deferred"] = s.link_verdicts_deferred;
    j["syncs"] = s.syncs;
    j["reconnects"] = s.reconnects;
    j["reset_pulses"] = s.reset_pulses;
    j["armed"] = s.armed ? nlohmann::json(*s.armed) : nlohmann::json(nullptr);
    j["arm_refusals"] = s.arm_refusals;
    j["speed"] = s.speed ? nlohmann::json(*s.speed) : nlohmann::json(nullptr);
    j["mission_items"] = s.mission_items;
    j["auto_restarts_corrected"] = s.auto_restarts_corrected;
    j["baud"] = s.baud;
    j["refused_values"] = {
        {"count", s.refused_values},
        {"last", s.refused_value.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.refused_value)}};
    j["params"] = {
        {"cached", s.params_cached}, {"announced", s.params_announced}, {"dropped", s.params_dropped}};
    auto& stations = j["ground_stations"] = {{"missions_too_large", s.gcs_missions_too_large},
                                             {"to_airsegd_kept", s.gcs_to_airsegd_kept}};
    if (s.gcs_endpoint) {
        stations["udp_peers"] = s.gcs_udp_peers;
        stations["tcp_clients"] = s.gcs_tcp_clients;
        stations["udp_peers_evicted"] = s.gcs_udp_peers_evicted;
        stations["tcp_refused"] = s.gcs_tcp_refused;
        stations["frames_in"] = s.gcs_frames_in;
        stations["invalid_in"] = s.gcs_invalid_in;
        stations["dropped_out"] = s.gcs_dropped_out;
    }
    if (s.tlog_enabled) {
        // A recorder that cannot write (disk full, read-only) is reported; the daemon goes on without it.
        j["tlog"] = {
            {"write_errors", s.tlog_write_errors},
            {"dropped_frames", s.tlog_dropped_frames},
            {"error", s.tlog_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.tlog_error)}};
    }
    return j;
}

AutopilotStatusSection::AutopilotStatusSection(Bus& bus, Strand strand) : bus_(bus) {
    subscription_ =
        bus_.subscribe<autopilot::AutopilotStatus>(strand, [this](const autopilot::AutopilotStatus& s) {
            // Published five times a second and mostly unchanged: comparing the values is far cheaper than
            // building the JSON to compare.
            if (last_ && *last_ == s) {
                return;
            }
            last_ = s;
            bus_.publish(status::StatusSection{"autopilot", autopilot_status_json(s), {}});
        });
}

}  // namespace airseg::daemon

#include "groundside/mqtt_options.hpp"

#include <algorithm>

namespace airseg::groundside {

void add_mqtt_options(cli::OptionTable& table, MqttOptions& options, std::string& vehicle,
                      std::function<void()> chosen) {
    using namespace airseg::cli;
    table
        .value("mqtt", "HOST[:PORT]", "the fleet's MQTT broker (port 1883 unless given); docs/fleet.md",
               [&options, chosen](std::string_view option, std::string_view v) {
                   if (auto problem = parse_broker(v, options); !problem.empty()) {
                       throw UsageError(std::string(option) + ": " + problem);
                   }
                   chosen();
               })
        .value("vehicle", "ID", "the vehicle's id on the broker (its topics are airseg/ID/...)",
               [&vehicle](std::string_view option, std::string_view v) {
                   vehicle = v;
                   if (auto problem = check_vehicle_id(vehicle); !problem.empty()) {
                       throw UsageError(std::string(option) + ": " + problem);
                   }
               })
        .value("mqtt-user", "NAME", "broker user name", text(options.username))
        .value("mqtt-password-file", "FILE",
               "the broker password, on the first line of FILE (with --mqtt-user)",
               text(options.password_file))
        .value("mqtt-ca", "FILE",
               "TLS to the broker (give its TLS port, often 8883): its certificate must be signed by this CA "
               "(PEM) and name the broker's host",
               text(options.ca_file))
        .value("mqtt-cert", "FILE", "TLS client certificate, PEM (with --mqtt-key and --mqtt-ca)",
               text(options.cert_file))
        .value("mqtt-key", "FILE", "the client certificate's private key, PEM, not encrypted",
               text(options.key_file));
}

std::string check_mqtt_options(const MqttOptions& m) {
    if (!m.password_file.empty() && m.username.empty()) {
        return "--mqtt-password-file needs --mqtt-user";
    }
    if (m.cert_file.empty() != m.key_file.empty()) {
        return "--mqtt-cert and --mqtt-key go together";
    }
    if (!m.cert_file.empty() && m.ca_file.empty()) {
        return "--mqtt-cert needs --mqtt-ca (TLS)";
    }
    return {};
}

std::string check_vehicle_id(const std::string& id) {
    const bool fit = !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
               c == '-';
    });
    return fit ? std::string{} : "vehicle id '" + id + "' is not 1 to 64 of A-Z a-z 0-9 _ -";
}

}  // namespace airseg::groundside

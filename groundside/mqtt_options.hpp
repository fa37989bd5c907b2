#pragma once
// The MQTT options airsegctl and airseg-ground share (--mqtt, --vehicle, --mqtt-user, --mqtt-password-file,
// --mqtt-ca, --mqtt-cert, --mqtt-key): one table, one spelling, one check.
#include <functional>
#include <string>

#include "cli/command_line.hpp"
#include "groundside/mqtt_session.hpp"

namespace airseg::groundside {

/// Adds the options to `table`, writing into `options` and `vehicle`; `chosen` runs when --mqtt is given.
void add_mqtt_options(cli::OptionTable& table, MqttOptions& options, std::string& vehicle,
                      std::function<void()> chosen);

/// The options together (a password needs a user, a client certificate its key and a CA); an error for
/// people, empty when fine.
std::string check_mqtt_options(const MqttOptions& options);

/// A vehicle id fit for a topic level: 1 to 64 of A-Z a-z 0-9 _ -. An error for people, empty when fine.
std::string check_vehicle_id(const std::string& id);

/// The topic of one kind of a vehicle's messages: airseg/<vehicle>/<kind>.
inline std::string vehicle_topic(const std::string& vehicle, const std::string& kind) {
    return "airseg/" + vehicle + "/" + kind;
}

}  // namespace airseg::groundside

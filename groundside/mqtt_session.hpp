#pragma once
// One MQTT connection (libmosquitto, MQTT 3.1.1) for airseg-ground's fleet bridge and airsegctl --mqtt:
// user/password and TLS (CA, client certificate; the broker's certificate checked against the CA and the host
// name), a last will, subscriptions renewed on every reconnect, and reconnection with backoff (after a TLS
// failure too) by a network thread of its own. Every handler runs on the executor given, never on that
// thread. docs/fleet.md.
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "services/common/asio.hpp"

namespace airseg::groundside {

struct MqttOptions {
    std::string host = "localhost";
    int port = 1883;
    std::string username;
    std::string password_file;  // the password's first line; a file, so it is not on a command line
    std::string ca_file;        // TLS: the broker's CA; TLS is on when this is set
    std::string cert_file;      // TLS client certificate (with key_file)
    std::string key_file;
    std::string client_id;      // empty: the library makes one up
    bool clean_session = true;  // false: the broker keeps our subscriptions and QoS 1 messages while away
    int keepalive_s = 10;
};

/// "HOST" or "HOST:PORT" into `options`; an error for people, empty when fine.
std::string parse_broker(std::string_view text, MqttOptions& options);

class MqttSession {
  public:
    struct Handlers {
        /// Connected (true), or the connection is gone or an attempt failed (false, with why: the broker's
        /// refusal, a TLS failure, "connection lost", the system's "Connection refused"). `definitive` when
        /// trying again fails the same way until someone changes something (a refusal, a certificate).
        std::function<void(bool connected, const std::string& why, bool definitive)> on_connection;
        std::function<void(const std::string& topic, const std::string& payload)> on_message;
    };

    MqttSession(asio::any_io_executor executor, MqttOptions options, Handlers handlers);
    ~MqttSession();
    MqttSession(const MqttSession&) = delete;
    MqttSession& operator=(const MqttSession&) = delete;

    /// Before start(): what the broker publishes for us if we vanish.
    void set_will(const std::string& topic, const std::string& payload, int qos, bool retain);
    /// Starts connecting (and reconnecting, for as long as it runs); an error for people when the options
    /// cannot work (a missing password file; a TLS file missing, unreadable, not PEM, a key not the
    /// certificate's, naming the option and the file), empty otherwise.
    std::string start();
    void stop();

    /// Queues a message; QoS 1 messages wait for the connection if it is down. False when refused (too big,
    /// stopped).
    bool publish(const std::string& topic, const std::string& payload, int qos, bool retain);
    /// Subscribes now if connected, and again after every reconnect.
    void subscribe(const std::string& topic, int qos);

  private:
    struct State;
    std::shared_ptr<State> state_;
};

}  // namespace airseg::groundside

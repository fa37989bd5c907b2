#pragma once
// airsegctl through an MQTT broker (airsegctl --mqtt HOST --vehicle ID): the topics a ground hub's fleet
// bridge publishes for that vehicle (docs/fleet.md). Commands go to airseg/ID/cmd and their answers come back
// on airseg/ID/cmd/result by request id; watch and log read the telemetry, link and events topics.
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "client/vehicle_link.hpp"
#include "groundside/mqtt_session.hpp"

namespace airseg::client {

/// The telemetry sample in the fleet bridge's JSON (telemetry_json) back in the protocol's form; nullopt
/// when it is not one.
std::optional<groundlink::protocol::Telemetry> telemetry_from_json(const nlohmann::json& vehicle);

class MqttClient final : public VehicleLink {
  public:
    MqttClient(groundside::MqttOptions options, std::string vehicle);
    ~MqttClient() override;
    MqttClient(const MqttClient&) = delete;
    MqttClient& operator=(const MqttClient&) = delete;

    /// Connects to the broker and subscribes; an error for people (refused: "not authorised") or empty.
    std::string open(std::chrono::milliseconds timeout);

    LocalAnswer request(const nlohmann::json& request, std::chrono::milliseconds timeout,
                        const MessageHandler& on_message = {}) override;
    void run_for(std::chrono::milliseconds duration,
                 const std::function<void(const groundlink::protocol::Message&)>& on_message) override;
    nlohmann::json link_stats() const override { return link_; }
    bool link_up() const override { return link_.value("link", "down") == "up"; }
    /// Stick input is not carried over MQTT: a broker's latency is no way to drive.
    void send_joystick(double, double) override {}

  private:
    LocalAnswer exchange(const nlohmann::json& request, std::chrono::milliseconds timeout);
    void on_message(const std::string& topic, const std::string& payload);

    asio::io_context io_;
    // libmosquitto's network thread posts each message to io_, which otherwise has nothing to wait on between
    // two: run_for() would return at once and a live view redraw as fast as it can print.
    asio::any_io_executor keep_waiting_ =
        asio::prefer(io_.get_executor(), asio::execution::outstanding_work.tracked);
    std::string vehicle_;
    std::unique_ptr<groundside::MqttSession> session_;
    bool connected_ = false;
    std::string refused_;
    bool definitive_ = false;             // refused_ would only repeat (a refusal, a TLS failure)
    std::pair<std::string, int> broker_;  // host, port: for the messages
    nlohmann::json link_ = {{"link", "down"}};
    std::function<void(const groundlink::protocol::Message&)> on_message_;
    std::string awaiting_;
    std::optional<nlohmann::json> answer_;
};

}  // namespace airseg::client

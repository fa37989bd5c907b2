#pragma once
// The hub's window onto an MQTT broker shared by a fleet: what the vehicle pushes, the link statistics and
// the plan's progress under airseg/<vehicle>/..., and commands taken from airseg/<vehicle>/cmd, each answered
// on
// .../cmd/result. The broker's access control decides who may command; the bridge runs what reaches it with
// the hub's control rights. docs/fleet.md.
#include <deque>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "ground/hub.hpp"
#include "groundside/mqtt_session.hpp"

namespace airseg::ground {

struct FleetConfig {
    groundside::MqttOptions mqtt;  // client_id and clean_session are set by the bridge
    std::string vehicle;           // the <vehicle> in every topic
    std::string hub_version;       // "airseg-ground 1.2.3", for the status topic
};

class FleetBridge {
  public:
    /// Command ids remembered, so that a QoS 1 command delivered twice runs once.
    static constexpr std::size_t kRememberedIds = 256;

    FleetBridge(asio::any_io_executor strand, Hub& hub, FleetConfig config);
    FleetBridge(const FleetBridge&) = delete;
    FleetBridge& operator=(const FleetBridge&) = delete;

    /// Starts connecting to the broker (and reconnecting for as long as it runs); an error for people when
    /// the options cannot work, empty otherwise.
    std::string start();
    void stop();

  private:
    std::string topic(std::string_view leaf) const;
    void on_connection(bool up, const std::string& why);
    void on_command(const std::string& payload);
    void on_vehicle(const groundlink::protocol::Message& message);
    void publish(std::string_view leaf, const nlohmann::json& payload, int qos, bool retain = false);
    void publish_status();
    void publish_plan();
    void answer(const nlohmann::json& id, const nlohmann::json& answer);
    /// Remembers `key` as running; false when it was seen before (its answer, if any, is sent again).
    bool first_time(const std::string& key, const nlohmann::json& id);
    void tick();

    Hub& hub_;
    FleetConfig config_;
    groundside::MqttSession session_;
    asio::steady_timer timer_;
    bool connected_ = false;
    std::string last_why_;
    std::string link_ = "down";
    std::optional<groundlink::protocol::LinkStatsReport> vehicle_link_;
    std::optional<nlohmann::json> plan_;  // state, element, next_waypoint as last published
    std::map<std::string, std::optional<nlohmann::json>> answers_;  // by id as JSON text; empty: running
    std::deque<std::string> answer_order_;
    bool stopped_ = false;
};

}  // namespace airseg::ground

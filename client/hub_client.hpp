#pragma once
// airsegctl through the ground hub (airseg-ground), which owns the radio and keeps the one session to the
// vehicle: a Unix or TCP socket carrying hub frames (groundside/hub_wire.hpp). The hub grants a role per
// client: control (one client at a time, with the control key when the hub has one) or monitor.
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "client/vehicle_link.hpp"
#include "groundside/hub_wire.hpp"

namespace airseg::client {

struct HubOptions {
    std::string socket{groundside::hub::kDefaultSocket};  // Unix socket path, unless tcp is set
    std::string tcp;                                      // HOST:PORT of the hub's TCP listener
    std::string key_file;            // proves the control key; without it the client is a monitor
    bool want_control = false;       // commands that change the vehicle ask for control
    std::string name = "airsegctl";  // shown by the hub to other clients and in its log
};

class HubClient final : public VehicleLink {
  public:
    explicit HubClient(HubOptions options);
    ~HubClient() override;
    HubClient(const HubClient&) = delete;
    HubClient& operator=(const HubClient&) = delete;

    /// Connects, answers the hub's challenge and waits for its welcome; an error for people, empty on
    /// success.
    std::string open(std::chrono::milliseconds timeout);
    /// The role the hub granted ("control" or "monitor") and, for a monitor that asked for control, why not.
    const std::string& role() const { return role_; }
    const std::string& role_reason() const { return role_reason_; }

    LocalAnswer request(const nlohmann::json& request, std::chrono::milliseconds timeout,
                        const MessageHandler& on_message = {}) override;
    void run_for(std::chrono::milliseconds duration,
                 const std::function<void(const groundlink::protocol::Message&)>& on_message) override;
    nlohmann::json link_stats() const override { return link_; }
    bool link_up() const override { return link_.value("link", "down") == "up"; }
    void send_joystick(double steering, double throttle) override;

  private:
    bool send_frame(const std::vector<std::uint8_t>& frame);
    /// Waits for frames until `deadline` or until `done` says so; false when the connection is gone.
    bool pump(std::chrono::steady_clock::time_point deadline,
              const std::function<bool(groundside::hub::Frame&)>& on_frame);
    void take_json(const nlohmann::json& j);

    HubOptions options_;
    int fd_ = -1;
    groundside::hub::FrameReader reader_;
    std::string role_;
    std::string role_reason_;
    std::string closed_reason_;
    nlohmann::json link_ = {{"link", "down"}};
    std::uint32_t next_id_ = 1;
};

}  // namespace airseg::client

#pragma once
// What airsegctl's live commands need from a path to the vehicle that carries the ground protocol: the radio
// itself (RadioClient) or the ground hub that owns it (HubClient). Blocking calls with timeouts.
#include <chrono>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>

#include "client/local_client.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::client {

class VehicleLink {
  public:
    virtual ~VehicleLink() = default;

    using MessageHandler = std::function<void(const groundlink::protocol::Message&)>;

    /// Sends one command and waits for the vehicle's result. What the vehicle pushes meanwhile goes to
    /// `on_message` as in run_for (a live view that asks keeps its picture whole); without one they are not seen.
    virtual LocalAnswer request(const nlohmann::json& request, std::chrono::milliseconds timeout,
                                const MessageHandler& on_message = {}) = 0;

    /// Runs the link for `duration`, calling `on_message` for each ground-protocol message from the vehicle.
    virtual void run_for(std::chrono::milliseconds duration, const MessageHandler& on_message) = 0;

    /// Link statistics seen from the ground end of the radio link, in the status document's groundlink form.
    virtual nlohmann::json link_stats() const = 0;
    virtual bool link_up() const = 0;

    /// Queues one joystick input as a Fast message (the freshest replaces an unsent one).
    virtual void send_joystick(double steering, double throttle) = 0;
};

}  // namespace airseg::client

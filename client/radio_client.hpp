#pragma once
// airsegctl's radio path: the ground end of the radio link (GroundEnd) run by blocking calls with timeouts,
// since the command line waits for answers.
#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "client/vehicle_link.hpp"
#include "groundside/ground_end.hpp"

namespace airseg::client {

class RadioClient final : public VehicleLink {
  public:
    explicit RadioClient(groundside::RadioOptions options);
    ~RadioClient() override;
    RadioClient(const RadioClient&) = delete;
    RadioClient& operator=(const RadioClient&) = delete;

    /// Opens the ports and starts the transport; returns an error for people, empty on success.
    std::string open();

    /// Sends one command and waits for its result (the session is set up first if needed).
    LocalAnswer request(const nlohmann::json& request, std::chrono::milliseconds timeout,
                        const MessageHandler& on_message = {}) override;

    void run_for(std::chrono::milliseconds duration,
                 const std::function<void(const groundlink::protocol::Message&)>& on_message) override;

    nlohmann::json link_stats() const override;
    bool link_up() const override;
    void send_joystick(double steering, double throttle) override;

    /// Bytes this end's transport wrote to the link so far (all paths, framing included).
    std::uint64_t bytes_sent() const;

  private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace airseg::client

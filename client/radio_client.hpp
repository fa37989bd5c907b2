#pragma once
// airsegctl's radio path: the same ground-link transport core as airsegd, on one or two serial radio ports or
// UDP, speaking the ground protocol. Blocking calls with timeouts: the command line waits for answers.
#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "client/local_client.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"

namespace airseg::client {

struct RadioOptions {
    std::vector<std::string> ports;  // --link PATH[,PATH2], in the same pair order as the vehicle's ports
    unsigned baud = 57600;
    std::string mode = "single";  // single | split | redundant (two ports need split or redundant)
    std::string udp;              // HOST:PORT instead of serial ports
    std::string key_file;         // must match the vehicle's groundlink.key_file
};

/// Checks option combinations; returns a message for people, empty when fine.
std::string validate(const RadioOptions& options);

class RadioClient {
  public:
    explicit RadioClient(RadioOptions options);
    ~RadioClient();
    RadioClient(const RadioClient&) = delete;
    RadioClient& operator=(const RadioClient&) = delete;

    /// Opens the ports and starts the transport; returns an error for people, empty on success.
    std::string open();

    /// Sends one command and waits for its result (the session is set up first if needed).
    LocalAnswer request(const nlohmann::json& request, std::chrono::milliseconds timeout);

    /// Runs the link for `duration`, calling `on_message` for each ground-protocol message from the vehicle.
    void run_for(std::chrono::milliseconds duration,
                 const std::function<void(const groundlink::protocol::Message&)>& on_message);

    /// Link statistics as the status document's groundlink section shows them, seen from the ground.
    nlohmann::json link_stats() const;
    bool link_up() const;

    /// Queues one joystick input as a Fast message (the freshest replaces an unsent one).
    void send_joystick(double steering, double throttle);

    /// Bytes this end's transport wrote to the link so far (all paths, framing included).
    std::uint64_t bytes_sent() const;

  private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace airseg::client

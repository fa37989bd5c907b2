#pragma once
// A client of the simulators' control sockets (airseg-apmsim, airseg-linksim): one datagram per command, the
// reply comes back to the address this client binds.
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace airseg::test {

class ControlClient {
  public:
    /// Binds `own` (removed first, and again on destruction) and talks to the socket at `server`.
    ControlClient(std::string own, std::string server);
    ~ControlClient();
    ControlClient(const ControlClient&) = delete;
    ControlClient& operator=(const ControlClient&) = delete;

    /// The reply to `text`, or nullopt when it cannot be sent or no reply comes within `timeout`.
    std::optional<std::string> ask(const std::string& text,
                                   std::chrono::milliseconds timeout = std::chrono::seconds(5));
    /// The reply as JSON; a missing or non-JSON reply is a test failure (ADD_FAILURE) and gives {}.
    nlohmann::json json(const std::string& text);
    /// The reply as JSON, or {} when there is none (for polling while the simulator may be busy).
    nlohmann::json try_json(const std::string& text);

  private:
    std::string own_, server_;
    int fd_ = -1;
};

}  // namespace airseg::test

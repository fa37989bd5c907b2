#pragma once
// airsegctl's connection to airsegd's local socket: one JSON request line out, one JSON answer line back.
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace airseg::client {

struct LocalAnswer {
    std::optional<nlohmann::json> answer;  // set when the daemon answered
    std::string error;                     // why there is no answer: no socket, timeout, garbage
};

class LocalClient {
  public:
    explicit LocalClient(std::string socket_path,
                         std::chrono::milliseconds timeout = std::chrono::seconds(5));
    ~LocalClient();
    LocalClient(const LocalClient&) = delete;
    LocalClient& operator=(const LocalClient&) = delete;

    /// Sends one request and waits for its answer, reconnecting first if needed.
    LocalAnswer request(const nlohmann::json& request);

  private:
    bool connect(std::string& error);
    bool closed_by_daemon() const;
    std::string path_;
    std::chrono::milliseconds timeout_;
    int fd_ = -1;
    std::string pending_;  // bytes received past the last answer line
};

}  // namespace airseg::client

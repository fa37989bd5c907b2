#pragma once
// The status service: gathers every service's health and its own status section into one document, serves
// it (and every other on-board command) on the local socket, and keeps the one-line summary for systemd.
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "services/common/service.hpp"
#include "services/common/slack_timer.hpp"
#include "services/status/local_command_server.hpp"
#include "services/status/status_messages.hpp"

namespace airseg::status {

struct StatusServiceConfig {
    std::string socket_path;
    unsigned socket_mode = 0660;
    Duration refresh_interval = std::chrono::seconds(1);
    Duration socket_retry = std::chrono::seconds(5);
};

class StatusService : public Service {
  public:
    StatusService(ServiceContext& ctx, StatusServiceConfig config);

    /// The whole document now (call on this service's strand, or use the "status" command).
    nlohmann::json document() const;

  protected:
    void on_start() override;
    void on_stop() override;
    void on_tick(TimePoint now) override;

  private:
    void do_refresh();
    void do_open_socket();
    void publish_summary();
    /// status.local_socket.* and status.log_lines_held.
    nlohmann::json own_section() const;

    StatusServiceConfig config_;
    LocalCommandServer server_;
    SlackTimer refresh_timer_;
    asio::steady_timer socket_timer_;
    // Rendered when the document is read (document() is const to its callers, the cache is not).
    mutable std::map<std::string, nlohmann::json> sections_;
    mutable std::map<std::string, std::function<nlohmann::json()>> unrendered_;
    Subscription sections_sub_;
    std::string last_summary_;
    TimePoint started_at_;
};

}  // namespace airseg::status
